"""Shader nodes against Cycles, node by node: each case drives an emission-only material with
one node (or a short chain), rendered with one bounce by Lantern (pt) and by Cycles
(node_stage.py), each at 1 spp through the pixel centres: Cycles' sample 0 goes through the
centre (its filter sample is (0.5, 0.5), in every seed), and Lantern's pixel filter is narrowed
to FILTER_PX. So both images are the node's output at the pixel centres, with no filter
footprint left to straddle the node's discontinuities (checker edges, stepped ramps, saw
waves) and no noise: every pixel channel must agree within TOL (relative, 0.05 floor for values
near 0), none allowed beyond, and Lantern's image 1 % brighter or darker, or 5 % brighter on
one 8x8 block, must fail that (negative controls, tests/README.md). The sphere cases leave out
the silhouette ring (grazing normals there are the interpolation's, differently rounded).
Every case must vary over the image (a constant would pass anything) and export without a
warning. Voronoi hashes its integer cells with PCG (measured), White Noise the float bits of
its input (its cases use floored coordinates, which both renderers compute bit-exactly).
Blackbody and Wavelength are held to an independent computation (Planck and the CIE observer
integrated here, not with the exporter's code), Cycles' own blackbody being a fit."""

import numpy as np
import pytest

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)
import lantern  # noqa: E402

import node_stage as st  # noqa: E402
from nodes_common import (CASE_TOL, FILTER_PX, SPECTRAL_CYCLES, SPECTRAL_EXPECTED, SPECTRAL_TOL,
    TOL, _abs, _coord, _covered, _floored, _ident, _link, _node, _observer, assert_exact,
    render_cycles, render_lantern)  # noqa: E402
from nodes_cases import CASES, _image, mix_color, texcoord  # noqa: E402


def test_observer_table_gives_illuminant_a():
    """The observer's data (node_cie1931): CIE illuminant A, a Planckian radiator whose
    relative spectrum CIE 15 defines with c2 = 1.435e-2 m K at 2848 K, summed over the 5 nm
    rows from 380 to 780 nm, has the published chromaticity x, y = 0.44757, 0.40745 (CIE
    15:2004), here within the fifth digit's rounding; x-bar 1 % higher must miss it."""
    lam, cmf = _observer()
    rows = (lam >= 380.0) & (lam <= 780.0)
    s_a = 100.0 * (560.0 / lam[rows]) ** 5 * np.expm1(1.435e7 / (2848.0 * 560.0)) / \
        np.expm1(1.435e7 / (2848.0 * lam[rows]))

    def xy(obs):
        xyz = (s_a[:, None] * obs[rows]).sum(axis=0)
        return xyz[:2] / xyz.sum()

    tol = 1e-5
    got = xy(cmf)
    assert np.abs(got - (0.44757, 0.40745)).max() <= tol, got
    assert np.abs(xy(cmf * (1.01, 1.0, 1.0)) - (0.44757, 0.40745)).max() > tol


# Texture nodes with their Vector unlinked on the sphere: Blender reads Generated (UV for Image
# Texture), here varying in all three axes (the plane's cases above read a constant z of 0.5)
UNLINKED = {
    "checker": ("ShaderNodeTexChecker", "Color", None, {"Scale": 3.3}),
    "noise_3d": ("ShaderNodeTexNoise", "Color", None, {"Scale": 3.0, "Detail": 3.0}),
    "noise_4d": ("ShaderNodeTexNoise", "Fac", {"noise_dimensions": "4D"},
                 {"Scale": 2.5, "W": 0.4}),
    "noise_ridged": ("ShaderNodeTexNoise", "Fac", {"noise_type": "RIDGED_MULTIFRACTAL"},
                     {"Scale": 2.0, "Detail": 3.0}),
    "magic": ("ShaderNodeTexMagic", "Color", {"turbulence_depth": 3}, {"Scale": 2.5}),
    # (a sharp mortar: a smooth one's band is so steep that Generated's float rounding on
    # the sphere, 5e-7 between the two, moves its pixels by 4e-4)
    "brick": ("ShaderNodeTexBrick", "Color", None, {
        "Scale": 3.0, "Mortar": (0.1, 0.2, 0.3, 1.0), "Mortar Size": 0.05,
        "Mortar Smooth": 0.0}),
    "image_uv": ("ShaderNodeTexImage", "Color", None, {}),
    "voronoi_f1_distance": ("ShaderNodeTexVoronoi", "Distance", None, {"Scale": 5.0}),
    "voronoi_f1_color": ("ShaderNodeTexVoronoi", "Color", None, {"Scale": 5.0}),
    "voronoi_f1_position": ("ShaderNodeTexVoronoi", "Position", None, {"Scale": 3.0}),
    "voronoi_f2_chebychev": ("ShaderNodeTexVoronoi", "Distance", {
        "feature": "F2", "distance": "CHEBYCHEV"}, {"Scale": 4.0, "Randomness": 0.7}),
    "voronoi_f1_manhattan": ("ShaderNodeTexVoronoi", "Distance", {"distance": "MANHATTAN"},
                             {"Scale": 4.0}),
    "voronoi_smooth_f1_minkowski": ("ShaderNodeTexVoronoi", "Color", {
        "feature": "SMOOTH_F1", "distance": "MINKOWSKI"},
        {"Scale": 3.0, "Smoothness": 0.5, "Exponent": 0.8}),
    "voronoi_2d": ("ShaderNodeTexVoronoi", "Distance", {"voronoi_dimensions": "2D"},
                   {"Scale": 5.0}),
    # (every distance above 8, where Lantern's search used to start: 684 of 2496 channels off;
    # its Distance, (sum |d|^0.3)^(1/0.3), carries float rounding up to 4.8e-4: Color only)
    "voronoi_minkowski_exponent_0_3": ("ShaderNodeTexVoronoi", "Color", {
        "distance": "MINKOWSKI"}, {"Scale": 3.0, "Exponent": 0.3}),
}
for _g in ("LINEAR", "QUADRATIC", "EASING", "DIAGONAL", "SPHERICAL", "QUADRATIC_SPHERE",
           "RADIAL"):
    UNLINKED[f"gradient_{_g.lower()}"] = ("ShaderNodeTexGradient", "Color",
                                          {"gradient_type": _g}, {})
for _t, _dirs in (("BANDS", ("X", "Y", "Z", "DIAGONAL")), ("RINGS", ("X", "Y", "Z",
                                                                      "SPHERICAL"))):
    for _d, _profile in zip(_dirs, ("SIN", "SAW", "TRI", "SIN")):
        UNLINKED[f"wave_{_t.lower()}_{_d.lower()}_{_profile.lower()}"] = (
            "ShaderNodeTexWave", "Color", {"wave_type": _t, f"{_t.lower()}_direction": _d,
                                           "wave_profile": _profile},
            {"Scale": 1.3, "Distortion": 1.5, "Detail": 2.0})


def unlinked(idname, out, props, inputs):
    def build(nt, emit):
        n = _node(nt, idname, props, **inputs)
        if idname == "ShaderNodeTexImage":
            n.image = _image()
        assert not n.inputs["Vector"].is_linked
        if out == "Position":   # signed
            nt.links.new(_abs(nt, n.outputs[out], 0.5), emit.inputs["Color"])
        else:
            _link(nt, n, out, emit)
    return build


for _name, _spec in UNLINKED.items():
    CASES[f"{_name}_unlinked_sphere"] = ("sphere", unlinked(*_spec))


def white_noise_unlinked(dim, vector=None):
    """White Noise with its Vector unlinked: Cycles reads the socket's value there (no
    implicit Generated), so the case varies through W (4D: floored Generated X) alone."""
    def build(nt, emit):
        n = nt.nodes.new("ShaderNodeTexWhiteNoise")
        n.noise_dimensions = dim
        if vector is not None:
            n.inputs["Vector"].default_value = vector
        x = nt.nodes.new("ShaderNodeSeparateXYZ")
        nt.links.new(_floored(nt), x.inputs[0])
        nt.links.new(x.outputs["X"], _ident(n, "W"))
        assert not n.inputs["Vector"].is_linked
        _link(nt, n, "Color", emit)
    return build


def deform(kind):
    """Deforms the sphere (modifiers, a shape key): Generated stays on the undeformed mesh."""
    obj = bpy.data.objects["Sphere"]
    if kind == "twist":
        m = obj.modifiers.new("Twist", "SIMPLE_DEFORM")
        m.deform_method, m.angle = "TWIST", 0.8
    elif kind == "displace":   # no texture: along the normals by strength x (1 - midlevel)
        obj.modifiers.new("Displace", "DISPLACE").strength = 0.3
    elif kind == "shape_key":
        obj.shape_key_add(name="Basis")
        key = obj.shape_key_add(name="Lean")
        co = np.empty(3 * len(key.data), np.float32)
        key.data.foreach_get("co", co)
        co = co.reshape(-1, 3)
        co[:, 0] *= 1.0 + 0.4 * co[:, 2]
        key.data.foreach_set("co", co.ravel())
        key.value = 0.7
    elif kind == "subsurf_bend":   # builds, then deforms
        obj.modifiers.new("Subdivision", "SUBSURF").render_levels = 1
        m = obj.modifiers.new("Bend", "SIMPLE_DEFORM")
        m.deform_method, m.angle = "BEND", 0.8
    else:
        raise ValueError(kind)


def deformed(kind, build):
    def run(nt, emit):
        deform(kind)
        build(nt, emit)
    return run


def voronoi_dims(dim, feature, metric, out, **inputs):
    """1D and 4D Voronoi on the sphere: 4D with its Vector unlinked and W set, 1D over W
    linked to 2.7 x Generated X (1D reads no vector). The W output as emission strength."""
    def build(nt, emit):
        n = _node(nt, "ShaderNodeTexVoronoi", {"voronoi_dimensions": dim, "feature": feature,
                                               "distance": metric}, **inputs)
        if dim == "1D":
            x = nt.nodes.new("ShaderNodeSeparateXYZ")
            nt.links.new(_coord(nt), x.inputs[0])
            m = _node(nt, "ShaderNodeMath", {"operation": "MULTIPLY"})
            nt.links.new(x.outputs["X"], m.inputs[0])
            m.inputs[1].default_value = 2.7
            nt.links.new(m.outputs[0], _ident(n, "W"))
        else:
            _ident(n, "W").default_value = 0.7
        if out == "W":
            nt.links.new(n.outputs["W"], emit.inputs["Strength"])
        elif out == "Position":
            nt.links.new(_abs(nt, n.outputs[out], 0.5), emit.inputs["Color"])
        else:
            _link(nt, n, out, emit)
    return build


def voronoi_linked_randomness(value):
    """Randomness from a link, outside [0, 1]: Cycles clamps it there."""
    def build(nt, emit):
        n = _node(nt, "ShaderNodeTexVoronoi", Scale=4.0)
        v = nt.nodes.new("ShaderNodeValue")
        v.outputs[0].default_value = value
        nt.links.new(v.outputs[0], n.inputs["Randomness"])
        _link(nt, n, "Color", emit)
    return build


for _dim, _feature, _metric, _out in (
        ("4D", "F1", "EUCLIDEAN", "Color"), ("4D", "F2", "MANHATTAN", "Distance"),
        ("4D", "SMOOTH_F1", "EUCLIDEAN", "Color"), ("4D", "F1", "CHEBYCHEV", "Position"),
        ("4D", "F1", "MINKOWSKI", "W"), ("1D", "F1", "EUCLIDEAN", "Color"),
        ("1D", "F2", "EUCLIDEAN", "Distance"), ("1D", "SMOOTH_F1", "EUCLIDEAN", "Distance"),
        ("1D", "F1", "EUCLIDEAN", "W")):
    CASES[f"voronoi_{_dim.lower()}_{_feature.lower()}_{_metric.lower()}_{_out.lower()}"] = (
        "sphere", voronoi_dims(_dim, _feature, _metric, _out, Scale=3.0, Exponent=1.5,
                               Smoothness=0.6, Randomness=0.9))
CASES["voronoi_randomness_linked_above_one"] = ("plane", voronoi_linked_randomness(1.6))
CASES["voronoi_randomness_linked_below_zero"] = ("plane", voronoi_linked_randomness(-0.3))
CASES["texcoord_generated_twisted_sphere"] = ("sphere", deformed("twist",
                                                                 texcoord("Generated")))
CASES["voronoi_f1_unlinked_displaced_sphere"] = ("sphere", deformed(
    "displace", unlinked(*UNLINKED["voronoi_f1_distance"])))
CASES["wave_unlinked_shape_key_sphere"] = ("sphere", deformed(
    "shape_key", unlinked(*UNLINKED["wave_bands_x_sin"])))
CASES["white_noise_4d_unlinked_sphere"] = ("sphere", white_noise_unlinked("4D"))
CASES["white_noise_4d_unlinked_vector_set"] = ("plane", white_noise_unlinked(
    "4D", (0.3, -1.7, 2.25)))
for _blend in ("MIX", "DARKEN", "MULTIPLY", "BURN", "LIGHTEN", "SCREEN", "DODGE", "ADD",
               "OVERLAY", "SOFT_LIGHT", "LINEAR_LIGHT", "DIFFERENCE", "EXCLUSION", "SUBTRACT",
               "DIVIDE", "HUE", "SATURATION", "COLOR", "VALUE"):
    CASES[f"mix_{_blend.lower()}"] = ("plane", mix_color(_blend))


@pytest.fixture(scope="module", autouse=True)
def _addon():
    st.addon()


@pytest.mark.parametrize("case", sorted(CASES))
def test_node_output_matches_cycles(case, tmp_path):
    shape, build = CASES[case]
    sc, nt, emit = st.stage(shape)
    build(nt, emit)
    img_l, warnings = render_lantern()
    img_c = render_cycles(sc, tmp_path / "cycles.exr")
    assert warnings == []
    covered = _covered(shape, img_c)
    assert np.std(img_c[covered]) > 0.01, "the case does not vary: it would test nothing"
    if case in SPECTRAL_CYCLES:   # against the independent computation; Cycles within its bound
        expected = SPECTRAL_EXPECTED[case](img_c.shape[1])
        assert_exact(case, img_l, np.broadcast_to(expected, img_l.shape).copy(),
                     tol=SPECTRAL_TOL[case])
        tol, floor = SPECTRAL_CYCLES[case]
        if case == "wavelength":   # Cycles' own table and matrix: with the controls too
            assert_exact(case, img_l, img_c, tol=tol, floor=floor)
        else:   # Cycles' fit: a bound
            err = st.relative_error(img_l, img_c, floor).max()
            assert err <= tol, f"{case}: worst error against Cycles {err:.4f} > {tol}"
        return
    assert_exact(case, img_l, img_c, covered, *CASE_TOL.get(case, (TOL, 0.05)))


# ---- Generated through a final render: its depsgraph computes Blender's undeformed
# coordinates (ORCO) for every mesh, carried through the modifiers that build (Array,
# Subdivision) but not those that deform, which no viewport depsgraph without a 3D view has, so
# test_node_output_matches_cycles never reads them. The engine's own export is rendered at the
# pixel centres (the F12 it ran is discarded).
@pytest.mark.parametrize("stack", ["array_twist", "subsurf_bend"])
def test_generated_through_final_render(stack, tmp_path, monkeypatch):
    import importlib
    sc, nt, emit = st.stage("sphere")
    obj = bpy.data.objects["Sphere"]
    if stack == "array_twist":
        a = obj.modifiers.new("Array", "ARRAY")
        a.count, a.relative_offset_displace = 2, (0.5, 0.0, 0.0)
        m = obj.modifiers.new("Twist", "SIMPLE_DEFORM")
        m.deform_method, m.angle = "TWIST", 0.8
    else:
        deform("subsurf_bend")
    texcoord("Generated")(nt, emit)
    export = importlib.import_module("lantern_blender.export")
    captured = []

    def capture(depsgraph, **kw):   # kw: the engine's frame_set (motion blur's steps)
        captured.append((depsgraph.mode, *export_scene(depsgraph, **kw)))
        return captured[-1][1:]

    export_scene = export.export_scene
    monkeypatch.setattr(export, "export_scene", capture)
    sc.render.engine = "LANTERN"
    sc.lantern.samples, sc.lantern.max_depth, sc.lantern.integrator = 1, 1, "pt"
    sc.render.filepath = str(tmp_path / "f12.exr")
    bpy.ops.render.render(write_still=False)
    monkeypatch.undo()
    assert [c[0] for c in captured] == ["RENDER"], "the engine's export did not run"
    _, scene, report = captured[0]
    assert list(report.messages) == []
    scene.film["filter_width"] = FILTER_PX
    img_l = np.asarray(lantern.render(scene, spp=1, integrator="pt", max_depth=1, seed=1),
                       np.float64)
    img_c = render_cycles(sc, tmp_path / "cycles.exr")
    covered = _covered("sphere", img_c)
    assert np.std(img_c[covered]) > 0.01
    assert_exact(f"generated_final_render_{stack}", img_l, img_c, covered)
    # and the viewport depsgraph's export, which has no ORCO here, says what it cannot do
    _, warnings = render_lantern()
    assert any("Generated coordinates follow the deformed mesh" in w for w in warnings), warnings
