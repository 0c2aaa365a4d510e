"""Node graphs between a Volume object's grids and its inputs against Cycles through the add-on
(docs/volumes.md "Node graphs on volume inputs", issue 29). Each test writes a VDB with the
core's OpenVDB writer (lantern._core.vdb_write_list) into its tmp dir, loads it in Blender as a
turned, scaled Volume object, and compares K seeds of each renderer (tools/render_compare.py's
settings, Cycles' stored as order-free references) by lantern.metrics.assert_agreement with its
negative controls, plus two controls of the scene's own, each told apart:

- the density graph: a "density" blob and a "heat" ramp along x on a transform of its own; the
  Principled Volume reads `Attribute "heat" (Fac) -> Map Range (0..1 -> 0.05..2.5, clamped) ->
  Math Multiply x 10 -> Density`, times its Density Attribute "density" (Cycles multiplies the
  two), on a floor under a sun; Lantern compiles the graph into a density program reading both
  grids (kOpGrid), bounded per majorant brick by interval arithmetic. Controls: the graph taken
  out (the Density socket's 2 alone, times the density grid), the Map Range reversed (the heat's
  ramp mirrored);
- the fire: a "density" blob and a "flame" grid (hot in the blob's upper half); the Principled
  Volume (Density Attribute cleared: the graph alone is the density) reads `Attribute "density"
  -> Math Multiply x 6 -> Density` and `Attribute "flame" -> Map Range (0..1 -> 0..4, clamped)
  -> Emission Strength` (Emission Color orange), in a dim world with a sun; the emission's
  program is gathered at the tentative collisions. Controls: the emission's graph taken out (no
  emission), the Map Range's To Max 3 instead of 4."""

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


def _blob(n=20):
    """The density blob both tests' VDBs hold (n^3 voxels over the unit cube) and its voxel
    centres' z."""
    c = (np.arange(n) + 0.5) / n - 0.5
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    d = np.clip(np.exp(-(x ** 2 + (y - 0.05) ** 2 + z ** 2) / (2 * 0.2 ** 2)) - 0.08, 0, None)
    return d, z


def write_vdb(path):
    n = 20
    d, _ = _blob(n)
    m = 10
    cc = (np.arange(m) + 0.5) / m
    heat = np.broadcast_to(cc[None, None, :], (m, m, m)).astype(np.float32)
    lantern._core.vdb_write_list(str(path), [
        {"name": "density", "voxels": np.ascontiguousarray(d.astype(np.float32)),
         "index_to_object": _cube_map(n)},
        {"name": "heat", "voxels": np.ascontiguousarray(heat),
         "index_to_object": _cube_map(m, -0.55, 1.1)}])


def _graph_material():
    m = bpy.data.materials.new("vdb_graph_smoke")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Color"].default_value = (0.85, 0.8, 0.7, 1.0)
    v.inputs["Absorption Color"].default_value = (0.3, 0.3, 0.3, 1.0)
    v.inputs["Density"].default_value = 2.0   # read only without the graph (a control)
    a = nt.nodes.new("ShaderNodeAttribute")
    a.attribute_name = "heat"
    mr = nt.nodes.new("ShaderNodeMapRange")
    mr.name = "map"
    mr.inputs["From Min"].default_value = 0.0
    mr.inputs["From Max"].default_value = 1.0
    mr.inputs["To Min"].default_value = 0.05
    mr.inputs["To Max"].default_value = 2.5
    mr.clamp = True
    mul = nt.nodes.new("ShaderNodeMath")
    mul.operation = "MULTIPLY"
    mul.inputs[1].default_value = 10.0
    nt.links.new(a.outputs["Fac"], mr.inputs["Value"])
    nt.links.new(mr.outputs["Result"], mul.inputs[0])
    nt.links.new(mul.outputs[0], v.inputs["Density"])
    nt.links.new(v.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    return m


def _stage(vdb_path, name, material, world, location, rotation_deg, scale, sun):
    """The scene both tests render: a floor, the Volume object `name` reading vdb_path at the
    given placement with `material()`, a sun of strength `sun` and the camera."""
    def build():
        scene = bpy_stage.reset(SIZE, world=world)
        _cube("floor", (0, 0, -0.05), 1.0, _material("floor", (0.7, 0.7, 0.7)),
              scale=(6, 6, 0.1))
        vol = bpy.data.volumes.new(name)
        vol.filepath = str(vdb_path)
        obj = bpy.data.objects.new(name, vol)
        scene.collection.objects.link(obj)
        obj.location = location
        obj.rotation_euler = tuple(math.radians(a) for a in rotation_deg)
        obj.scale = scale
        vol.materials.append(material())
        _light(scene, "SUN", (0, 0, 3), sun, rotation=(50, 0, 40), angle=0.05)
        _camera(scene, (0, -3.5, 1.8), (70, 0, 0), lens=30.0)
    return build


def stage(vdb_path):
    return _stage(vdb_path, "smoke", _graph_material, (0.05, 0.06, 0.08), (0.1, 0.0, 0.8),
                  (10, 0, 20), (1.4, 1.1, 1.2), 3.0)


def test_vdb_density_graph_matches_cycles(tmp_path):
    path = tmp_path / "graph.vdb"
    write_vdb(path)
    cyc = bpy_stage.compare_with_cycles("vdb density graph", stage(path), SPP, (0.01, 0.05),
                                        cycles_seed0=960, k_seeds=K, se_floor=SE_FLOOR)
    nt = bpy.data.materials["vdb_graph_smoke"].node_tree
    # the heat's ramp mirrored (Lantern only) is told apart: the grid's values matter
    mr = nt.nodes["map"]
    mr.inputs["To Min"].default_value, mr.inputs["To Max"].default_value = 2.5, 0.05
    bpy_stage.control_differs("vdb density graph, ramp mirrored", cyc, K, SPP[1], SE_FLOOR)
    # the graph ignored (the Density socket's 2 alone, as Lantern rendered it before) too
    mr.inputs["To Min"].default_value, mr.inputs["To Max"].default_value = 0.05, 2.5
    v = nt.nodes["Principled Volume"]
    nt.links.remove(v.inputs["Density"].links[0])
    bpy_stage.control_differs("vdb density graph, graph ignored", cyc, K, SPP[1], SE_FLOOR)


def write_fire_vdb(path):
    n = 20
    d, z = _blob(n)
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


def fire_stage(vdb_path):
    return _stage(vdb_path, "fire", _fire_material, (0.02, 0.02, 0.03), (0.0, 0.0, 0.8),
                  (8, 0, -25), (1.2, 1.0, 1.3), 1.0)


def test_vdb_fire_graphs_match_cycles(tmp_path):
    path = tmp_path / "fire.vdb"
    write_fire_vdb(path)
    cyc = bpy_stage.compare_with_cycles("vdb fire graphs", fire_stage(path), SPP, (0.01, 0.05),
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
