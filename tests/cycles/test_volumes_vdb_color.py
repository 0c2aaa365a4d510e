"""A Volume object's colour grid against Cycles through the add-on (docs/volumes.md, issue 29):
a smoke cube (density grid, 24^3) and a colour grid ramping red to blue along x at half the
resolution (12^3, a transform of its own) written by the core's OpenVDB writer
(lantern._core.vdb_write_list) into the test's tmp dir, loaded in Blender as a Volume object
(turned, scaled), Principled Volume with its Color Attribute "color" (Color times the grid's
colour scatters, max(1 - that, 0) x (1 - sqrt(Absorption Color)) absorbs, as Cycles), on a floor
under a sun. K seeds of each renderer (tools/render_compare.py's settings, Cycles' stored as
order-free references), lantern.metrics.assert_agreement with its negative controls, and two of
the scene's own: Lantern without the colour grid (the Color Attribute cleared: the Color socket
alone) and with the ramp mirrored (the object turned 180 degrees about z), each told apart."""

import math
import os
import sys

import numpy as np
import pytest

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)
import lantern
import lantern._core

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402
from bpy_stage import camera as _camera, cube as _cube, light as _light  # noqa: E402
from bpy_stage import rough_material as _material  # noqa: E402

K = 8
SIZE = 32
SPP = (256, 256)   # Cycles', Lantern's per seed
SE_FLOOR = 1e-6

pytestmark = pytest.mark.skipif(not lantern.vdb_available(),
                                reason="Lantern built without OpenVDB")


def _unit_cube_map(n):
    """n^3 voxels over the unit cube centred on the object's origin."""
    v = 1.0 / n
    return np.array([[v, 0, 0, -0.5 + v / 2], [0, v, 0, -0.5 + v / 2],
                     [0, 0, v, -0.5 + v / 2], [0, 0, 0, 1]], np.float64)


def write_vdb(path):
    n = 24
    c = (np.arange(n) + 0.5) / n - 0.5
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    # a soft-edged cube of smoke, 0 at the block's border
    d = np.clip(1.0 - np.maximum(np.maximum(abs(x), abs(y)), abs(z)) / 0.42, 0.0, 0.25) * 4.0
    m = 12
    cc = (np.arange(m) + 0.5) / m - 0.5
    u = np.clip(cc + 0.5, 0.0, 1.0)
    col = np.zeros((m, m, m, 3), np.float32)
    col[..., 0] = u[None, None, :]
    col[..., 1] = 0.3
    col[..., 2] = 1.0 - u[None, None, :]
    lantern._core.vdb_write_list(str(path), [
        {"name": "density", "voxels": np.ascontiguousarray(d.astype(np.float32)),
         "index_to_object": _unit_cube_map(n)},
        {"name": "color", "voxels": col, "index_to_object": _unit_cube_map(m)}])


def _smoke_material():
    m = bpy.data.materials.new("vdb_color_smoke")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Color"].default_value = (0.9, 0.85, 0.95, 1.0)
    v.inputs["Absorption Color"].default_value = (0.2, 0.2, 0.2, 1.0)
    v.inputs["Density"].default_value = 6.0
    v.inputs["Color Attribute"].default_value = "color"
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
        obj.location = (0.0, 0.0, 0.7)
        obj.rotation_euler = (0.0, 0.0, math.radians(15))
        obj.scale = (1.2, 1.0, 1.0)
        vol.materials.append(_smoke_material())
        _light(scene, "SUN", (0, 0, 3), 3.0, rotation=(50, 0, 40), angle=0.05)
        _camera(scene, (0, -3.2, 1.6), (72, 0, 0), lens=32.0)
    return build


# `long` (bench/long_tests.sh): Cycles' renders dominate (stored once as references; a fresh
# store is K Cycles renders of about 14 s of CPU each). CI covers the colour grid's parts:
# tests/python/test_volume_color_grid.py (the reader, Beer-Lambert per column of a colour
# ramp, bad input) and the add-on's binding of the Color Attribute
# (tests/blender/test_bl_volume_objects.py).
@pytest.mark.long
def test_vdb_colour_grid_matches_cycles(tmp_path):
    path = tmp_path / "smoke.vdb"
    write_vdb(path)
    cyc = bpy_stage.compare_with_cycles("vdb colour smoke", stage(path), SPP, (0.01, 0.05),
                                        cycles_seed0=990, k_seeds=K, se_floor=SE_FLOOR)
    v = bpy.data.materials["vdb_color_smoke"].node_tree.nodes["Principled Volume"]
    # the colour ignored (Lantern without the grid: the Color socket alone), told apart
    v.inputs["Color Attribute"].default_value = ""
    bpy_stage.control_differs("vdb colour smoke, colour ignored", cyc, K, SPP[1], SE_FLOOR)
    v.inputs["Color Attribute"].default_value = "color"
    # the ramp mirrored (turned 180 degrees about z), told apart
    bpy.data.objects["smoke"].rotation_euler[2] += math.radians(180)
    bpy_stage.control_differs("vdb colour smoke, ramp mirrored", cyc, K, SPP[1], SE_FLOOR)
