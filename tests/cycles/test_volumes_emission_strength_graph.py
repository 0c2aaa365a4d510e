"""Node graphs on mesh volumes' emission strengths against Cycles through the add-on
(docs/volumes.md "Node graphs on volume inputs", issue 29): a Principled Volume (grey
scattering, Density 1.5, Emission Color orange) whose Emission Strength is `Gradient Texture
(Generated) -> Math Multiply x 6`, and an Emission shader (Color blue-white) whose Strength is
`Noise Texture (Generated, Scale 3) Fac -> Map Range (0.3..0.7 -> 0..5, clamped)`, each a
"volume_emission" program (emission flame_emission x max(value, 0) per point, gathered at the
tracking's tentative collisions), in a dim world with a dim sun. K seeds of each renderer
(tools/render_compare.py's settings, Cycles' stored), metrics.assert_agreement with its
negative controls, and the Principled Volume's strength graph taken out (its socket's 3)
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


def _flame():
    m = bpy.data.materials.new("strength_principled")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Density"].default_value = 1.5
    v.inputs["Color"].default_value = (0.6, 0.6, 0.6, 1.0)
    v.inputs["Emission Strength"].default_value = 3.0   # without the graph
    v.inputs["Emission Color"].default_value = (1.0, 0.45, 0.1, 1.0)
    g = nt.nodes.new("ShaderNodeTexGradient")
    k = nt.nodes.new("ShaderNodeMath")
    k.operation = "MULTIPLY"
    k.inputs[1].default_value = 6.0
    nt.links.new(g.outputs["Fac"], k.inputs[0])
    nt.links.new(k.outputs[0], v.inputs["Emission Strength"])
    nt.links.new(v.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    return m


def _glow():
    m = bpy.data.materials.new("strength_emission")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    e = nt.nodes.new("ShaderNodeEmission")
    e.inputs["Color"].default_value = (0.3, 0.6, 1.0, 1.0)
    n = nt.nodes.new("ShaderNodeTexNoise")
    n.inputs["Scale"].default_value = 3.0
    n.inputs["Detail"].default_value = 1.0
    r = nt.nodes.new("ShaderNodeMapRange")
    r.clamp = True
    r.inputs["From Min"].default_value = 0.3
    r.inputs["From Max"].default_value = 0.7
    r.inputs["To Min"].default_value = 0.0
    r.inputs["To Max"].default_value = 5.0
    nt.links.new(n.outputs["Fac"], r.inputs["Value"])
    nt.links.new(r.outputs["Result"], e.inputs["Strength"])
    nt.links.new(e.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    return m


def flames():
    scene = bpy_stage.reset(SIZE, world=(0.02, 0.02, 0.03))
    _cube("floor", (0, 0, -0.05), 1.0, _material("floor", (0.7, 0.7, 0.7)), scale=(6, 6, 0.1))
    _cube("flame", (-0.55, 0.1, 0.6), 0.9, _flame())
    _cube("glow", (0.6, 0.0, 0.5), 0.8, _glow())
    _light(scene, "SUN", (0, 0, 3), 0.5, rotation=(50, 0, 40), angle=0.05)
    _camera(scene, (0, -4.0, 1.8), (72, 0, 0), lens=32.0)


def test_emission_strength_graphs_match_cycles():
    cyc = bpy_stage.compare_with_cycles("volume emission strength graphs", flames, SPP,
                                        (0.01, 0.05), cycles_seed0=1060, k_seeds=K,
                                        se_floor=SE_FLOOR)
    nt = bpy.data.materials["strength_principled"].node_tree
    v = nt.nodes["Principled Volume"]
    nt.links.remove(v.inputs["Emission Strength"].links[0])
    bpy_stage.control_differs("volume emission strength graphs, graph ignored", cyc, K, SPP[1],
                              SE_FLOOR)
