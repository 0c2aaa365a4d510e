"""Colour graphs on two shaders of one mesh volume against Cycles through the add-on
(docs/volumes.md "Node graphs on volume inputs", issue 29): `Add Shader (Volume Scatter (Density
3, Color: Gradient Texture (Generated) -> ColorRamp (blue -> orange)), Principled Volume
(Density 2, Color grey, Absorption Color: Noise Texture Fac -> ColorRamp (dark -> pale
yellow)))`: a "volume_color" program on one shader and a "volume_absorption_color" program on
the other, the Principled Volume's absorption max(1 - Color, 0) x Density times the Absorption
Color's factor alone ("absorb_alone"), as Cycles adds the two closures; and a Volume Absorption
(Color: Spherical Gradient -> ColorRamp) added to a Principled Volume whose Absorption Color is
a graph. K seeds of each renderer (tools/render_compare.py's settings, Cycles' stored),
metrics.assert_agreement with its negative controls, and the first cube's Absorption Color
graph taken out (its socket's black, what Lantern rendered before with a warning) told
apart."""

import os
import sys

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402
from bpy_stage import camera as _camera, cube as _cube, light as _light  # noqa: E402
from bpy_stage import rough_material as _material  # noqa: E402

K = 8
SIZE = 32
SPP = (256, 128)   # Cycles', Lantern's per seed
SE_FLOOR = 1e-6


def _ramp(nt, a, b):
    r = nt.nodes.new("ShaderNodeValToRGB")
    r.color_ramp.elements[0].color = a
    r.color_ramp.elements[1].color = b
    return r


def _scatter_and_principled():
    m = bpy.data.materials.new("two_shaders")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    s = nt.nodes.new("ShaderNodeVolumeScatter")
    s.inputs["Density"].default_value = 3.0
    g = nt.nodes.new("ShaderNodeTexGradient")
    r = _ramp(nt, (0.1, 0.3, 0.9, 1.0), (0.95, 0.55, 0.1, 1.0))
    nt.links.new(g.outputs["Fac"], r.inputs["Fac"])
    nt.links.new(r.outputs["Color"], s.inputs["Color"])
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Density"].default_value = 2.0
    v.inputs["Color"].default_value = (0.5, 0.5, 0.5, 1.0)
    v.inputs["Absorption Color"].default_value = (0.0, 0.0, 0.0, 1.0)   # without the graph
    n = nt.nodes.new("ShaderNodeTexNoise")
    n.inputs["Scale"].default_value = 3.0
    n.inputs["Detail"].default_value = 1.0
    a = _ramp(nt, (0.05, 0.05, 0.05, 1.0), (0.95, 0.9, 0.4, 1.0))
    a.color_ramp.elements[0].position = 0.3
    a.color_ramp.elements[1].position = 0.7
    nt.links.new(n.outputs["Fac"], a.inputs["Fac"])
    nt.links.new(a.outputs["Color"], v.inputs["Absorption Color"])
    add = nt.nodes.new("ShaderNodeAddShader")
    nt.links.new(s.outputs[0], add.inputs[0])
    nt.links.new(v.outputs[0], add.inputs[1])
    nt.links.new(add.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    return m


def _absorption_and_principled():
    m = bpy.data.materials.new("two_absorbers")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    b = nt.nodes.new("ShaderNodeVolumeAbsorption")
    b.inputs["Density"].default_value = 2.0
    g = nt.nodes.new("ShaderNodeTexGradient")
    g.gradient_type = "SPHERICAL"
    r = _ramp(nt, (0.9, 0.2, 0.1, 1.0), (0.2, 0.8, 0.9, 1.0))
    nt.links.new(g.outputs["Fac"], r.inputs["Fac"])
    nt.links.new(r.outputs["Color"], b.inputs["Color"])
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Density"].default_value = 2.5
    v.inputs["Color"].default_value = (0.7, 0.7, 0.7, 1.0)
    t = nt.nodes.new("ShaderNodeTexCoord")
    sep = nt.nodes.new("ShaderNodeSeparateXYZ")
    a = _ramp(nt, (0.0, 0.1, 0.3, 1.0), (0.9, 0.9, 0.9, 1.0))
    nt.links.new(t.outputs["Generated"], sep.inputs[0])
    nt.links.new(sep.outputs["Z"], a.inputs["Fac"])
    nt.links.new(a.outputs["Color"], v.inputs["Absorption Color"])
    add = nt.nodes.new("ShaderNodeAddShader")
    nt.links.new(b.outputs[0], add.inputs[0])
    nt.links.new(v.outputs[0], add.inputs[1])
    nt.links.new(add.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    return m


def volumes():
    scene = bpy_stage.reset(SIZE, world=(0.05, 0.06, 0.08))
    _cube("floor", (0, 0, -0.05), 1.0, _material("floor", (0.7, 0.7, 0.7)), scale=(6, 6, 0.1))
    _cube("mixed", (-0.55, 0.1, 0.6), 0.9, _scatter_and_principled())
    _cube("absorbers", (0.6, 0.0, 0.5), 0.8, _absorption_and_principled())
    _light(scene, "SUN", (0, 0, 3), 3.0, rotation=(50, 0, 40), angle=0.05)
    _camera(scene, (0, -4.0, 1.8), (72, 0, 0), lens=32.0)


def test_colour_graphs_on_two_shaders_match_cycles():
    cyc = bpy_stage.compare_with_cycles("volume colour graphs on two shaders", volumes, SPP,
                                        (0.01, 0.05), cycles_seed0=1100, k_seeds=K,
                                        se_floor=SE_FLOOR)
    nt = bpy.data.materials["two_shaders"].node_tree
    v = nt.nodes["Principled Volume"]
    nt.links.remove(v.inputs["Absorption Color"].links[0])
    bpy_stage.control_differs("volume colour graphs on two shaders, absorption graph ignored",
                              cyc, K, SPP[1], SE_FLOOR)
