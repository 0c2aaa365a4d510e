"""Node graphs on a Volume object's colours against Cycles through the add-on (docs/volumes.md
"Node graphs on volume inputs", issue 29). Each test writes a VDB with the core's OpenVDB
writer into its tmp dir (test_volumes_vdb_graph's blob), loads it in Blender as a turned,
scaled Volume object, and compares K seeds of each renderer (tools/render_compare.py's
settings, Cycles' stored) by lantern.metrics.assert_agreement with its negative controls, plus
a control of the scene's own (the graph taken out: the socket's value, what Lantern rendered
before), which must be told apart:

- the smoke: a Principled Volume (Density Attribute "density", Density 12) whose Color is
  `Attribute "heat" (Fac) -> ColorRamp (blue -> orange)`, the heat a ramp along x on a
  transform of its own: a "volume_color" program of the heat grid (kOpGrid), its majorant per
  brick per channel from the ramp's interval over the brick;
- the fire: the blob's Density (x 6 by a graph) and `Attribute "flame" -> ColorRamp (red ->
  yellow)` on the Emission Color with `Attribute "flame" -> Map Range (0..1 -> 0..4)` on the
  Emission Strength: a "volume_emission_color" program times the strength's program."""

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
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy_stage  # noqa: E402
from bpy_stage import camera as _camera, cube as _cube, light as _light  # noqa: E402
from bpy_stage import rough_material as _material  # noqa: E402
from test_volumes_vdb_graph import _blob, _cube_map  # noqa: E402

K = 8
SIZE = 32
SPP = (256, 128)   # Cycles', Lantern's per seed
SE_FLOOR = 1e-6

pytestmark = pytest.mark.skipif(not lantern.vdb_available(),
                                reason="Lantern built without OpenVDB")


def write_vdb(path):
    n = 20
    d, z = _blob(n)
    m = 10
    cc = (np.arange(m) + 0.5) / m
    heat = np.broadcast_to(cc[None, None, :], (m, m, m)).astype(np.float32)
    flame = np.clip(2.0 * z + 0.5, 0.0, 1.0) * (d > 0.15)
    lantern._core.vdb_write_list(str(path), [
        {"name": "density", "voxels": np.ascontiguousarray(d.astype(np.float32)),
         "index_to_object": _cube_map(n)},
        {"name": "heat", "voxels": np.ascontiguousarray(heat),
         "index_to_object": _cube_map(m, -0.55, 1.1)},
        {"name": "flame", "voxels": np.ascontiguousarray(flame.astype(np.float32)),
         "index_to_object": _cube_map(n)}])


def _ramp(nt, a, b):
    r = nt.nodes.new("ShaderNodeValToRGB")
    r.name = "ramp"
    r.color_ramp.elements[0].color = a
    r.color_ramp.elements[1].color = b
    return r


def _smoke_material():
    m = bpy.data.materials.new("vdb_color_smoke")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Color"].default_value = (0.7, 0.7, 0.7, 1.0)   # read only without the graph
    v.inputs["Absorption Color"].default_value = (0.3, 0.3, 0.3, 1.0)
    v.inputs["Density"].default_value = 12.0
    a = nt.nodes.new("ShaderNodeAttribute")
    a.attribute_name = "heat"
    r = _ramp(nt, (0.1, 0.2, 0.9, 1.0), (0.95, 0.5, 0.1, 1.0))
    nt.links.new(a.outputs["Fac"], r.inputs["Fac"])
    nt.links.new(r.outputs["Color"], v.inputs["Color"])
    nt.links.new(v.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    return m


def _fire_material():
    m = bpy.data.materials.new("vdb_color_fire")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Color"].default_value = (0.6, 0.6, 0.6, 1.0)
    v.inputs["Density Attribute"].default_value = ""
    v.inputs["Emission Color"].default_value = (0.2, 0.6, 1.0, 1.0)   # without the graph
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
    mr.inputs["To Max"].default_value = 4.0
    mr.clamp = True
    nt.links.new(f.outputs["Fac"], mr.inputs["Value"])
    nt.links.new(mr.outputs["Result"], v.inputs["Emission Strength"])
    r = _ramp(nt, (1.0, 0.1, 0.02, 1.0), (1.0, 0.9, 0.2, 1.0))
    nt.links.new(f.outputs["Fac"], r.inputs["Fac"])
    nt.links.new(r.outputs["Color"], v.inputs["Emission Color"])
    nt.links.new(v.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    return m


def _stage(vdb_path, name, material, world, location, rotation_deg, scale, sun):
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


def test_vdb_color_graph_matches_cycles(tmp_path):
    path = tmp_path / "color.vdb"
    write_vdb(path)
    build = _stage(path, "smoke", _smoke_material, (0.05, 0.06, 0.08), (0.1, 0.0, 0.8),
                   (10, 0, 20), (1.4, 1.1, 1.2), 3.0)
    cyc = bpy_stage.compare_with_cycles("vdb colour graph", build, SPP, (0.01, 0.05),
                                        cycles_seed0=1020, k_seeds=K, se_floor=SE_FLOOR)
    nt = bpy.data.materials["vdb_color_smoke"].node_tree
    v = nt.nodes["Principled Volume"]
    nt.links.remove(v.inputs["Color"].links[0])
    bpy_stage.control_differs("vdb colour graph, graph ignored", cyc, K, SPP[1], SE_FLOOR)


def test_vdb_emission_color_graph_matches_cycles(tmp_path):
    path = tmp_path / "fire.vdb"
    write_vdb(path)
    build = _stage(path, "fire", _fire_material, (0.02, 0.02, 0.03), (0.0, 0.0, 0.8),
                   (8, 0, -25), (1.2, 1.0, 1.3), 1.0)
    cyc = bpy_stage.compare_with_cycles("vdb emission colour graph", build, SPP, (0.01, 0.05),
                                        cycles_seed0=1030, k_seeds=K, se_floor=SE_FLOOR)
    nt = bpy.data.materials["vdb_color_fire"].node_tree
    v = nt.nodes["Principled Volume"]
    nt.links.remove(v.inputs["Emission Color"].links[0])
    bpy_stage.control_differs("vdb emission colour graph, graph ignored", cyc, K, SPP[1],
                              SE_FLOOR)
