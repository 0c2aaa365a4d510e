"""Export of volume outputs (addon/export/volume.py, docs/volumes.md): the coefficients of
Principled Volume, Volume Scatter + Volume Absorption under a Mix Shader, and the world's
Volume, against Cycles' closure setup written out by hand; a Volume without Surface is a pure
volume boundary, one with a Surface keeps it."""

import math

import bpy
import numpy as np

from blender_helpers import add_camera, add_plane


def export(addon):
    from lantern_blender.export import export_scene
    return export_scene(bpy.context.evaluated_depsgraph_get())


def _volume_only(name):
    mat = bpy.data.materials.new(name)
    nt = mat.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    return mat, nt, nt.nodes["Material Output"]


def _by_name(scene, name):
    return next(m for m in scene.materials if m["name"] == name)


def test_principled_volume_coefficients(empty, addon):
    add_camera(empty)
    mat, nt, out = _volume_only("Fog")
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Density"].default_value = 2.0
    v.inputs["Color"].default_value = (0.5, 0.6, 0.7, 1)
    v.inputs["Absorption Color"].default_value = (0.25, 0.36, 0.49, 1)
    v.inputs["Anisotropy"].default_value = 0.3
    v.inputs["Emission Strength"].default_value = 2.0
    v.inputs["Emission Color"].default_value = (1.0, 0.5, 0.25, 1)
    nt.links.new(v.outputs[0], out.inputs["Volume"])
    add_plane(empty, material=mat, name="Box")
    scene, report = export(addon)
    m = _by_name(scene, "Fog")
    assert m["volume_only"] is True
    vol = m["volume"]
    c, a = np.array([0.5, 0.6, 0.7]), np.sqrt([0.25, 0.36, 0.49])
    np.testing.assert_allclose(vol["sigma_s"], 2.0 * c, rtol=1e-6)
    np.testing.assert_allclose(vol["sigma_a"], 2.0 * (1 - c) * (1 - a), rtol=1e-5)
    np.testing.assert_allclose(vol["emission"], [2.0, 1.0, 0.5], rtol=1e-6)
    assert math.isclose(vol["g"], 0.3, rel_tol=1e-6)


def test_mixed_scatter_and_absorption_with_surface(empty, addon):
    add_camera(empty)
    mat = bpy.data.materials.new("Murky")   # keeps its Principled BSDF surface
    nt = mat.node_tree
    out = nt.nodes["Material Output"]
    sc = nt.nodes.new("ShaderNodeVolumeScatter")
    sc.inputs["Density"].default_value = 4.0
    sc.inputs["Color"].default_value = (0.2, 0.4, 0.8, 1)
    sc.inputs["Anisotropy"].default_value = -0.2
    ab = nt.nodes.new("ShaderNodeVolumeAbsorption")
    ab.inputs["Density"].default_value = 1.0
    ab.inputs["Color"].default_value = (0.9, 0.5, 0.1, 1)
    mix = nt.nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = 0.25
    nt.links.new(sc.outputs[0], mix.inputs[1])
    nt.links.new(ab.outputs[0], mix.inputs[2])
    nt.links.new(mix.outputs[0], out.inputs["Volume"])
    add_plane(empty, material=mat, name="Glass")
    scene, report = export(addon)
    m = _by_name(scene, "Murky")
    assert not m.get("volume_only", False)
    vol = m["volume"]
    np.testing.assert_allclose(vol["sigma_s"], 0.75 * 4.0 * np.array([0.2, 0.4, 0.8]), rtol=1e-6)
    np.testing.assert_allclose(vol["sigma_a"], 0.25 * np.array([0.1, 0.5, 0.9]), rtol=1e-5)
    assert math.isclose(vol["g"], -0.2, rel_tol=1e-6)


def test_world_volume(empty, addon):
    add_camera(empty)
    world = bpy.data.worlds.new("Hazy")
    nt = world.node_tree
    sc = nt.nodes.new("ShaderNodeVolumeScatter")
    sc.inputs["Density"].default_value = 0.1
    nt.links.new(sc.outputs[0], nt.nodes["World Output"].inputs["Volume"])
    empty.world = world
    scene, report = export(addon)
    np.testing.assert_allclose(scene.world["volume"]["sigma_s"], [0.08, 0.08, 0.08], rtol=1e-6)
    np.testing.assert_allclose(scene.world["volume"]["sigma_a"], [0, 0, 0])


def test_principled_volume_blackbody(empty, addon):
    """Blackbody: Tint x (5.670373e-8 x 1e-6 / pi) x mix(1, T^4, intensity) x the blackbody
    colour of luminance 1, beside the plain emission (Cycles' closure, written out by hand; the
    colour itself is node_spectral's, checked against Planck's law in tests/cycles/test_nodes);
    nothing and no warning at intensity 0; rendered against Cycles in tests/cycles (fire)."""
    from lantern_blender.export.node_spectral import blackbody_rgb
    add_camera(empty)
    mat, nt, out = _volume_only("Fire")
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Emission Strength"].default_value = 0.5
    v.inputs["Blackbody Intensity"].default_value = 0.75
    v.inputs["Temperature"].default_value = 2500.0
    v.inputs["Blackbody Tint"].default_value = (1.0, 0.5, 0.25, 1)
    nt.links.new(v.outputs[0], out.inputs["Volume"])
    add_plane(empty, material=mat, name="Box")
    cold, nt2, out2 = _volume_only("Cold")
    v2 = nt2.nodes.new("ShaderNodeVolumePrincipled")
    v2.inputs["Emission Strength"].default_value = 0.5
    nt2.links.new(v2.outputs[0], out2.inputs["Volume"])
    add_plane(empty, material=cold, name="Other")
    scene, report = export(addon)
    sigma = 5.670373e-8 * 1e-6 / math.pi
    intensity = sigma * (0.25 + 0.75 * 2500.0 ** 4)
    rgb = np.maximum(np.array(blackbody_rgb(2500.0)), 0.0)
    want = 0.5 + np.array([1.0, 0.5, 0.25]) * intensity * rgb
    np.testing.assert_allclose(_by_name(scene, "Fire")["volume"]["emission"], want, rtol=1e-5)
    assert intensity > 0.5  # a visible fire: the T^4 term carries it
    np.testing.assert_allclose(_by_name(scene, "Cold")["volume"]["emission"], [0.5] * 3,
                               rtol=1e-6)
    assert not [m for m in report.messages if "Blackbody" in m], report.messages


def test_density_graph_becomes_a_density_program(empty, addon):
    """A Noise Texture on a Principled Volume's Density: a "density" program on the material,
    the coefficients per unit of density, no warning; a graph on Color a "volume_color" program
    beside it; a graph on Anisotropy still warns by name (its own value is used), and so does a
    Density graph with a second volume shader beside it."""
    add_camera(empty)
    mat, nt, out = _volume_only("Smoke")
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Density"].default_value = 7.0   # not used: the graph drives it
    v.inputs["Color"].default_value = (0.5, 0.6, 0.7, 1)
    noise = nt.nodes.new("ShaderNodeTexNoise")
    nt.links.new(noise.outputs["Fac"], v.inputs["Density"])
    nt.links.new(v.outputs[0], out.inputs["Volume"])
    add_plane(empty, material=mat, name="Box")
    scene, report = export(addon)
    m = _by_name(scene, "Smoke")
    assert [p["target"] for p in m.get("programs", [])] == ["density"]
    np.testing.assert_allclose(m["volume"]["sigma_s"], [0.5, 0.6, 0.7], rtol=1e-6)
    assert not [w for w in report.messages if "Smoke" in w], report.messages
    # a graph on Color: a "volume_color" program, the colour's part per unit of density out
    # of sigma_a and sigma_s into color_scatter and color_absorb (docs/volumes.md), no warning
    nt.links.new(noise.outputs["Color"], v.inputs["Color"])
    scene, report = export(addon)
    m = _by_name(scene, "Smoke")
    assert [p["target"] for p in m.get("programs", [])] == ["density", "volume_color"]
    np.testing.assert_allclose(m["volume"]["sigma_s"], [0.0] * 3, atol=1e-9)
    np.testing.assert_allclose(m["volume"]["sigma_a"], [0.0] * 3, atol=1e-9)
    np.testing.assert_allclose(m["volume"]["color_scatter"], [1.0] * 3, rtol=1e-6)
    # (Absorption Color 0 by default: max(1 - sqrt(0), 0) = 1)
    np.testing.assert_allclose(m["volume"]["color_absorb"], [1.0] * 3, rtol=1e-6)
    assert not [w for w in report.messages if "Smoke" in w], report.messages
    # negative: a graph on Anisotropy is not rendered (a warning names it)
    nt.links.new(noise.outputs["Fac"], v.inputs["Anisotropy"])
    scene, report = export(addon)
    assert any("'Anisotropy'" in w and "Smoke" in w for w in report.messages), report.messages
    nt.links.remove(v.inputs["Anisotropy"].links[0])
    # two shaders, one with a Density graph: the socket's value, a warning
    nt.links.remove(v.inputs["Color"].links[0])
    ab = nt.nodes.new("ShaderNodeVolumeAbsorption")
    add = nt.nodes.new("ShaderNodeAddShader")
    nt.links.new(v.outputs[0], add.inputs[0])
    nt.links.new(ab.outputs[0], add.inputs[1])
    nt.links.new(add.outputs[0], out.inputs["Volume"])
    scene, report = export(addon)
    m = _by_name(scene, "Smoke")
    assert "density" not in [p["target"] for p in m.get("programs", [])]
    assert any("Density" in w and "Smoke" in w for w in report.messages), report.messages
    np.testing.assert_allclose(m["volume"]["sigma_s"], 7.0 * np.array([0.5, 0.6, 0.7]),
                               rtol=1e-6)


def test_emission_and_absorption_color_graphs(empty, addon):
    """A graph on a Principled Volume's Emission Color: a "volume_emission_color" program, its
    factor (weight x Emission Strength) the volume's flame_emission and nothing of it in the
    constant emission; a graph on its Absorption Color: a "volume_absorption_color" program,
    the Color (constant) as color_base, the scattering left in sigma_s. An Emission shader's
    Color the same; an Emission Strength of 0 drops the program (it emits nothing)."""
    add_camera(empty)
    mat, nt, out = _volume_only("Glow")
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Density"].default_value = 2.0
    v.inputs["Color"].default_value = (0.5, 0.6, 0.7, 1)
    v.inputs["Emission Strength"].default_value = 3.0
    noise = nt.nodes.new("ShaderNodeTexNoise")
    nt.links.new(noise.outputs["Color"], v.inputs["Emission Color"])
    nt.links.new(noise.outputs["Color"], v.inputs["Absorption Color"])
    nt.links.new(v.outputs[0], out.inputs["Volume"])
    add_plane(empty, material=mat, name="Box")
    scene, report = export(addon)
    m = _by_name(scene, "Glow")
    assert sorted(p["target"] for p in m["programs"]) == ["volume_absorption_color",
                                                          "volume_emission_color"]
    vol = m["volume"]
    np.testing.assert_allclose(vol["flame_emission"], [3.0] * 3, rtol=1e-6)
    np.testing.assert_allclose(vol["emission"], [0.0] * 3, atol=1e-9)
    np.testing.assert_allclose(vol["sigma_s"], 2.0 * np.array([0.5, 0.6, 0.7]), rtol=1e-6)
    np.testing.assert_allclose(vol["sigma_a"], [0.0] * 3, atol=1e-9)
    np.testing.assert_allclose(vol["color_absorb"], [2.0] * 3, rtol=1e-6)
    np.testing.assert_allclose(vol["color_scatter"], [0.0] * 3, atol=1e-9)
    np.testing.assert_allclose(vol["color_base"], [0.5, 0.6, 0.7], rtol=1e-6)
    assert not [w for w in report.messages if "Glow" in w], report.messages
    # negative: Emission Strength 0 emits nothing, and the program is dropped
    v.inputs["Emission Strength"].default_value = 0.0
    scene, report = export(addon)
    m = _by_name(scene, "Glow")
    assert [p["target"] for p in m["programs"]] == ["volume_absorption_color"]
    assert "flame_emission" not in m["volume"]
    # an Emission shader's Color: the same program, its factor the Strength
    mat2, nt2, out2 = _volume_only("Glow2")
    e = nt2.nodes.new("ShaderNodeEmission")
    e.inputs["Strength"].default_value = 5.0
    nt2.links.new(nt2.nodes.new("ShaderNodeTexGradient").outputs["Color"], e.inputs["Color"])
    nt2.links.new(e.outputs[0], out2.inputs["Volume"])
    add_plane(empty, material=mat2, name="Box2")
    scene, report = export(addon)
    m = _by_name(scene, "Glow2")
    assert [p["target"] for p in m["programs"]] == ["volume_emission_color"]
    np.testing.assert_allclose(m["volume"]["flame_emission"], [5.0] * 3, rtol=1e-6)
    assert not [w for w in report.messages if "Glow2" in w], report.messages


def test_mesh_emission_strength_graph(empty, addon):
    """A graph on a mesh volume's Emission Strength (issue 29): a "volume_emission" program,
    its factor (weight x the constant Emission Color) the volume's flame_emission and nothing
    of it in the constant emission, no warning; with an Emission Color graph on the same shader
    both programs and the factor the weight alone; an Emission shader's Strength the same with
    its Color. lt hands the scene to pt and auto leaves it to pt (an emissive volume). Control:
    the link removed, the socket's value is constant emission and no program is exported."""
    import lantern
    add_camera(empty)
    mat, nt, out = _volume_only("Flame")
    mix = nt.nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = 0.25
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Density"].default_value = 2.0
    v.inputs["Emission Strength"].default_value = 7.0   # the graph drives it
    v.inputs["Emission Color"].default_value = (1.0, 0.5, 0.25, 1)
    grad = nt.nodes.new("ShaderNodeTexGradient")
    nt.links.new(grad.outputs["Fac"], v.inputs["Emission Strength"])
    nt.links.new(v.outputs[0], mix.inputs[2])
    nt.links.new(nt.nodes.new("ShaderNodeVolumeScatter").outputs[0], mix.inputs[1])
    nt.links.new(mix.outputs[0], out.inputs["Volume"])
    add_plane(empty, material=mat, name="Box")
    scene, report = export(addon)
    m = _by_name(scene, "Flame")
    assert [p["target"] for p in m["programs"]] == ["volume_emission"]
    np.testing.assert_allclose(m["volume"]["flame_emission"], [0.25, 0.125, 0.0625], rtol=1e-6)
    np.testing.assert_allclose(m["volume"]["emission"], [0.0] * 3, atol=1e-9)
    assert not [w for w in report.messages if "Flame" in w], report.messages
    for integ, says in (("lt", "rendering with pt"), ("auto", "only pt renders")):
        s = lantern.Session(scene, integrator=integ, seed=1, spp_per_iteration=1, max_depth=2,
                            threads=1)
        s.step()
        assert any(says in w and "Flame" in w for w in s.warnings), (integ, s.warnings)
    # with an Emission Color graph: both programs, the factor the weight
    nt.links.new(nt.nodes.new("ShaderNodeTexNoise").outputs["Color"], v.inputs["Emission Color"])
    scene, report = export(addon)
    m = _by_name(scene, "Flame")
    assert sorted(p["target"] for p in m["programs"]) == ["volume_emission",
                                                          "volume_emission_color"]
    np.testing.assert_allclose(m["volume"]["flame_emission"], [0.25] * 3, rtol=1e-6)
    assert not [w for w in report.messages if "Flame" in w], report.messages
    # an Emission shader's Strength: its Color the factor
    mat2, nt2, out2 = _volume_only("Flame2")
    e = nt2.nodes.new("ShaderNodeEmission")
    e.inputs["Color"].default_value = (0.2, 0.4, 0.8, 1)
    nt2.links.new(nt2.nodes.new("ShaderNodeTexGradient").outputs["Fac"], e.inputs["Strength"])
    nt2.links.new(e.outputs[0], out2.inputs["Volume"])
    add_plane(empty, material=mat2, name="Box2")
    scene, report = export(addon)
    m2 = _by_name(scene, "Flame2")
    assert [p["target"] for p in m2["programs"]] == ["volume_emission"]
    np.testing.assert_allclose(m2["volume"]["flame_emission"], [0.2, 0.4, 0.8], rtol=1e-6)
    # control: no link, the socket's value (7) is constant emission
    nt.links.remove(v.inputs["Emission Strength"].links[0])
    nt.links.remove(v.inputs["Emission Color"].links[0])
    scene, report = export(addon)
    m = _by_name(scene, "Flame")
    assert not m.get("programs") and "flame_emission" not in m["volume"]
    np.testing.assert_allclose(m["volume"]["emission"], [1.75, 0.875, 0.4375], rtol=1e-6)


def test_colour_graphs_on_two_shaders(empty, addon):
    """A Color graph on a Volume Scatter added to a Principled Volume whose Absorption Color is
    a graph (issue 29): both programs, the scatterer's colour part in color_scatter, the
    Principled Volume's absorption max(1 - Color, 0) x Density in absorb_alone (its factor's
    alone) and its scattering constant, no warning. Control: the Color graph removed, the
    Absorption Color's shader is the colour shader again (color_base, color_absorb)."""
    add_camera(empty)
    mat, nt, out = _volume_only("Two")
    s = nt.nodes.new("ShaderNodeVolumeScatter")
    s.inputs["Density"].default_value = 3.0
    nt.links.new(nt.nodes.new("ShaderNodeTexGradient").outputs["Color"], s.inputs["Color"])
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Density"].default_value = 2.0
    v.inputs["Color"].default_value = (0.5, 0.6, 0.7, 1)
    nt.links.new(nt.nodes.new("ShaderNodeTexNoise").outputs["Color"], v.inputs["Absorption Color"])
    add = nt.nodes.new("ShaderNodeAddShader")
    nt.links.new(s.outputs[0], add.inputs[0])
    nt.links.new(v.outputs[0], add.inputs[1])
    nt.links.new(add.outputs[0], out.inputs["Volume"])
    add_plane(empty, material=mat, name="Box")
    scene, report = export(addon)
    m = _by_name(scene, "Two")
    assert sorted(p["target"] for p in m["programs"]) == ["volume_absorption_color",
                                                          "volume_color"]
    vol = m["volume"]
    np.testing.assert_allclose(vol["color_scatter"], [3.0] * 3, rtol=1e-6)
    np.testing.assert_allclose(vol["color_absorb"], [0.0] * 3, atol=1e-9)
    np.testing.assert_allclose(vol["absorb_alone"], [1.0, 0.8, 0.6], rtol=1e-5)
    np.testing.assert_allclose(vol["sigma_s"], [1.0, 1.2, 1.4], rtol=1e-6)
    np.testing.assert_allclose(vol["sigma_a"], [0.0] * 3, atol=1e-9)
    assert not [w for w in report.messages if "Two" in w], report.messages
    nt.links.remove(s.inputs["Color"].links[0])
    scene, report = export(addon)
    vol = _by_name(scene, "Two")["volume"]
    assert "absorb_alone" not in vol
    np.testing.assert_allclose(vol["color_absorb"], [2.0] * 3, rtol=1e-6)
    np.testing.assert_allclose(vol["color_base"], [0.5, 0.6, 0.7], rtol=1e-6)
    # the Absorption Color's shader white (it absorbs nothing): its graph is dropped, else the
    # core would apply its factor to the Color's shader's absorption
    nt.links.new(nt.nodes.new("ShaderNodeTexGradient").outputs["Color"], s.inputs["Color"])
    v.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1)
    scene, report = export(addon)
    m = _by_name(scene, "Two")
    assert [p["target"] for p in m["programs"]] == ["volume_color"]
    assert "absorb_alone" not in m["volume"]
