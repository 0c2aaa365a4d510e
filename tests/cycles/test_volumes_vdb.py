"""A Volume object (OpenVDB) against Cycles through the add-on (docs/volumes.md): a smoke grid
written by the core's OpenVDB writer (lantern._core.vdb_write) into the test's tmp dir, loaded
in Blender as a Volume object (rotated, scaled, moved: the grid's transform times the object's
matrix), Principled Volume reading its "density" grid, on a floor under a sun (its shadow rays
cross the smoke) and a dim world. K seeds of each renderer (tools/render_compare.py's settings),
lantern.metrics.assert_agreement with its negative controls, and two of the scene's own:
Lantern rendering the object turned 90 degrees about z, and with its density in world units
(Render Space "World" for Lantern only: Cycles' object-space scaling off), must each be told
apart from Cycles."""

import math
import os
import sys

import numpy as np
import pytest

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)
import lantern

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402
from bpy_stage import camera as _camera, cube as _cube, light as _light  # noqa: E402
from bpy_stage import rough_material as _material  # noqa: E402

K = 8
SIZE = 32
SPP = (256, 256)   # Cycles', Lantern's per seed
SE_FLOOR = 1e-6
ROT = (math.radians(10), 0.0, math.radians(25))
SCALE = (1.3, 1.1, 1.2)

pytestmark = pytest.mark.skipif(not lantern.vdb_available(),
                                reason="Lantern built without OpenVDB")


def smoke_voxels(n=24):
    """Two overlapping blobs of different sizes (not symmetric under a turn about z), 0 at the
    block's border: density (nz, ny, nx)."""
    c = (np.arange(n) + 0.5) / n - 0.5
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    a = np.exp(-((x + 0.12) ** 2 + (y - 0.05) ** 2 + z ** 2) / (2 * 0.13 ** 2))
    b = 0.7 * np.exp(-((x - 0.2) ** 2 + (y + 0.15) ** 2 + (z - 0.1) ** 2) / (2 * 0.08 ** 2))
    d = np.clip(a + b - 0.05, 0.0, None)
    return np.ascontiguousarray(d.astype(np.float32))


def write_vdb(path):
    n = 24
    voxel = 1.0 / n   # a unit cube of voxels, centred on the object's origin
    m = np.array([[voxel, 0, 0, -0.5 + voxel / 2], [0, voxel, 0, -0.5 + voxel / 2],
                  [0, 0, voxel, -0.5 + voxel / 2], [0, 0, 0, 1]], np.float64)
    lantern._core.vdb_write(str(path), "density", smoke_voxels(n), m)


def _smoke_material():
    """Principled Volume (no Surface), Density 12 times the "density" grid (its default
    Density Attribute)."""
    m = bpy.data.materials.new("vdb_smoke")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Color"].default_value = (0.85, 0.8, 0.7, 1.0)
    v.inputs["Absorption Color"].default_value = (0.3, 0.3, 0.3, 1.0)
    v.inputs["Density"].default_value = 12.0
    nt.links.new(v.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    return m


def stage(vdb_path):
    def build():
        scene = bpy_stage.reset(SIZE, world=(0.05, 0.06, 0.08))
        _cube("floor", (0, 0, -0.05), 1.0, _material("floor", (0.7, 0.7, 0.7)),
              scale=(6, 6, 0.1))
        vol = bpy.data.volumes.new("smoke")
        vol.filepath = str(vdb_path)
        obj = bpy.data.objects.new("smoke", vol)
        scene.collection.objects.link(obj)
        obj.location = (0.1, 0.0, 0.8)
        obj.rotation_euler = ROT
        obj.scale = SCALE
        vol.materials.append(_smoke_material())
        _light(scene, "SUN", (0, 0, 3), 3.0, rotation=(50, 0, 40), angle=0.05)
        _camera(scene, (0, -3.5, 1.8), (70, 0, 0), lens=30.0)
    return build


def test_vdb_smoke_matches_cycles(tmp_path):
    path = tmp_path / "smoke.vdb"
    write_vdb(path)
    cyc = bpy_stage.compare_with_cycles("vdb smoke", stage(path), SPP, (0.01, 0.05),
                                        cycles_seed0=950, k_seeds=K, se_floor=SE_FLOOR)
    # the grid's placement matters: the object turned 90 degrees about z is told apart
    smoke = bpy.data.objects["smoke"]
    smoke.rotation_euler[2] += math.radians(90)
    bpy_stage.control_differs("vdb smoke, turned 90 degrees", cyc, K, SPP[1], SE_FLOOR)
    # and Cycles' object-space density (Volume > Render > Space "Object", the default: divided
    # by the scale along the diagonal) is what matches: the density in world units is told apart
    smoke.rotation_euler[2] -= math.radians(90)
    smoke.data.render.space = "WORLD"
    bpy_stage.control_differs("vdb smoke, density in world space", cyc, K, SPP[1], SE_FLOOR)
