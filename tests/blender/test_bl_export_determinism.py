"""The same script-built scene exports the same arrays in every process.

tests/cycles/test_hair.py's fur (a UV sphere with 400 particle hairs) exported differently in
each Blender process: Blender 5.0.1's UV sphere primitive gives the same vertices but another
face order and other loop starts per process, and the particle system places its hairs over the
faces in their order, so the sphere's arrays and the strands themselves changed (a farm job of
the scene got another lantern.merge.scene_identity per chunk; the stored Cycles reference was
stale on every run). test_hair now rebuilds the sphere in a canonical face order
(tests/cycles/mesh_canon.py).

Two fresh processes export the fur; every mesh and curve array must be byte-identical. Control:
the digest sees the face order (the primitive's own order against the canonical one)."""

import hashlib
import os
import subprocess
import sys
from pathlib import Path

import pytest

import lantern

pytestmark = pytest.mark.skipif(not lantern.session.native_available(),
                                reason="lantern native module not built")

ROOT = Path(__file__).resolve().parents[2]

# run in tests/cycles: builds the fur, exports it through the add-on, prints one digest line
_SCRIPT = r"""
import hashlib, os, sys
import numpy as np
sys.path[:0] = [os.getcwd(), os.path.join(os.getcwd(), "..", "..", "tools")]
import test_hair as th
import render_compare as rc
from lantern.merge import scene_identity
if sys.argv[1] == "raw":
    th.canonical_faces = lambda obj: None
th.fur()
sc = rc.export_current()
n = sc.to_native()
h = hashlib.sha256()
for kind in ("meshes", "curves"):
    for item in n[kind]:
        for name in sorted(item):
            v = item[name]
            if isinstance(v, np.ndarray) or isinstance(v, (list, tuple)):
                a = np.ascontiguousarray(np.asarray(v))
                if a.dtype != object:
                    h.update(f"{kind}.{name}{a.shape}{a.dtype}".encode()); h.update(a.tobytes())
print("DIGEST", len(n["meshes"]), len(n["curves"]), h.hexdigest(), scene_identity(sc))
"""


def _export(mode):
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "python")] +
                                        [p for p in env.get("PYTHONPATH", "").split(os.pathsep)
                                         if p])
    out = subprocess.run([sys.executable, "-c", _SCRIPT, mode], capture_output=True, text=True,
                         timeout=300, env=env, cwd=str(ROOT / "tests" / "cycles"))
    lines = [ln for ln in out.stdout.splitlines() if ln.startswith("DIGEST")]
    assert out.returncode == 0 and lines, out.stdout[-2000:] + out.stderr[-2000:]
    _, meshes, curves, digest, identity = lines[-1].split()
    assert (meshes, curves) == ("1", "1"), lines[-1]
    return digest, identity


def test_fur_exports_the_same_arrays_in_two_processes():
    first, second = _export("canonical"), _export("canonical")
    assert first == second, f"fur exported differently in two processes: {first} != {second}"
    raw = _export("raw")  # control: the primitive's own face order is seen by the digest
    assert raw[0] != first[0] and raw[1] != first[1], raw
