"""False-alarm families issue 19 found unmeasured: depth of field (dof_moments, dof), F12
regions and border (bl_region, bl_border), texels, node_integrators, bounces. A family whose
test is not compare_renders gives its own rule as kw["compare"] (_moments_rule, _region_rule)."""

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[3]   # the checkout: the families render its tests' scenes
sys.path.insert(0, str(ROOT / "tools"))      # render_compare, lantern_bpy

import lantern  # noqa: E402
from lantern.testing.fa_bl_scenes import _BL_SCENES, _bl_empty_scene  # noqa: E402
from lantern.testing.fa_lantern import sets  # noqa: E402


# ---- The families issue 19 found unmeasured (DOF, F12 regions and border, texels, nodes) ----
# A family whose test is not compare_renders gives its own rule as kw["compare"]: called as
# compare(a, b, alpha=..., **kw), it returns .passed and .blocks.p, .blocks.n (Bonferroni n).


def _tested(passed, p, n):
    from types import SimpleNamespace
    return SimpleNamespace(passed=passed, blocks=SimpleNamespace(p=np.atleast_1d(p), n=n))


def _moments_rule(checks, _unused, alpha=1e-3, cap=0.0):
    """test_camera_dof._moment_test on each (a, b, exact): fails where any check does (each at
    `alpha`, as the test: three checks, no Bonferroni); p: each check's two-sided t tail of
    its excess over the cap."""
    from lantern import student_t
    ok, ps = True, []
    for a, b, exact in checks:
        a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
        se2a, se2b = a.var(ddof=1) / len(a), b.var(ddof=1) / len(b)
        rel = (a.mean() - b.mean()) / exact - 1.0
        se = np.sqrt(se2a + se2b) / abs(exact)
        dof = float(student_t.welch_dof(se2a, len(a), se2b, len(b)))
        ok &= abs(rel) <= cap + student_t.quantile(alpha, dof) * se
        ps.append(float(student_t.two_sided_tail(max(0.0, abs(rel) - cap) / se, dof)))
    return _tested(bool(ok), min(ps), len(ps))


def pairs_dof_moments(trial):
    """test_camera_dof.py::test_defocus_blurs_by_the_aperture (blades 0 and 5): the total and
    the added variances of a defocused square against the aperture's exact ones, 16 pinhole
    seeds of 32 spp and 16 lens seeds of 256 spp, its cap 0.2 %."""
    sys.path.insert(0, str(ROOT / "tests" / "python"))
    import math

    import test_camera_dof as td
    depth, focus, radius, side = 2.0, 4.0, 0.05, 0.02
    seed0 = 1000 * trial + 1100000

    def run(blades):
        dof = {"radius": radius, "focus_distance": focus, "blades": blades, "rotation": 0.3}
        pin = td.renders(td.spot_scene(depth, side), "pt", 32, seed0, k_seeds=td.K_MOMENTS)
        blur = td.renders(td.spot_scene(depth, side, dof=dof), "pt", 256, seed0 + 500,
                          k_seeds=td.K_MOMENTS)
        m0 = np.array([td.moments(i) for i in pin])
        m1 = np.array([td.moments(i) for i in blur])
        r_pix = radius * abs(depth - focus) / depth / focus / (2 * td.HALF) * 64
        if blades >= 3:
            var = r_pix ** 2 * (1.0 + 2.0 * math.cos(math.pi / blades) ** 2) / 12.0
        else:
            var = r_pix ** 2 / 4.0
        area = (side / depth / (2 * td.HALF) * 64) ** 2
        checks = [(m1[:, 0], np.zeros(len(m1)), area), (m1[:, 1], m0[:, 1], var),
                  (m1[:, 2], m0[:, 2], var)]
        return checks, None, {"compare": _moments_rule, "cap": td.CAP}
    for blades in (0, 5):
        yield (f"dof moments blades {blades}: total, variance x, y vs the aperture's "
               "(test_camera_dof)", lambda blades=blades: run(blades))


def pairs_dof(trial):
    """test_camera_dof.py's block comparisons: in focus vs pinhole (pt, 16 x 16 spp a side,
    64 x 64), and lt, bdpt, cis through the lens against pt (16 x 32 spp, lt 64; pt 16 x 256
    spp, one reference shared by the three within a trial, as the test's fixture)."""
    sys.path.insert(0, str(ROOT / "tests" / "python"))
    import test_camera_dof as td
    seed0 = 1000 * trial + 1200000
    cache = {}

    def sharp():
        depth = 2.0
        pin = td.renders(td.spot_scene(depth, 0.04), "pt", 16, seed0, k_seeds=16)
        dof = td.renders(td.spot_scene(depth, 0.04, dof={"radius": 0.05,
                                                         "focus_distance": depth}),
                         "pt", 16, seed0 + 100, k_seeds=16)
        return dof, pin, {}
    yield "dof in focus vs pinhole (test_camera_dof)", sharp

    def lens(integrator):
        if "pt" not in cache:
            cache["pt"] = td.renders(td.dof_box(), "pt", 256, seed0 + 200, k_seeds=16)
        other = td.renders(td.dof_box(), integrator, 32 if integrator != "lt" else 64,
                           seed0 + 400, k_seeds=16)
        return other, cache["pt"], {}
    for integ in ("lt", "bdpt", "cis"):
        yield f"dof {integ} vs pt through the lens (test_camera_dof)", (
            lambda integ=integ: lens(integ))


def _region_rule(regions, _unused, alpha=1e-3):
    """test_bl_mix's region rule: per region and channel z = |mean - expected| / (pixels' se
    + 1e-4), the test passing |z| < 5 (two-sided normal p 5.7e-7 a channel); here each
    region's smallest p times its 3 channels against alpha, so p x n < 1.7e-6 is the test's
    own failure."""
    from statistics import NormalDist
    ps = []
    for px, expected in regions:
        se = px.std(axis=0, ddof=1) / np.sqrt(len(px)) + 1e-4
        z = np.abs(px.mean(axis=0) - expected) / se
        ps.append(min(2.0 * (1.0 - NormalDist().cdf(float(v))) for v in z))
    p = min(ps)
    return _tested(p * 3 >= alpha, p, 3)


def pairs_bl_region(trial):
    """tests/blender/test_bl_mix.py's F12 regions, each trial another lantern.seed: the
    diffuse/translucent mix (64 spp), the transparent/emission veil (512 spp), the factor
    texture's 0.2 and 0.8 halves (64 spp), each region's pixels against its exact value by the
    test's |z| < 5 from the pixels' spread (needs bpy)."""
    sys.path.insert(0, str(ROOT / "tests" / "blender"))
    import tempfile

    import bpy
    import test_bl_mix as tm
    from blender_helpers import add_plane, render_exr
    from test_bl_textures import add_uvs, make_image, ortho_camera, white_world
    tmp = Path(tempfile.mkdtemp())
    seed = 1000 * trial + 1300000
    d_col, t_col = np.array([0.9, 0.5, 0.1]), np.array([0.1, 0.5, 0.9])
    red = np.array([1.0, 0.0, 0.0])

    def analytic():
        sc = _bl_empty_scene()
        sc.lantern.seed = seed
        white_world(sc)

        def build(nodes, links):
            d = tm.shader(nodes, "ShaderNodeBsdfDiffuse", Color=(*d_col, 1))
            t = tm.shader(nodes, "ShaderNodeBsdfTranslucent", Color=(*t_col, 1))
            return tm.mix(nodes, links, 0.3, d, t).outputs[0]
        dt = add_plane(sc, size=1.0, location=(-0.5, 0, 0), material=tm.node_material("DT", build))
        ortho_camera(sc)
        sc.lantern.samples = 64
        px = render_exr(sc, tmp, "dt.exr")[..., :3].astype(np.float64)
        left = (px[10:22, 2:14].reshape(-1, 3), 0.7 * d_col + 0.3 * t_col)
        bpy.data.objects.remove(dt)

        def build_e(nodes, links):
            t = nodes.new("ShaderNodeBsdfTransparent")
            e = tm.shader(nodes, "ShaderNodeEmission", Color=(1, 1, 1, 1), Strength=2.0)
            return tm.mix(nodes, links, 0.3, t, e).outputs[0]
        add_plane(sc, size=1.0, location=(0.5, 0, 0.5), material=tm.node_material("Veil", build_e))

        def build_red(nodes, links):
            return tm.shader(nodes, "ShaderNodeEmission", Color=(1, 0, 0, 1),
                             Strength=1.0).outputs[0]
        add_plane(sc, size=1.0, location=(0.5, 0, 0), material=tm.node_material("Red", build_red))
        sc.lantern.samples = 512
        px = render_exr(sc, tmp, "veil.exr")[..., :3].astype(np.float64)
        right = (px[10:22, 18:30].reshape(-1, 3), 0.7 * red + 0.3 * 2.0)
        return left, right

    def factor():
        sc = _bl_empty_scene()
        sc.lantern.seed = seed
        img = make_image("Fac", np.array([[[51, 51, 51, 255], [204, 204, 204, 255]]], np.uint8),
                         colorspace="Non-Color")

        def build(nodes, links):
            black = tm.shader(nodes, "ShaderNodeBsdfDiffuse", Color=(0, 0, 0, 1))
            white = tm.shader(nodes, "ShaderNodeBsdfDiffuse", Color=(1, 1, 1, 1))
            tex = nodes.new("ShaderNodeTexImage")
            tex.image = img
            tex.interpolation = "Closest"
            m = tm.mix(nodes, links, 0.5, black, white)
            links.new(tex.outputs["Color"], m.inputs["Fac"])
            return m.outputs[0]
        add_uvs(add_plane(sc, size=2.0, material=tm.node_material("Blend", build)))
        white_world(sc)
        ortho_camera(sc)
        sc.lantern.samples = 64
        px = render_exr(sc, tmp)[..., :3].astype(np.float64)
        return [(px[4:28, cols].reshape(-1, 3), fac)
                for cols, fac in ((slice(3, 13), 0.2), (slice(19, 29), 0.8))]
    cache = {}

    def region(i):
        if not cache:
            cache["r"] = [*analytic(), *factor()]
        return [cache["r"][i]], None, {"compare": _region_rule}
    for i, what in enumerate(("diffuse/translucent mix", "transparent/emission veil",
                              "factor texture 0.2", "factor texture 0.8")):
        yield f"F12 region {what} vs exact, |z| from pixels (test_bl_mix)", (
            lambda i=i: region(i))


def pairs_bl_border(trial):
    """tests/blender/test_bl_layers_passes.py::test_border_with_and_without_crop: the cropped
    border's edge columns, 8 seeds of 64 spp (F12, one plain EXR a seed), against the
    filter's exact red fraction by _edge_agrees' rule (block 1, cap 1e-4; needs bpy)."""
    sys.path.insert(0, str(ROOT / "tests" / "blender"))
    import tempfile

    import test_bl_layers_passes as tl
    from blender_helpers import render_exr

    def run():
        tmp = Path(tempfile.mkdtemp())
        sc = _bl_empty_scene()
        tl._split_scene(sc)
        r = sc.render
        r.resolution_x, r.resolution_y = 40, 30
        r.use_border = True
        r.border_min_x, r.border_max_x, r.border_min_y, r.border_max_y = 0.3, 0.8, 0.1, 0.6
        r.use_crop_to_border = True
        sc.lantern.samples = tl.BORDER_SPP
        x0 = 12
        crops = []
        for k in range(tl.BORDER_SEEDS):
            sc.lantern.seed = 1000 * trial + 1400000 + k
            crops.append(render_exr(sc, tmp, f"crop{k}.exr"))
        frac = tl._red_fraction(np.arange(crops[0].shape[1]) + x0, tl.EDGE)
        edge = (frac > 0) & (frac < 1)
        cols = [c[..., [0, 2]].astype(np.float64).mean(axis=0, keepdims=True) for c in crops]
        exact = np.stack([frac, 1 - frac], axis=-1)[None]
        return cols, exact, {"block": 1, "mask": edge[None], "bias_cap": 1e-4}
    yield "F12 border edge columns vs the filter's exact fraction (test_bl_layers_passes)", run


def pairs_texels(trial):
    """test_textures.py's exact texels and its emitter comparison at the tests' settings: the
    checker (srgb, linear; pt, cis), the tilted normal map under the sun (cis: pt is exact
    per pixel), the alpha card (bdpt, cis: pt is in exact_images), and the textured emitter
    (pt, bdpt, cis) against the half emitter (pt, 32 x 96 spp, shared by the three within a
    trial, as the test)."""
    sys.path.insert(0, str(ROOT / "tests" / "python"))
    import math

    import test_textures as tt
    seed0 = 1000 * trial + 1500000

    def checker(colorspace, integrator):
        s = tt.plane_scene()
        tex = s.add_texture(tt.CHECKER, colorspace=colorspace, interpolation="closest")
        tt.finish_plane(s, dict(base_color_texture=tex))
        imgs = [lantern.render(s, spp=16, integrator=integrator, seed=seed0 + k, threads=2,
                               backend="cpu") for k in range(tt.K)]
        expected_all = tt.CHECKER[..., :3] / 255.0
        if colorspace == "srgb":
            expected_all = tt.srgb_to_linear(expected_all)
        expected = np.repeat(np.repeat(expected_all[::-1], 16, axis=0), 16, axis=1)
        return imgs, expected, {"block": 4, "mask": tt.interior_mask(16, 4, 1),
                                "bias_cap": tt.EXACT}
    for cs in ("srgb", "linear"):
        for integ in ("pt", "cis"):
            yield f"checker {cs} {integ} vs its texels (test_textures)", (
                lambda cs=cs, integ=integ: checker(cs, integ))

    def normal_map():
        b = (int(round((math.sin(math.radians(30)) + 1) * 127.5)), 128,
             int(round((math.cos(math.radians(30)) + 1) * 127.5)))
        n = np.array([2 * v / 255.0 - 1 for v in b])
        n /= np.linalg.norm(n)
        light = np.array([1.0, 0.0, 1.0]) / math.sqrt(2)
        expected = 0.5 / math.pi * 2.0 * max(0.0, float(n @ light)) * tt.bump_shadowing(n, light)
        imgs = [tt.sun_scene(b, integrator="cis", seed=seed0 + 100 + k, spp=4)
                for k in range(tt.K)]
        mask = np.zeros((8, 8), bool)
        mask[1:7, 1:7] = True
        return imgs, np.full((64, 64, 3), expected), {"block": 8, "mask": mask,
                                                      "bias_cap": tt.EXACT}
    yield "normal map tilted cis vs its exact shading (test_textures)", normal_map

    def card(integrator):
        s = tt.alpha_card_scene(0.3)
        imgs = [lantern.render(s, spp=tt.ALPHA_SPP, integrator=integrator, seed=seed0 + 200 + k,
                               threads=2, max_depth=2, backend="cpu") for k in range(tt.K)]
        expected, mask = tt.alpha_card_expected(0.3)
        return imgs, expected, {"block": 4, "mask": mask, "bias_cap": tt.EXACT}
    for integ in ("bdpt", "cis"):
        yield f"alpha card {integ} vs its exact image (test_textures)", (
            lambda integ=integ: card(integ))

    # the test's two emitters (test_emission_texture_lights_like_its_bright_part)
    cache = {}

    def emitter(integrator):
        if "ref" not in cache:
            cache["ref"] = [lantern.render(tt._lit_floor(tt._half_emitter), spp=96,
                                           integrator="pt", seed=seed0 + 300 + k, threads=2,
                                           max_depth=2)
                            for k in range(2 * tt.K)]
        got = [lantern.render(tt._lit_floor(tt._textured_emitter), spp=48,
                              integrator=integrator, seed=seed0 + 400 + k, threads=2,
                              max_depth=2)
               for k in range(2 * tt.K)]
        return got, cache["ref"], {"block": 8}
    for integ in ("pt", "bdpt", "cis"):
        yield f"textured emitter {integ} vs half emitter pt (test_textures)", (
            lambda integ=integ: emitter(integ))


def pairs_node_integrators(trial):
    """tests/cycles/test_node_scenes.py::test_node_scene_integrators_agree: nodes_procedural
    and nodes_vector exported once, bdpt, lvc and cis against pt, 16 seeds a side (pt 8 spp,
    the others 6), max_depth 6; pt shared by the three within a trial, as the test (bpy, no
    Cycles render)."""
    sys.path.insert(0, str(ROOT / "tests" / "cycles"))
    import node_stage as st
    import test_node_scenes as tn
    st.addon()
    seed0 = 1000 * trial + 1600000
    cache = {}

    def sets(name):
        if name not in cache:
            import bpy
            from lantern_blender.export import export_scene
            if ("scene", name) not in _BL_SCENES:
                tn.node_scenes.SCENES[name]()
                _BL_SCENES["scene", name] = export_scene(bpy.context.evaluated_depsgraph_get())[0]
            scene = _BL_SCENES["scene", name]
            cache[name] = {}
            for i, integ in enumerate(("pt", "bdpt", "lvc", "cis")):
                spp = tn.CROSS_SPP_PT if integ == "pt" else tn.CROSS_SPP
                cache[name][integ] = [np.asarray(lantern.render(
                    scene, spp=spp, integrator=integ, max_depth=6, seed=seed0 + 100 * i + k),
                    np.float64) for k in range(tn.CROSS_K)]
        return cache[name]
    for name in ("nodes_procedural", "nodes_vector"):
        for integ in ("bdpt", "lvc", "cis"):
            yield f"{name} {integ} vs pt (test_node_scenes)", (
                lambda name=name, integ=integ: (sets(name)[integ], sets(name)["pt"], {}))


def pairs_bounces(trial):
    """render/test_bounces.py: Cycles' max_bounces 0 and 1 against Lantern's max_depth 2 and 3
    on the Cornell box at 32 x 32, 16 seeds a side of 64 (0 bounces) or 128 spp (1), both
    re-rendered every trial with their own seeds (needs bpy and Cycles)."""
    import bpy
    import lantern_bpy
    import render_compare as rc
    lantern_bpy.load_addon()
    seed0 = 1000 * trial + 1700000

    def run(bounces):
        rc.build_scene("cornell_box")
        sc = bpy.context.scene
        sc.render.resolution_x = sc.render.resolution_y = 32
        sc.render.threads_mode, sc.render.threads = "FIXED", 2
        rc.BOUNCES = bounces
        spp = {0: 64, 1: 128}[bounces]
        cyc = [rc.render_cycles(seed=seed0 + k, spp=spp)[0] for k in range(16)]
        lan = [rc.render_lantern(seed=seed0 + 500 + k, spp=spp, threads=2)[0] for k in range(16)]
        return lan, cyc, {"block": rc.BLOCK}
    for bounces in (0, 1):
        yield (f"Cycles max_bounces={bounces} vs Lantern max_depth={bounces + 2} "
               "(render/test_bounces)", lambda bounces=bounces: run(bounces))


FAMILIES = {"dof_moments": pairs_dof_moments, "dof": pairs_dof,
            "bl_region": pairs_bl_region, "bl_border": pairs_bl_border,
            "texels": pairs_texels, "node_integrators": pairs_node_integrators,
            "bounces": pairs_bounces}
