"""Negative emission is clamped to 0 (docs/nodes.md, difftest D17) and the export says so, naming
the material: a node graph that goes negative on an emission input (difftest D17's unnormalized
Noise on a Principled's Emission Strength) and a constant negative Strength warn; the same graphs
kept positive (a normalized Noise; a positive Strength) do not (the negative controls)."""

import bpy
import pytest

import lantern

pytestmark = pytest.mark.skipif(not lantern.session.native_available(),
                                reason="lantern native module not built")


def _export():
    from lantern_blender.export import export_scene
    _, report = export_scene(bpy.context.evaluated_depsgraph_get())
    return [m for m in report.messages if "negative" in m]


def _scene(empty, kind, normalize=False, strength=1.0):
    from blender_helpers import add_camera, add_plane
    add_camera(empty, location=(0, 0, 5))
    mat = bpy.data.materials.new("Glow")
    nt = mat.node_tree
    for n in list(nt.nodes):
        if n.type != "OUTPUT_MATERIAL":
            nt.nodes.remove(n)
    out = next(n for n in nt.nodes if n.type == "OUTPUT_MATERIAL")
    if kind == "principled_noise":
        node = nt.nodes.new("ShaderNodeBsdfPrincipled")
        noise = nt.nodes.new("ShaderNodeTexNoise")
        noise.normalize = normalize
        nt.links.new(noise.outputs["Fac"], node.inputs["Emission Strength"])
    else:
        node = nt.nodes.new("ShaderNodeEmission")
        node.inputs["Strength"].default_value = strength
    nt.links.new(node.outputs[0], out.inputs["Surface"])
    add_plane(empty, size=4.0, material=mat, name="Panel")


def test_graph_with_negative_emission_warns(empty):
    _scene(empty, "principled_noise", normalize=False)
    msgs = _export()
    assert len(msgs) == 1, msgs
    assert "Material 'Glow'" in msgs[0] and "emission" in msgs[0], msgs[0]


def test_positive_graph_does_not_warn(empty):
    _scene(empty, "principled_noise", normalize=True)   # Fac in [0, 1]
    assert _export() == []


@pytest.mark.parametrize("strength, warns", [(-2.0, True), (3.0, False)])
def test_constant_negative_strength_warns(empty, strength, warns):
    _scene(empty, "emission", strength=strength)
    msgs = _export()
    assert len(msgs) == (1 if warns else 0), msgs
    if warns:
        assert "Material 'Glow'" in msgs[0] and "'Strength' is negative" in msgs[0], msgs[0]
