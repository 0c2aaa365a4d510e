"""Embree symbol safety: Blender ships its own Embree 4 (libembree4.so.4 in bpy) that exports the
same unprefixed rtc* names as the Embree Lantern loads. Inside the Blender binary that library
sits in the global symbol scope. Loading Lantern there must neither crash nor call into it.

Each case runs in a fresh interpreter, since the global scope cannot be undone in-process."""
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

lantern = pytest.importorskip("lantern")
if not getattr(lantern, "native_available", lambda: True)():
    pytest.skip("lantern's native module is not built", allow_module_level=True)


def _blender_embree():
    try:
        import importlib.util
        spec = importlib.util.find_spec("bpy")
    except (ImportError, ValueError):
        spec = None
    if spec is None or not spec.submodule_search_locations:
        return None
    lib = Path(list(spec.submodule_search_locations)[0]) / "lib" / "libembree4.so.4"
    return lib if lib.exists() else None


CHILD = r"""
import ctypes, json, os, sys
import numpy as np
pre = os.environ.get("PRELOAD")
if pre:
    ctypes.CDLL(pre, mode=os.RTLD_NOW | os.RTLD_GLOBAL)
    # the foreign Embree really is in the global scope now: the bare name resolves to it
    glob = ctypes.CDLL(None)
    assert hasattr(glob, "rtcNewDevice"), "preload did not reach the global scope"
import lantern
from lantern import _core, scenes
img = lantern.render(scenes.cornell_box(width=32, height=32), spp=4, seed=7, threads=1)
np.save(sys.argv[1], img)
print(json.dumps({"embree": _core.embree_version()}))
"""


def _run(tmp_path, name, preload):
    out = tmp_path / f"{name}.npy"
    env = dict(os.environ)
    env.pop("PRELOAD", None)
    if preload:
        env["PRELOAD"] = str(preload)
    proc = subprocess.run([sys.executable, "-c", CHILD, str(out)], env=env,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, f"child failed ({proc.returncode}):\n{proc.stdout}\n{proc.stderr}"
    info = json.loads(proc.stdout.strip().splitlines()[-1])
    return np.load(out), info


def test_foreign_embree_in_global_scope(tmp_path):
    foreign = _blender_embree()
    if foreign is None:
        pytest.skip("bpy with its libembree4.so.4 is not installed here")
    plain, info_plain = _run(tmp_path, "plain", None)
    mixed, info_mixed = _run(tmp_path, "mixed", foreign)
    assert np.isfinite(mixed).all()
    assert mixed.mean() > 0
    # the version Lantern reports comes from the Embree it loaded, not Blender's 4.x
    assert info_mixed["embree"] == info_plain["embree"]
    assert not info_mixed["embree"].startswith("4.")
    # same seed, same settings, same backend: same image, bit for bit, with or without it
    assert np.array_equal(plain, mixed)
