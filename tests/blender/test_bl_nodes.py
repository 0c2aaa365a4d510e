"""Node graphs through the add-on (material_compile): graph clean-up (groups, reroutes, muted
nodes) gives the same program as the plain graph, a material without graphs carries none, and
bad input (cycles, unknown or newer node types, missing images, NaN and huge values) renders a
finite image with a warning naming the problem. The node outputs themselves are checked
against Cycles in tests/cycles/test_nodes.py."""

import math

import bpy
import numpy as np
import pytest

from blender_helpers import add_camera, add_plane

lantern = pytest.importorskip("lantern")


def _export():
    from lantern_blender.export import export_scene
    return export_scene(bpy.context.evaluated_depsgraph_get())


def _material(name="Graph"):
    """A Principled material; returns (material, tree, principled node)."""
    mat = bpy.data.materials.new(name)
    nt = mat.node_tree
    return mat, nt, nt.nodes["Principled BSDF"]


def _scene_with(mat, scene):
    add_camera(scene, location=(0, 0, 3))
    plane = add_plane(scene, size=2.0, material=mat)
    plane.data.uv_layers.new(name="UV")
    light = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    scene.collection.objects.link(light)
    return plane


def _render(scene_obj, spp=2):
    img = lantern.render(scene_obj, spp=spp, integrator="pt", max_depth=2, seed=3)
    return np.asarray(img)


def _checker_into(nt, socket):
    c = nt.nodes.new("ShaderNodeTexChecker")
    c.inputs["Scale"].default_value = 4.0
    nt.links.new(c.outputs["Color"], socket)
    return c


def test_plain_materials_carry_no_program(empty):
    mat, nt, bsdf = _material()
    _scene_with(mat, empty)
    scene, report = _export()
    assert all("programs" not in m for m in scene.materials)
    assert scene.attribute_channels == []
    assert "node_programs" not in scene.to_native()


def test_graph_exports_a_program_and_renders_it(empty):
    mat, nt, bsdf = _material()
    _checker_into(nt, bsdf.inputs["Base Color"])
    _scene_with(mat, empty)
    scene, report = _export()
    assert report.messages == []
    progs = scene.materials[1]["programs"]
    assert [p["target"] for p in progs] == ["base_color"]
    assert scene.attribute_channels == ["generated"]
    img = _render(scene)
    assert np.isfinite(img).all()
    # the checker shows: the plane's centre rows hold both colours (Color1 0.8, Color2 0.2
    # under the same light), where the old fallback rendered one constant
    row = img[img.shape[0] // 2, img.shape[1] // 4: 3 * img.shape[1] // 4].mean(axis=1)
    assert row.max() > 2.5 * row.min() > 0.0


def test_group_reroute_and_muted_node_give_the_plain_program(empty):
    # plain: checker -> Base Color
    mat, nt, bsdf = _material("Plain")
    _checker_into(nt, bsdf.inputs["Base Color"])
    # same through a node group (with the checker inside), a reroute and a muted Invert
    mat2, nt2, bsdf2 = _material("Wrapped")
    group = bpy.data.node_groups.new("G", "ShaderNodeTree")
    group.interface.new_socket("Out", in_out="OUTPUT", socket_type="NodeSocketColor")
    group.interface.new_socket("S", in_out="INPUT", socket_type="NodeSocketFloat")
    gin, gout = group.nodes.new("NodeGroupInput"), group.nodes.new("NodeGroupOutput")
    chk = group.nodes.new("ShaderNodeTexChecker")
    group.links.new(gin.outputs[0], chk.inputs["Scale"])
    group.links.new(chk.outputs["Color"], gout.inputs[0])
    gnode = nt2.nodes.new("ShaderNodeGroup")
    gnode.node_tree = group
    gnode.inputs[0].default_value = 4.0
    reroute = nt2.nodes.new("NodeReroute")
    inv = nt2.nodes.new("ShaderNodeInvert")
    inv.mute = True
    nt2.links.new(gnode.outputs[0], reroute.inputs[0])
    nt2.links.new(reroute.outputs[0], inv.inputs["Color"])
    nt2.links.new(inv.outputs[0], bsdf2.inputs["Base Color"])
    _scene_with(mat, empty)
    add_plane(empty, size=1.0, location=(5, 0, 0), material=mat2, name="Other")
    scene, report = _export()
    assert report.messages == []
    by_name = {m["name"]: m for m in scene.materials}
    a, b = by_name["Plain"]["programs"][0], by_name["Wrapped"]["programs"][0]
    assert a["code"] == b["code"] and a["consts"] == b["consts"]


def test_unknown_and_newer_nodes_warn_by_name(empty):
    mat, nt, bsdf = _material()
    gabor = nt.nodes.new("ShaderNodeTexGabor")       # not evaluated by Lantern (yet)
    gabor.name = "Ripples"
    nt.links.new(gabor.outputs["Value"], bsdf.inputs["Base Color"])
    _scene_with(mat, empty)
    scene, report = _export()
    assert any("Ripples" in m and "TEX_GABOR" in m for m in report.messages), report.messages
    assert np.isfinite(_render(scene)).all()


def test_cycle_in_a_graph_warns_and_renders(empty):
    mat, nt, bsdf = _material()
    a, b = nt.nodes.new("ShaderNodeMath"), nt.nodes.new("ShaderNodeMath")
    nt.links.new(a.outputs[0], b.inputs[0])
    nt.links.new(b.outputs[0], a.inputs[0])     # Blender marks one of the two invalid
    nt.links.new(b.outputs[0], bsdf.inputs["Roughness"])
    _scene_with(mat, empty)
    scene, report = _export()
    assert any("invalid" in m and "cycle" in m for m in report.messages), report.messages
    assert np.isfinite(_render(scene)).all()


def test_missing_image_in_a_graph_is_magenta_with_a_warning(empty):
    mat, nt, bsdf = _material()
    img = nt.nodes.new("ShaderNodeTexImage")          # no image
    img.name = "Nothing"
    mapping = nt.nodes.new("ShaderNodeMapping")
    nt.links.new(nt.nodes.new("ShaderNodeTexCoord").outputs["UV"], mapping.inputs[0])
    nt.links.new(mapping.outputs[0], img.inputs["Vector"])
    emit = nt.nodes.new("ShaderNodeEmission")
    nt.links.new(img.outputs["Color"], emit.inputs["Color"])
    nt.links.new(emit.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    _scene_with(mat, empty)
    scene, report = _export()
    assert any("Nothing" in m and "no image" in m for m in report.messages), report.messages
    out = _render(scene)
    centre = out[out.shape[0] // 2, out.shape[1] // 2]
    assert np.isfinite(out).all()
    assert centre[0] > 0.5 and centre[1] < 0.05 and centre[2] > 0.5   # magenta


@pytest.mark.parametrize("value", [math.nan, math.inf, 1e30, -1e30])
def test_nan_and_huge_values_render_finite(empty, value):
    mat, nt, bsdf = _material()
    v = nt.nodes.new("ShaderNodeValue")
    v.outputs[0].default_value = value
    m = nt.nodes.new("ShaderNodeMath")
    m.operation = "MULTIPLY"
    nt.links.new(v.outputs[0], m.inputs[0])
    nt.links.new(nt.nodes.new("ShaderNodeTexNoise").outputs["Fac"], m.inputs[1])
    nt.links.new(m.outputs[0], bsdf.inputs["Base Color"])
    nt.links.new(m.outputs[0], bsdf.inputs["Roughness"])
    nt.links.new(m.outputs[0], bsdf.inputs["Emission Strength"])
    _scene_with(mat, empty)
    scene, report = _export()
    out = _render(scene)
    assert np.isfinite(out).all()


def test_fresnel_mix_factor_drives_the_mix(empty):
    mat = bpy.data.materials.new("Rim")
    nt = mat.node_tree
    for n in list(nt.nodes):
        if n.type != "OUTPUT_MATERIAL":
            nt.nodes.remove(n)
    mix = nt.nodes.new("ShaderNodeMixShader")
    nt.links.new(nt.nodes.new("ShaderNodeFresnel").outputs[0], mix.inputs["Fac"])
    nt.links.new(nt.nodes.new("ShaderNodeBsdfDiffuse").outputs[0], mix.inputs[1])
    nt.links.new(nt.nodes.new("ShaderNodeBsdfGlossy").outputs[0], mix.inputs[2])
    nt.links.new(mix.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    _scene_with(mat, empty)
    scene, report = _export()
    assert report.messages == []
    top = next(m for m in scene.materials if m["name"] == "Rim")
    assert top["type"] == "mix"
    assert [p["target"] for p in top["programs"]] == ["mix_factor"]


def test_programs_survive_the_scene_file(empty, tmp_path):
    mat, nt, bsdf = _material()
    _checker_into(nt, bsdf.inputs["Base Color"])
    _scene_with(mat, empty)
    scene, report = _export()
    path = tmp_path / "graph.lantern"
    scene.save(path)
    again = lantern.load_scene(path)
    assert again.attribute_channels == scene.attribute_channels
    assert again.materials[1]["programs"] == scene.materials[1]["programs"]
    assert np.array_equal(_render(again), _render(scene))   # same seed: the same image



# ---- Shading by a bent normal, exactly: a Lambert plane under one sharp sun ----
# _scene_with's plane (2 m at the origin, seen from 3 m with the 50 mm lens: 0.0675 m a pixel,
# every row and columns 3..28 on it, the filter's +-1.5 px included) as white Lambert (Principled
# with Specular IOR Level 0, docs/materials.md) under a sharp sun off the vertical and no world,
# pt: each sample sees the one light once, so a pixel reads rho E max(0, n . l) / pi to float
# rounding, whatever the filter, where the shading normal n is constant over its footprint,
# times the bump shadowing term Lantern's bumped Lambert takes from Cycles (_lambert)
SUN_E, ALBEDO, SUN_ROT = 2.0, 0.8, (0.55, -0.35, 0.0)
PLANE_COLS = slice(3, 29)
EXACT_RTOL = 1e-5   # float rounding
BUMP_RTOL = 2e-4    # and the bump's forward difference in float (kBumpStep): 8.5e-5 measured


def _lambert_under_sun(scene, bsdf):
    import mathutils
    bsdf.inputs["Base Color"].default_value = (ALBEDO, ALBEDO, ALBEDO, 1.0)
    bsdf.inputs["Specular IOR Level"].default_value = 0.0
    sun = bpy.data.lights["Sun"]
    sun.energy, sun.angle = SUN_E, 0.0
    bpy.data.objects["Sun"].rotation_euler = SUN_ROT
    uv = bpy.data.objects["Plane"].data.uv_layers["UV"]
    for loop, st in zip(uv.data, [(0, 0), (1, 0), (1, 1), (0, 1)]):  # u along +x, v along +y
        loop.uv = st
    # the sun shines along its -Z: towards it is its +Z
    return np.array(mathutils.Euler(SUN_ROT).to_matrix() @ mathutils.Vector((0, 0, 1)))


def _lambert(n, to_sun):
    """rho E max(0, n . l) / pi, times Cycles' bump shadowing term, which Lantern's bumped
    Lambert applies (bsdf/lambert.h, docs/nodes.md "Bump and displacement"): the GGX masking G1
    with alpha^2 = min(tan^2(n, z) / 8, 1) at the sun's angle to the plane's own normal +z; 1
    for the unbent normal."""
    n = np.asarray(n, np.float64) / np.linalg.norm(n)
    cos_l = float(n @ to_sun)
    alpha2 = min((1.0 / n[2] ** 2 - 1.0) / 8.0, 1.0)
    g = 2.0 / (1.0 + math.sqrt(1.0 + alpha2 * (1.0 / to_sun[2] ** 2 - 1.0)))
    return ALBEDO * SUN_E / math.pi * max(0.0, cos_l) * g


def _assert_shading(name, img, expected, wrong, rtol=EXACT_RTOL):
    """img (H, W, 3) against the exact shading `expected` ((H, W) or scalar) per pixel to
    `rtol` (no noise: a 1 % bias fails by far); `wrong`, the shading of a normal a little off
    (the control: a bump distance or a strength 5 % short), must fail it by 10x."""
    img = np.asarray(img, np.float64)[..., :3]
    expected = np.broadcast_to(np.asarray(expected, np.float64)[..., None], img.shape)
    wrong = np.broadcast_to(np.asarray(wrong, np.float64)[..., None], img.shape)
    err = np.abs(img / expected - 1.0)
    off = np.abs(img / wrong - 1.0)
    print(f"{name}: max rel. error {err.max():.2e} (allowed {rtol:.0e}); against the "
          f"control's normal {off.min():.2e} at least")
    assert err.max() <= rtol, (name, err.max())
    assert off.min() > 10 * rtol, (name, "control", off.min())


def _bump_material(name="Bumpy", height_node="ShaderNodeTexNoise"):
    mat, nt, bsdf = _material(name)
    h = nt.nodes.new(height_node)
    bump = nt.nodes.new("ShaderNodeBump")
    bump.inputs["Distance"].default_value = 0.2
    nt.links.new(h.outputs[0], bump.inputs["Height"])
    nt.links.new(bump.outputs[0], bsdf.inputs["Normal"])
    return mat, nt, bsdf, bump


def test_bump_exports_a_program_and_bends_the_image(empty):
    """A Bump fed by another Bump, on heights of constant slope (the Object coordinates' x
    under the inner one, y under the outer one): two programs, and the plane shaded by the
    bent normal exactly. Blender's Bump over a normal n with a height of surface gradient g
    gives n |det| - d g (Mikkelsen 2010, eq. 4; Cycles' svm bump): the inner one bends z to
    (-d1, 0, 1) / s1 (s1 = sqrt(1 + d1^2)); the outer one's surface gradient over that normal
    is y scaled by n_z, so it gives n - d2 y: (-d1, -d2 s1, 1) up to length."""
    mat, nt, bsdf = _material("Bumpy")
    sep = nt.nodes.new("ShaderNodeSeparateXYZ")
    nt.links.new(nt.nodes.new("ShaderNodeTexCoord").outputs["Object"], sep.inputs[0])
    inner, outer = nt.nodes.new("ShaderNodeBump"), nt.nodes.new("ShaderNodeBump")
    d1, d2 = 0.3, 0.2
    inner.inputs["Distance"].default_value = d1
    outer.inputs["Distance"].default_value = d2
    nt.links.new(sep.outputs["X"], inner.inputs["Height"])
    nt.links.new(sep.outputs["Y"], outer.inputs["Height"])
    nt.links.new(inner.outputs[0], outer.inputs["Normal"])   # a chain: the inner bump first
    nt.links.new(outer.outputs[0], bsdf.inputs["Normal"])
    _scene_with(mat, empty)
    to_sun = _lambert_under_sun(empty, bsdf)
    scene, report = _export()
    assert report.messages == []
    progs = scene.materials[1]["programs"]
    assert [p["target"] for p in progs] == ["bump", "bump"]
    s1 = math.hypot(1.0, d1)
    bumped = _render(scene)[:, PLANE_COLS]
    _assert_shading("two bumps", bumped, _lambert((-d1, -d2 * s1, 1.0), to_sun),
                    _lambert((-d1, -0.95 * d2 * s1, 1.0), to_sun), BUMP_RTOL)  # outer 5 % short
    nt.links.remove(bsdf.inputs["Normal"].links[0])
    flat_scene, _ = _export()
    assert "programs" not in flat_scene.materials[1]
    _assert_shading("no bump", _render(flat_scene)[:, PLANE_COLS], _lambert((0, 0, 1), to_sun),
                    _lambert((-d1, -d2 * s1, 1.0), to_sun))


def test_constant_bump_and_displacement_as_bump(empty):
    mat, nt, bsdf, bump = _bump_material(height_node="ShaderNodeValue")
    disp = nt.nodes.new("ShaderNodeDisplacement")
    nt.links.new(nt.nodes.new("ShaderNodeTexVoronoi").outputs["Distance"], disp.inputs["Height"])
    nt.links.new(disp.outputs[0], nt.nodes["Material Output"].inputs["Displacement"])
    _scene_with(mat, empty)
    scene, report = _export()
    assert report.messages == []   # Bump Only (the default method) renders: no warning
    # the constant height bends nothing (no program); the displacement is one program
    assert [p["target"] for p in scene.materials[1]["programs"]] == ["displacement"]
    assert np.isfinite(_render(scene)).all()
    mat.displacement_method = "BOTH"
    _, report = _export()
    assert any("true displacement" in m and "'BOTH'" in m for m in report.messages), \
        report.messages
    nt.links.new(nt.nodes.new("ShaderNodeVectorDisplacement").outputs[0],
                 nt.nodes["Material Output"].inputs["Displacement"])
    _, report = _export()
    assert any("VECTOR_DISPLACEMENT" in m for m in report.messages), report.messages


def test_normal_map_fed_by_a_graph_exports_a_program(empty):
    """A Normal Map whose Color a graph drives: a normal_map program (strength beside it)
    that bends the image; on Coat Normal it warns by name (images only there)."""
    mat, nt, bsdf = _material("Mapped")
    nm = nt.nodes.new("ShaderNodeNormalMap")
    nm.inputs["Strength"].default_value = 0.7
    # the graph: colour A where the Object x < 0, B where x > 0 (a Mix by x > 0)
    colours = ((0.6, 0.45, 0.9), (0.35, 0.6, 0.85))
    sep = nt.nodes.new("ShaderNodeSeparateXYZ")
    nt.links.new(nt.nodes.new("ShaderNodeTexCoord").outputs["Object"], sep.inputs[0])
    step = nt.nodes.new("ShaderNodeMath")
    step.operation = "GREATER_THAN"
    step.inputs[1].default_value = 0.0
    nt.links.new(sep.outputs["X"], step.inputs[0])
    mix = nt.nodes.new("ShaderNodeMix")
    mix.data_type = "RGBA"
    sock = {s.identifier: s for s in mix.inputs}
    sock["A_Color"].default_value, sock["B_Color"].default_value = [(*c, 1.0) for c in colours]
    nt.links.new(step.outputs[0], sock["Factor_Float"])
    nt.links.new(next(s for s in mix.outputs if s.identifier == "Result_Color"),
                 nm.inputs["Color"])
    nt.links.new(nm.outputs[0], bsdf.inputs["Normal"])
    _scene_with(mat, empty)
    to_sun = _lambert_under_sun(empty, bsdf)
    scene, report = _export()
    assert report.messages == []
    m = scene.materials[1]
    assert [p["target"] for p in m["programs"]] == ["normal_map"]
    assert m["normal_strength"] == pytest.approx(0.7)

    def mapped_normal(c, strength=0.7):
        # tangent space (the plane's u along x, v along y: x, y, z), then Blender's Strength:
        # n + (mapped - n) strength, renormalised
        t = 2.0 * np.asarray(c) - 1.0
        t /= np.linalg.norm(t)
        return np.array([0.0, 0.0, 1.0]) + (t - [0.0, 0.0, 1.0]) * strength

    mapped = _render(scene)
    for c, cols in zip(colours, (slice(3, 14), slice(18, 29))):  # the halves, off x = 0
        _assert_shading(f"normal map {c}", mapped[:, cols], _lambert(mapped_normal(c), to_sun),
                        _lambert(mapped_normal(c, 0.665), to_sun))   # strength 5 % short
    nt.links.remove(bsdf.inputs["Normal"].links[0])
    _assert_shading("no normal map", _render(_export()[0])[:, PLANE_COLS],
                    _lambert((0, 0, 1), to_sun), _lambert(mapped_normal(colours[0]), to_sun))
    # in a shader mix the mix carries it (a mix bends one normal)
    nt.links.new(nm.outputs[0], bsdf.inputs["Normal"])
    mix = nt.nodes.new("ShaderNodeMixShader")
    nt.links.new(bsdf.outputs[0], mix.inputs[1])
    nt.links.new(nt.nodes.new("ShaderNodeBsdfDiffuse").outputs[0], mix.inputs[2])
    nt.links.new(mix.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    scene, report = _export()
    top = next(m for m in scene.materials if m.get("type") == "mix")
    assert [p["target"] for p in top["programs"]] == ["normal_map"]
    assert top["normal_strength"] == pytest.approx(0.7)
    nt.links.new(bsdf.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    bsdf.inputs["Specular IOR Level"].default_value = 0.5   # a Principled again, not Lambert
    bsdf.inputs["Coat Weight"].default_value = 0.5
    nt.links.new(nm.outputs[0], bsdf.inputs["Coat Normal"])
    _, report = _export()
    assert any("Normal Map 'Normal Map'" in w and "Coat Normal" in w for w in report.messages), \
        report.messages


def test_light_node_tree_scales_the_light(empty):
    from lantern_blender.export import node_spectral
    _scene_with(_material()[0], empty)
    lamp = bpy.data.lights["Sun"]
    lamp.energy = 2.0
    lamp.use_nodes = True
    lt = lamp.node_tree
    emit = next(n for n in lt.nodes if n.type == "EMISSION")
    bb = lt.nodes.new("ShaderNodeBlackbody")
    bb.inputs["Temperature"].default_value = 3000.0
    m = lt.nodes.new("ShaderNodeMath")           # folds to a constant: 1.5
    m.inputs[0].default_value, m.inputs[1].default_value = 0.5, 1.0
    lt.links.new(bb.outputs[0], emit.inputs["Color"])
    lt.links.new(m.outputs[0], emit.inputs["Strength"])
    scene, report = _export()
    assert report.messages == []
    sun = next(x for x in scene.lights if x["type"] == "sun")
    want = [2.0 * 1.5 * c for c in node_spectral.blackbody_rgb(3000.0)]
    assert sun["strength"] == pytest.approx(want, rel=1e-4)
    assert sun["strength"][0] > 1.5 * sun["strength"][2]   # warm


def test_procedural_world_bakes_an_environment_map(empty):
    _scene_with(_material()[0], empty)
    world = bpy.data.worlds.new("Sky")
    empty.world = world
    nt = world.node_tree
    bg = nt.nodes["Background"]
    grad = nt.nodes.new("ShaderNodeTexGradient")   # along Generated X: the direction's x
    nt.links.new(grad.outputs["Color"], bg.inputs["Color"])
    bg.inputs["Strength"].default_value = 2.0
    scene, report = _export()
    assert report.messages == []
    w = scene.world
    h, wd = w["map"].shape[:2]
    assert (h, wd) == (512, 1024) and np.isfinite(w["map"]).all()
    # texel (x, y) -> direction x = cos(elevation) cos(phi) (scene/envmap.h): texel W/2 of the
    # middle row faces +x (gradient ~1, strength 2), texel 0 faces -x (gradient 0, clamped)
    row = w["map"][h // 2]
    x = math.cos(math.pi / (2 * h)) * math.cos(math.pi / wd)
    assert row[wd // 2, 0] == pytest.approx(2.0 * x, rel=1e-3)
    assert row[0, 0] == 0.0
    assert np.isfinite(_render(scene)).all()
    nt.links.remove(bg.inputs["Color"].links[0])
    scene, _ = _export()
    assert "map" not in scene.world   # a constant world stays a colour
