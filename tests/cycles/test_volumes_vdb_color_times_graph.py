"""A Volume object's Color Attribute grid times a node graph on its Color against Cycles
through the add-on (docs/volumes.md "Node graphs on volume inputs", issue 29): Cycles' Principled
Volume multiplies its Color by the Color Attribute's colour, so a graph on the Color and the
grid multiply too. A smoke cube (density grid, 24^3), a colour grid ramping red to blue along x
(12^3, a transform of its own) and a heat grid ramping along z, written by the core's OpenVDB
writer into the test's tmp dir, loaded in Blender as a turned, scaled Volume object; its
Principled Volume's Color is `Attribute "heat" (Fac) -> ColorRamp (dark grey -> white)` and its
Color Attribute "color": a "volume_color" program of both grids (kOpGrid), the ramp times the
colour grid. K seeds of each renderer (tools/render_compare.py's settings, Cycles' stored),
lantern.metrics.assert_agreement with its negative controls, and the scene's own: the Color
Attribute cleared (the graph alone, what Lantern rendered before, warned), told apart."""

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
SPP = (256, 128)   # Cycles', Lantern's per seed
SE_FLOOR = 1e-6

pytestmark = pytest.mark.skipif(not lantern.vdb_available(),
                                reason="Lantern built without OpenVDB")


def _unit_cube_map(n, lo=-0.5, size=1.0):
    """n^3 voxels over the cube [lo, lo + size]^3 of the object's space."""
    v = size / n
    return np.array([[v, 0, 0, lo + v / 2], [0, v, 0, lo + v / 2],
                     [0, 0, v, lo + v / 2], [0, 0, 0, 1]], np.float64)


def write_vdb(path):
    n = 24
    c = (np.arange(n) + 0.5) / n - 0.5
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    d = np.clip(1.0 - np.maximum(np.maximum(abs(x), abs(y)), abs(z)) / 0.42, 0.0, 0.25) * 4.0
    m = 12
    u = (np.arange(m) + 0.5) / m
    col = np.zeros((m, m, m, 3), np.float32)
    col[..., 0] = u[None, None, :]
    col[..., 1] = 0.4
    col[..., 2] = 1.0 - u[None, None, :]
    heat = np.broadcast_to(u[:, None, None], (m, m, m)).astype(np.float32)
    lantern._core.vdb_write_list(str(path), [
        {"name": "density", "voxels": np.ascontiguousarray(d.astype(np.float32)),
         "index_to_object": _unit_cube_map(n)},
        {"name": "color", "voxels": col, "index_to_object": _unit_cube_map(m)},
        {"name": "heat", "voxels": np.ascontiguousarray(heat),
         "index_to_object": _unit_cube_map(m, -0.55, 1.1)}])


def _smoke_material():
    m = bpy.data.materials.new("vdb_color_times")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Color"].default_value = (0.9, 0.9, 0.9, 1.0)   # read only without the graph
    v.inputs["Absorption Color"].default_value = (0.2, 0.2, 0.2, 1.0)
    v.inputs["Density"].default_value = 6.0
    v.inputs["Color Attribute"].default_value = "color"
    a = nt.nodes.new("ShaderNodeAttribute")
    a.attribute_name = "heat"
    r = nt.nodes.new("ShaderNodeValToRGB")
    r.color_ramp.elements[0].color = (0.15, 0.15, 0.15, 1.0)
    r.color_ramp.elements[1].color = (1.0, 1.0, 1.0, 1.0)
    nt.links.new(a.outputs["Fac"], r.inputs["Fac"])
    nt.links.new(r.outputs["Color"], v.inputs["Color"])
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
        obj.location = (0.0, 0.0, 0.75)
        obj.rotation_euler = (math.radians(10), 0.0, math.radians(15))
        obj.scale = (1.2, 1.0, 1.1)
        vol.materials.append(_smoke_material())
        _light(scene, "SUN", (0, 0, 3), 3.0, rotation=(50, 0, 40), angle=0.05)
        _camera(scene, (0, -3.2, 1.6), (72, 0, 0), lens=32.0)
    return build


def test_vdb_color_grid_times_graph_matches_cycles(tmp_path):
    path = tmp_path / "smoke.vdb"
    write_vdb(path)
    cyc = bpy_stage.compare_with_cycles("vdb colour grid x graph", stage(path), SPP,
                                        (0.01, 0.05), cycles_seed0=1080, k_seeds=K,
                                        se_floor=SE_FLOOR)
    v = bpy.data.materials["vdb_color_times"].node_tree.nodes["Principled Volume"]
    # the grid ignored (the graph alone, as Lantern rendered it before), told apart
    v.inputs["Color Attribute"].default_value = ""
    bpy_stage.control_differs("vdb colour grid x graph, grid ignored", cyc, K, SPP[1],
                              SE_FLOOR)
