"""F12 into a multilayer EXR and back: every view layer's passes as numpy arrays, for scripts and
tests that drive bpy. The file is read in a child interpreter without bpy (OpenImageIO must not
meet bpy's own copy in one process)."""

import os
import subprocess
import sys

import numpy as np

_READER = r'''
import sys
import numpy as np
import OpenImageIO as oiio
inp = oiio.ImageInput.open(sys.argv[1])
if inp is None:
    sys.exit(oiio.geterror())
arrays = {}
si = 0
while inp.seek_subimage(si, 0):
    spec = inp.spec()
    px = np.asarray(inp.read_image(si, 0, 0, spec.nchannels, "float"), dtype=np.float32)
    px = px.reshape(spec.height, spec.width, spec.nchannels)
    groups = {}
    for c, name in enumerate(spec.channelnames):   # "Layer.Pass.X", or "R" in a plain EXR
        parts = name.split(".")
        key = "\x1f".join(parts[:-1]) if len(parts) > 1 else "\x1fCombined"
        groups.setdefault(key, []).append(c)
    for key, chans in groups.items():
        arrays[key] = px[:, :, chans]
    si += 1
np.savez(sys.argv[2], **arrays)
'''


def read_passes(path):
    """{(layer, pass): (H, W, C) float32, top row first} of an EXR (a plain one: ("", ...))."""
    out = str(path) + ".npz"
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    run = subprocess.run([sys.executable, "-c", _READER, str(path), out], env=env,
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    with np.load(out) as data:
        result = {}
        for key in data.files:
            layer, _, name = key.partition("\x1f")
            result[(layer, name)] = data[key]
    os.remove(out)
    return result


def render_passes(scene, path):
    """F12 of `scene` into a multilayer EXR at `path`, read back with read_passes."""
    import bpy
    scene.render.filepath = str(path)
    s = scene.render.image_settings
    s.media_type = "MULTI_LAYER_IMAGE"
    s.file_format = "OPEN_EXR_MULTILAYER"
    s.color_depth = "32"
    assert bpy.ops.render.render(write_still=True) == {"FINISHED"}
    return read_passes(path)
