"""Node graphs on volumes' colours against Cycles through the add-on (docs/volumes.md "Node
graphs on volume inputs", issue 29): three mesh volumes on a floor under a sun, in a dim
world, each colour a "volume_color" program (scattering color_scatter x c, absorption
color_absorb x max(1 - c, 0) per point, its majorant from the interval of c per channel):

- a Principled Volume (Density 6) whose Color is `Gradient Texture (Generated, Linear) ->
  ColorRamp (blue -> orange)` and Absorption Color `Generated Z -> ColorRamp (dark -> light)`
  (a "volume_absorption_color" program: absorption x max(1 - sqrt(a), 0) per point);
- `Volume Scatter (Color: Noise Texture (Generated, Scale 4) Fac -> ColorRamp (green ->
  (1.6, 0.1, 1.3)), Density 5) + Volume Absorption (constant grey, Density 1)` (a colour graph
  on one leaf of two; a colour above 1 scatters c x density and absorbs nothing, in both);
- a Volume Absorption (Density 4) whose Color is `Gradient Texture (Generated, Spherical) ->
  ColorRamp (red -> cyan)`.

K seeds of each renderer (tools/render_compare.py's settings, Cycles' stored), metrics.
assert_agreement with its negative controls, and a control of the scene's own: the Principled
Volume's colour graph taken out (its socket's colour, what Lantern rendered before) must be
told apart, and so must its Absorption Color's graph taken out. Bad input (Lantern alone): a
colour graph through negative values and a Math Inverse Square Root of a gradient less 0.5
(NaN below the middle, infinite at it) renders finite, the negative values named in a warning
(Lantern takes them as 0; Cycles scatters negatively), non-finite ones read 0."""

import os
import sys

import numpy as np

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


def _volume_material(name):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    return m, nt


def _ramp(nt, a, b, name=None):
    r = nt.nodes.new("ShaderNodeValToRGB")
    if name:
        r.name = name
    r.color_ramp.elements[0].color = a
    r.color_ramp.elements[1].color = b
    return r


def _principled():
    m, nt = _volume_material("color_principled")
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Density"].default_value = 6.0
    v.inputs["Color"].default_value = (0.7, 0.7, 0.7, 1.0)   # read only without the graph
    v.inputs["Absorption Color"].default_value = (0.3, 0.3, 0.3, 1.0)
    g = nt.nodes.new("ShaderNodeTexGradient")
    r = _ramp(nt, (0.1, 0.2, 0.9, 1.0), (0.95, 0.5, 0.1, 1.0), "ramp")
    nt.links.new(g.outputs["Fac"], r.inputs["Fac"])
    nt.links.new(r.outputs["Color"], v.inputs["Color"])
    # the Absorption Color: the gradient along z (Generated), dark at the bottom
    xyz = nt.nodes.new("ShaderNodeSeparateXYZ")
    tc = nt.nodes.new("ShaderNodeTexCoord")
    nt.links.new(tc.outputs["Generated"], xyz.inputs[0])
    a = _ramp(nt, (0.02, 0.05, 0.1, 1.0), (0.9, 0.7, 0.5, 1.0), "absorb")
    nt.links.new(xyz.outputs["Z"], a.inputs["Fac"])
    nt.links.new(a.outputs["Color"], v.inputs["Absorption Color"])
    nt.links.new(v.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    return m


def _scatter_plus_absorb():
    m, nt = _volume_material("color_scatter")
    s = nt.nodes.new("ShaderNodeVolumeScatter")
    s.inputs["Density"].default_value = 5.0
    s.inputs["Anisotropy"].default_value = 0.3
    a = nt.nodes.new("ShaderNodeVolumeAbsorption")
    a.inputs["Density"].default_value = 1.0
    a.inputs["Color"].default_value = (0.5, 0.5, 0.5, 1.0)
    n = nt.nodes.new("ShaderNodeTexNoise")
    n.inputs["Scale"].default_value = 4.0
    n.inputs["Detail"].default_value = 1.0
    r = _ramp(nt, (0.1, 0.8, 0.2, 1.0), (1.6, 0.1, 1.3, 1.0))   # above 1: albedo 1
    r.color_ramp.elements[0].position = 0.35
    r.color_ramp.elements[1].position = 0.65
    nt.links.new(n.outputs["Fac"], r.inputs["Fac"])
    nt.links.new(r.outputs["Color"], s.inputs["Color"])
    add = nt.nodes.new("ShaderNodeAddShader")
    nt.links.new(s.outputs[0], add.inputs[0])
    nt.links.new(a.outputs[0], add.inputs[1])
    nt.links.new(add.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    return m


def _absorber():
    m, nt = _volume_material("color_absorb")
    v = nt.nodes.new("ShaderNodeVolumeAbsorption")
    v.inputs["Density"].default_value = 4.0
    g = nt.nodes.new("ShaderNodeTexGradient")
    g.gradient_type = "SPHERICAL"
    r = _ramp(nt, (0.9, 0.1, 0.1, 1.0), (0.1, 0.9, 0.9, 1.0))
    nt.links.new(g.outputs["Fac"], r.inputs["Fac"])
    nt.links.new(r.outputs["Color"], v.inputs["Color"])
    nt.links.new(v.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    return m


def colors():
    scene = bpy_stage.reset(SIZE, world=(0.05, 0.06, 0.08))
    _cube("floor", (0, 0, -0.05), 1.0, _material("floor", (0.7, 0.7, 0.7)), scale=(6, 6, 0.1))
    _cube("principled", (-0.9, 0.2, 0.6), 0.9, _principled())
    _cube("scatter", (0.15, 0.0, 0.55), 0.8, _scatter_plus_absorb())
    _cube("absorber", (1.05, 0.2, 0.5), 0.7, _absorber())
    _light(scene, "SUN", (0, 0, 3), 3.0, rotation=(50, 0, 40), angle=0.05)
    _camera(scene, (0, -4.0, 1.8), (72, 0, 0), lens=32.0)


def test_color_graphs_match_cycles():
    cyc = bpy_stage.compare_with_cycles("volume colour graphs", colors, SPP, (0.01, 0.05),
                                        cycles_seed0=1010, k_seeds=K, se_floor=SE_FLOOR)
    # the Principled Volume's graph ignored (its socket's grey) is told apart
    nt = bpy.data.materials["color_principled"].node_tree
    v = nt.nodes["Principled Volume"]
    link = v.inputs["Color"].links[0]
    nt.links.remove(link)
    bpy_stage.control_differs("volume colour graphs, graph ignored", cyc, K, SPP[1], SE_FLOOR)
    nt.links.new(nt.nodes["ramp"].outputs["Color"], v.inputs["Color"])
    nt.links.remove(v.inputs["Absorption Color"].links[0])
    bpy_stage.control_differs("volume colour graphs, absorption graph ignored", cyc, K, SPP[1],
                              SE_FLOOR)


def _bad_material(kind):
    """A Volume Scatter whose Color is 3 x Gradient - 1 (from -1 to 2), or a Volume Absorption
    whose Color is Inverse Square Root (Gradient - 0.5): NaN, infinite and finite."""
    m, nt = _volume_material(f"color_bad_{kind}")
    g = nt.nodes.new("ShaderNodeTexGradient")
    if kind == "negative":
        v = nt.nodes.new("ShaderNodeVolumeScatter")
        v.inputs["Density"].default_value = 4.0
        ma = nt.nodes.new("ShaderNodeMath")
        ma.operation = "MULTIPLY_ADD"
        ma.inputs[1].default_value = 3.0
        ma.inputs[2].default_value = -1.0
        nt.links.new(g.outputs["Fac"], ma.inputs[0])
        nt.links.new(ma.outputs[0], v.inputs["Color"])
    else:
        v = nt.nodes.new("ShaderNodeVolumeAbsorption")
        v.inputs["Density"].default_value = 2.0
        sub = nt.nodes.new("ShaderNodeMath")
        sub.operation = "SUBTRACT"
        sub.inputs[1].default_value = 0.5
        inv = nt.nodes.new("ShaderNodeMath")
        inv.operation = "INVERSE_SQRT"
        nt.links.new(g.outputs["Fac"], sub.inputs[0])
        nt.links.new(sub.outputs[0], inv.inputs[0])
        nt.links.new(inv.outputs[0], v.inputs["Color"])
    nt.links.new(v.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    return m


def test_bad_color_graphs_are_finite_and_warned():
    scene = bpy_stage.reset(SIZE, world=(0.05, 0.06, 0.08))
    _cube("floor", (0, 0, -0.05), 1.0, _material("floor", (0.7, 0.7, 0.7)), scale=(6, 6, 0.1))
    _cube("negative", (-0.6, 0.0, 0.6), 0.9, _bad_material("negative"))
    _cube("nan", (0.6, 0.0, 0.6), 0.9, _bad_material("nan"))
    _light(scene, "SUN", (0, 0, 3), 3.0, rotation=(50, 0, 40), angle=0.05)
    _camera(scene, (0, -4.0, 1.8), (72, 0, 0), lens=32.0)
    img, warnings = bpy_stage.lantern_renders(1, 16)
    assert np.isfinite(img).all() and img.mean() > 1e-3
    # (render_compare sets Cycles' volume bounces for a comparison; none here)
    ours = [w for w in warnings if not w.startswith("Render settings")]
    assert len(ours) == 1, warnings   # the NaN / infinite graph reads 0 there, unwarned
    assert "'Color' of 'Volume Scatter' gives negative values" in ours[0], warnings
