"""Node graphs on mesh volumes' emission colours against Cycles through the add-on
(docs/volumes.md "Node graphs on volume inputs", issue 29): a Principled Volume (grey
scattering, Density 2, Emission Strength 3) whose Emission Color is `Gradient Texture
(Generated) -> ColorRamp (red -> yellow)`, and an Emission shader (Strength 2) whose Color is
`Noise Texture (Generated, Scale 3) Fac -> ColorRamp (blue -> white)`, each a
"volume_emission_color" program (emission flame_emission x e per point, gathered at the
tracking's tentative collisions), in a dim world with a dim sun. K seeds of each renderer
(tools/render_compare.py's settings, Cycles' stored), metrics.assert_agreement with its
negative controls, and the Principled Volume's emission graph taken out (its socket's grey)
told apart."""

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


def _glow():
    m = bpy.data.materials.new("emission_principled")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Density"].default_value = 2.0
    v.inputs["Color"].default_value = (0.6, 0.6, 0.6, 1.0)
    v.inputs["Emission Strength"].default_value = 3.0
    v.inputs["Emission Color"].default_value = (0.5, 0.5, 0.5, 1.0)   # without the graph
    g = nt.nodes.new("ShaderNodeTexGradient")
    r = _ramp(nt, (1.0, 0.1, 0.02, 1.0), (1.0, 0.9, 0.2, 1.0))
    nt.links.new(g.outputs["Fac"], r.inputs["Fac"])
    nt.links.new(r.outputs["Color"], v.inputs["Emission Color"])
    nt.links.new(v.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    return m


def _emitter():
    m = bpy.data.materials.new("emission_shader")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    e = nt.nodes.new("ShaderNodeEmission")
    e.inputs["Strength"].default_value = 2.0
    n = nt.nodes.new("ShaderNodeTexNoise")
    n.inputs["Scale"].default_value = 3.0
    n.inputs["Detail"].default_value = 1.0
    r = _ramp(nt, (0.1, 0.2, 1.0, 1.0), (1.0, 1.0, 1.0, 1.0))
    r.color_ramp.elements[0].position = 0.3
    r.color_ramp.elements[1].position = 0.7
    nt.links.new(n.outputs["Fac"], r.inputs["Fac"])
    nt.links.new(r.outputs["Color"], e.inputs["Color"])
    nt.links.new(e.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    return m


def glows():
    scene = bpy_stage.reset(SIZE, world=(0.02, 0.02, 0.03))
    _cube("floor", (0, 0, -0.05), 1.0, _material("floor", (0.7, 0.7, 0.7)), scale=(6, 6, 0.1))
    _cube("glow", (-0.55, 0.1, 0.6), 0.9, _glow())
    _cube("emitter", (0.6, 0.0, 0.5), 0.8, _emitter())
    _light(scene, "SUN", (0, 0, 3), 0.5, rotation=(50, 0, 40), angle=0.05)
    _camera(scene, (0, -4.0, 1.8), (72, 0, 0), lens=32.0)


def test_emission_color_graphs_match_cycles():
    cyc = bpy_stage.compare_with_cycles("volume emission colour graphs", glows, SPP,
                                        (0.01, 0.05), cycles_seed0=1040, k_seeds=K,
                                        se_floor=SE_FLOOR)
    nt = bpy.data.materials["emission_principled"].node_tree
    v = nt.nodes["Principled Volume"]
    nt.links.remove(v.inputs["Emission Color"].links[0])
    bpy_stage.control_differs("volume emission colour graphs, graph ignored", cyc, K, SPP[1],
                              SE_FLOOR)
