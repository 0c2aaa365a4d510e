"""Farm workers: `blender -b file.blend -E LANTERN -f N` (tools/bpy_blender.py stands in for the
binary: bpy is a module here) renders a saved .blend in a fresh process through the add-on and
writes the frame; its EXR records the samples and scene that `python -m lantern merge` needs.

The subprocesses use this checkout's lantern package (python/) and add-on."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import bpy
import numpy as np
import pytest

import lantern
from blender_helpers import add_camera, add_plane, emission_material

pytestmark = pytest.mark.skipif(not lantern.session.native_available(),
                                reason="lantern native module not built")

ROOT = Path(__file__).resolve().parents[2]
WORLD = (0.1, 0.2, 0.3)
EMIT = (1.0, 0.5, 2.0)  # colour (0.5, 0.25, 1) at strength 2


def _env():
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "python")] +
                                        [p for p in env.get("PYTHONPATH", "").split(os.pathsep)
                                         if p])
    return env


def _run(*args, timeout=300):
    return subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True,
                          timeout=timeout, env=_env(), cwd=str(ROOT))


def _blender(*args):
    return _run(ROOT / "tools" / "bpy_blender.py", *args)


def _read_bpy(path):
    image = bpy.data.images.load(str(path), check_existing=False)
    try:
        w, h = image.size
        px = np.empty(w * h * 4, dtype=np.float32)
        image.pixels.foreach_get(px)
    finally:
        bpy.data.images.remove(image)
    return px.reshape(h, w, 4)[::-1]


def _header(path):
    code = ("import sys, json; from lantern import exr; "
            "print(json.dumps(exr.read_exr(sys.argv[1]).metadata))")
    out = _run("-c", code, path)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


@pytest.fixture
def blend(empty, tmp_path):
    """An orthographic camera over an emissive square on a constant world: every pixel away
    from the square's edge is known exactly (a camera ray sees emission or the world)."""
    cam = add_camera(empty, location=(0, 0, 5))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 2.0  # 32 px over 2 m: the 1 m square spans x 8..24, y 4..20
    add_plane(empty, size=1.0, material=emission_material(2.0, (0.5, 0.25, 1.0)))
    world = bpy.data.worlds.new("W")
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (*WORLD, 1.0)
    bg.inputs["Strength"].default_value = 1.0
    empty.world = world
    empty.lantern.samples = 4
    empty.lantern.backend = "cpu"
    empty.render.image_settings.file_format = "OPEN_EXR"
    empty.render.image_settings.color_depth = "32"
    empty.render.filepath = str(tmp_path / "frame_####")
    path = tmp_path / "farm.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    return path


def test_blender_b_renders_a_frame(blend, tmp_path):
    out = _blender("-b", blend, "-E", "LANTERN", "-f", "3")
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-2000:]
    frame = tmp_path / "frame_0003.exr"
    assert frame.exists(), out.stdout[-2000:]
    px = _read_bpy(frame)
    assert px.shape == (24, 32, 4)
    np.testing.assert_allclose(px[7:17, 11:21, :3], np.broadcast_to(EMIT, (10, 10, 3)),
                               rtol=1e-5)
    outside = np.concatenate([px[:, :5, :3], px[:, 27:, :3]]).reshape(-1, 3)
    np.testing.assert_allclose(outside, np.broadcast_to(WORLD, outside.shape), rtol=1e-5)
    meta = _header(frame)
    assert int(meta["lantern.spp"]) == 4
    assert len(meta["lantern.scene"]) == 32


def test_blender_chunks_merge(blend, tmp_path):
    """Two workers render the frame with seeds 0 and 1 (--python-expr, as the Flamenco job
    type does); the merge weighs them by their samples and refuses another scene's frame."""
    outs = []
    for seed, samples in ((0, 4), (1, 12)):
        expr = (f"import bpy; s = bpy.context.scene; s.lantern.seed = {seed}; "
                f"s.lantern.samples = {samples}")
        o = _blender("-b", blend, "-E", "LANTERN", "-o", str(tmp_path / f"c{seed}_####"),
                     "--python-expr", expr, "-f", "1")
        assert o.returncode == 0, o.stderr[-2000:]
        outs.append(tmp_path / f"c{seed}_0001.exr")
    merged = tmp_path / "merged.exr"
    m = _run("-m", "lantern", "merge", *outs, "-o", merged)
    assert m.returncode == 0, m.stderr
    assert int(_header(merged)["lantern.spp"]) == 16
    px = _read_bpy(merged)
    np.testing.assert_allclose(px[7:17, 11:21, :3], np.broadcast_to(EMIT, (10, 10, 3)),
                               rtol=1e-5)
    expr = "import bpy; bpy.data.worlds['W'].node_tree.nodes['Background'].inputs[1]." \
           "default_value = 3.0; bpy.context.scene.lantern.seed = 2"
    o = _blender("-b", blend, "-E", "LANTERN", "-o", str(tmp_path / "other_####"),
                 "--python-expr", expr, "-f", "1")
    assert o.returncode == 0, o.stderr[-2000:]
    m = _run("-m", "lantern", "merge", outs[0], tmp_path / "other_0001.exr", "-o",
             tmp_path / "bad.exr")
    assert m.returncode == 1 and "different scenes" in m.stderr, m.stderr


def test_unknown_engine_is_refused(blend):
    out = _blender("-b", blend, "-E", "NOT_AN_ENGINE", "-f", "1")
    assert out.returncode != 0 and "NOT_AN_ENGINE" in out.stderr


def _compile_flamenco_job(tmp_path, settings):
    node = shutil.which("node")
    if node is None:
        pytest.skip("node (to run the Flamenco job compiler) is not installed")
    sfile = tmp_path / "settings.json"
    sfile.write_text(json.dumps(settings))
    out = subprocess.run([node, ROOT / "tools/flamenco/compile_job.js",
                          ROOT / "tools/flamenco/lantern_split_samples.js", sfile],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def test_flamenco_split_sample_job(blend, tmp_path):
    """The Flamenco 3 job type's tasks, run as a worker would run them (blender-render:
    exe, exeArgs, argsBefore, blendfile, args), give a merged frame of all the samples."""
    settings = {"frame": 2, "samples": 10, "chunks": 3, "seed": 7, "multilayer": False,
                "render_output_root": str(tmp_path / "farm"),
                "render_output_path": str(tmp_path / "farm" / "job" / "{timestamp}"),
                "blendfile": str(blend), "scene": "Scene"}
    tasks = _compile_flamenco_job(tmp_path, settings)
    chunks = [t for t in tasks if t["name"].startswith("render-chunk-")]
    merge_task = next(t for t in tasks if t["name"] == "merge-chunks")
    assert len(chunks) == 3 and sorted(merge_task["dependencies"]) == sorted(
        t["name"] for t in chunks)
    for task in chunks + [merge_task]:
        (cmd,) = task["commands"]
        p = cmd["parameters"]
        assert cmd["name"] == "blender-render" and p["exe"] == "{blender}"
        o = _blender("-b", "-y", *p["argsBefore"], p["blendfile"], *p["args"])
        assert o.returncode == 0, (task["name"], o.stderr[-2000:])
    (merged,) = (tmp_path / "farm" / "job").glob("*/000002.exr")
    meta = _header(merged)
    assert int(meta["lantern.spp"]) == 10
    assert sorted(meta["lantern.seed"].split(",")) == ["7", "8", "9"]
    px = _read_bpy(merged)
    np.testing.assert_allclose(px[7:17, 11:21, :3], np.broadcast_to(EMIT, (10, 10, 3)),
                               rtol=1e-5)
