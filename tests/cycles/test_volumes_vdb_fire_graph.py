"""A Volume object fire driven by node graphs of its grids against Cycles through the add-on
(docs/volumes.md "Node graphs on volume inputs", issue 29): a VDB of a "density" blob and a
"flame" grid (hot in the blob's upper half) written by the core's OpenVDB writer, loaded in
Blender as a turned, scaled Volume object whose Principled Volume (Density Attribute cleared:
the graph alone is the density) reads `Attribute "density" -> Math Multiply x 6 -> Density`
and `Attribute "flame" -> Map Range (0..1 -> 0..4, clamped) -> Emission Strength` (Emission
Color orange), in a dim world with a sun. Lantern compiles both graphs into programs reading
the grids (kOpGrid): the density's bounded per majorant brick, the emission's gathered at the
tentative collisions. K seeds a side (Cycles' stored), assert_agreement with its negative
controls, and two of the scene's own: Lantern with the emission's graph taken out (no
emission) and with the Map Range's To Max 3 instead of 4, each told apart."""

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


def _cube_map(n, lo=-0.5, size=1.0):
    v = size / n
    return np.array([[v, 0, 0, lo + v / 2], [0, v, 0, lo + v / 2],
                     [0, 0, v, lo + v / 2], [0, 0, 0, 1]], np.float64)


def write_vdb(path):
    n = 20
    c = (np.arange(n) + 0.5) / n - 0.5
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    d = np.clip(np.exp(-(x ** 2 + (y - 0.05) ** 2 + z ** 2) / (2 * 0.2 ** 2)) - 0.08, 0, None)
    flame = np.clip(2.0 * z + 0.3, 0.0, 1.0) * (d > 0.2)
    lantern._core.vdb_write_list(str(path), [
        {"name": "density", "voxels": np.ascontiguousarray(d.astype(np.float32)),
         "index_to_object": _cube_map(n)},
        {"name": "flame", "voxels": np.ascontiguousarray(flame.astype(np.float32)),
         "index_to_object": _cube_map(n)}])


def _fire_material():
    m = bpy.data.materials.new("vdb_graph_fire")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Color"].default_value = (0.6, 0.6, 0.6, 1.0)
    v.inputs["Density Attribute"].default_value = ""
    v.inputs["Emission Color"].default_value = (1.0, 0.45, 0.1, 1.0)
    v.inputs["Blackbody Intensity"].default_value = 0.0
    a = nt.nodes.new("ShaderNodeAttribute")
    a.attribute_name = "density"
    mul = nt.nodes.new("ShaderNodeMath")
    mul.operation = "MULTIPLY"
    mul.inputs[1].default_value = 6.0
    nt.links.new(a.outputs["Fac"], mul.inputs[0])
    nt.links.new(mul.outputs[0], v.inputs["Density"])
    f = nt.nodes.new("ShaderNodeAttribute")
    f.attribute_name = "flame"
    mr = nt.nodes.new("ShaderNodeMapRange")
    mr.name = "map"
    mr.inputs["From Min"].default_value = 0.0
    mr.inputs["From Max"].default_value = 1.0
    mr.inputs["To Min"].default_value = 0.0
    mr.inputs["To Max"].default_value = 4.0
    mr.clamp = True
    nt.links.new(f.outputs["Fac"], mr.inputs["Value"])
    nt.links.new(mr.outputs["Result"], v.inputs["Emission Strength"])
    nt.links.new(v.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    return m


def stage(vdb_path):
    def build():
        scene = bpy_stage.reset(SIZE, world=(0.02, 0.02, 0.03))
        _cube("floor", (0, 0, -0.05), 1.0, _material("floor", (0.7, 0.7, 0.7)),
              scale=(6, 6, 0.1))
        vol = bpy.data.volumes.new("fire")
        vol.filepath = str(vdb_path)
        obj = bpy.data.objects.new("fire", vol)
        scene.collection.objects.link(obj)
        obj.location = (0.0, 0.0, 0.8)
        obj.rotation_euler = (math.radians(8), 0.0, math.radians(-25))
        obj.scale = (1.2, 1.0, 1.3)
        vol.materials.append(_fire_material())
        _light(scene, "SUN", (0, 0, 3), 1.0, rotation=(50, 0, 40), angle=0.05)
        _camera(scene, (0, -3.5, 1.8), (70, 0, 0), lens=30.0)
    return build


def test_vdb_fire_graphs_match_cycles(tmp_path):
    path = tmp_path / "fire.vdb"
    write_vdb(path)
    cyc = bpy_stage.compare_with_cycles("vdb fire graphs", stage(path), SPP, (0.01, 0.05),
                                        cycles_seed0=970, k_seeds=K, se_floor=SE_FLOOR)
    nt = bpy.data.materials["vdb_graph_fire"].node_tree
    # the flame's Map Range to 3 instead of 4 (Lantern only) is told apart
    nt.nodes["map"].inputs["To Max"].default_value = 3.0
    bpy_stage.control_differs("vdb fire graphs, To Max 3", cyc, K, SPP[1], SE_FLOOR)
    # the emission's graph ignored (its socket's 1 with the Map Range unlinked) too
    nt.nodes["map"].inputs["To Max"].default_value = 4.0
    v = nt.nodes["Principled Volume"]
    nt.links.remove(v.inputs["Emission Strength"].links[0])
    v.inputs["Emission Strength"].default_value = 0.0
    bpy_stage.control_differs("vdb fire graphs, emission graph ignored", cyc, K, SPP[1],
                              SE_FLOOR)
