"""False-alarm rates of the comparison families of tests/ (tests/README.md): each family's
comparison (lantern.metrics.compare_renders, as its tests call it) on 20 independent seed sets
of a fair pair, counting failures at the tests' alpha (1e-3) and, to see the calibration with 20
trials, at alpha 0.05 and 0.2. Expected counts are 20 alpha.

    nice python3 tools/false_alarm.py [--trials 20] [--families cross,analytic,backend,cycles]
        [--out tests/false_alarm.json]

Families (fair pairs; the settings are the tests' or cheaper, which changes the noise, not the
null distribution):
- cross: lt against pt on cornell_point (test_light_tracing), bdpt against pt on the Cornell box
  (test_bidirectional), 16 seeds each;
- analytic: pt furnace against its exact value (test_render, test_bidirectional), and the
  direct term of the integrating sphere against the exact tessellated value;
- backend: the GPU tests' rule (test_cuda_backend, tools/gpu_compare.py) on CPU against CPU,
  two independent seed sets of the same integrator (what a correct GPU gives);
- paired: Lantern's own BVH against Embree with the same seeds, compared seed by seed
  (test_cpu_accel: bvh_k - embree_k + mean(embree) against mean(embree)) on the alpha-tested
  features box, pt, 16 seeds of 8 spp;
- scale: the glossy box at 1 m against 1 mm with the same seeds, paired
  (test_bidirectional.py::test_scale_invariance: cis, 16 seeds of 8 spp);
- instance: a box moved in a running session against a fresh render of the moved scene, the
  same seeds, paired (test_instance_move: 16 seeds of 8 spp, the built-in BVH);
- adaptive: adaptive renders against full ones on the half-emitter box, pt
  (test_adaptive_sampling's threshold, seeds and block);
- film: the shadow catcher's alpha against the wall's exact shadow (test_film, its settings);
- rotation: the HDRI turned by its mapping against the rolled map, paired seeds (test_world);
- hdri: test_world's HDRI scene with its world sun, bdpt against pt (16 x 64 spp a side) and
  lvc against bdpt on the same seeds, paired (test_integrators_agree_under_hdri);
- layers: tests/cycles/test_layers_passes' Combined of both view layers and the uncropped
  border against Cycles, 8 seeds of 16 spp an engine (needs bpy, like cycles);
- passes: the same test's data passes (Normal, Denoising Albedo, Denoising Normal, Diffuse
  Color) against Cycles, the same seeds and samples (needs bpy);
- bl_catcher: tests/blender/test_bl_world's F12 shadow catcher scene, exported, its alpha
  against the wall's exact shadow (16 seeds of 8 spp; needs bpy);
- bl_hdri: the same file's HDRI-lit Lambert plane against its exact irradiance (16 seeds of
  24 spp; needs bpy);
- coat_normal: tests/cycles/test_coat_normal's interior blocks against Cycles, 12 seeds of
  128 spp an engine, each trial its own seeds on both sides (needs bpy);
- pano: lt against pt through the panoramic camera (test_camera_pano, its samples);
- lighttree: bdpt against pt on the many-light stage with the tree (test_light_tree);
- cycles: Lantern against the stored Cycles reference of light_sun (needs bpy; the reference
  is one fixed set, so the 20 trials share it);
- fixture: the fixture's paired comparisons of test_bidirectional (lvc against bdpt, cis with
  the BSDF-product target against lvc: the same seeds on both sides), 16 seeds of 16 spp;
- tungsten: test_mitsuba's Cornell box and veach-mis against Tungsten's stored references,
  rendered at their footprints (the 20 trials share each reference, as cycles does);
- exact_images: the alpha card (test_textures, pt), the ball under a world hidden from the
  camera (test_world) and the glass ball's reflection alone (test_world_visibility) against
  their exact images, at their tests' settings;
- gpu_paired: test_cuda_backend's paired rule on CPU data: the built-in BVH against Embree with
  the same seeds (another traversal, the same wavefront), Cornell pt at that test's settings
  (32x32, 16 seeds of 64 spp, max_depth 8; one iteration of 64 where the test runs 4 of 16).
- lt_furnace: test_world's lt furnace, the image's totals over the ball's value times pt's
  coverage, one value a seed, against 1 (its seeds and samples; the coverage render is shared);
- sun_disc: render/test_sky_cycles' disc Lantern's camera sees, summed over the pixels' solid
  angles, against its light's strength (both skies, 8 seeds of 16 spp, cap 0.3 %; needs bpy).
"""

import argparse
import json
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python"))
sys.path.insert(0, str(ROOT / "tools"))

import lantern  # noqa: E402
from lantern import metrics, scenes  # noqa: E402

ALPHAS = (1e-3, 0.05, 0.2)


def sets(scene, integrator, spp, seed0, k=16, **settings):
    return [lantern.render(scene, spp=spp, seed=seed0 + i, integrator=integrator,
                           backend="cpu", max_depth=8, **settings) for i in range(k)]


def cornell_point():
    s = scenes.cornell_box(32, 32)
    s.lights = []
    s.add_light("point", position=[0.2, -0.1, 1.5], power=[30.0, 25.0, 20.0], radius=0.0)
    return s


def pairs_cross(trial):
    yield "lt vs pt, cornell_point", lambda: (
        sets(cornell_point(), "lt", 16, 100000 + 1000 * trial),
        sets(cornell_point(), "pt", 32, 500000 + 1000 * trial), {})
    yield "bdpt vs pt, cornell", lambda: (
        sets(scenes.cornell_box(32, 32), "bdpt", 8, 200000 + 1000 * trial),
        sets(scenes.cornell_box(32, 32), "pt", 32, 600000 + 1000 * trial), {})


def pairs_analytic(trial):
    furnace = scenes.furnace_sphere(albedo=0.5, emission=1.0, subdivisions=3, width=16,
                                    height=16)
    yield "furnace pt, exact", lambda: (
        [lantern.render(furnace, spp=32, seed=300000 + 1000 * trial + i, max_depth=16,
                        backend="cpu") for i in range(8)],
        scenes.furnace_expected(1.0, 0.5, 16), {"block": 4, "bias_cap": 1e-4,
                                                 "rel_floor": 1e-5})
    sys.path.insert(0, str(ROOT / "tests" / "python"))
    import test_render  # the exact direct term of the tessellated sphere
    power = 4 * np.pi ** 2
    sphere = scenes.integrating_sphere(albedo=0.5, power=power, subdivisions=4, width=16,
                                       height=16)
    expected = test_render._direct_light_image(sphere, 0.5, power)
    yield "integrating sphere direct, exact", lambda: (
        [lantern.render(sphere, spp=8, max_depth=2, seed=400000 + 1000 * trial + i,
                        backend="cpu") for i in range(16)], expected, {"bias_cap": 1e-4})


def pairs_backend(trial):
    for name, integ in (("pt", "pt"), ("cis", "cis")):
        yield f"backend rule, {name} cornell (cpu vs cpu)", (lambda integ=integ: (
            sets(scenes.cornell_box(32, 32), integ, 16, 700000 + 1000 * trial),
            sets(scenes.cornell_box(32, 32), integ, 16, 800000 + 1000 * trial), {}))


def pairs_cycles(trial):
    import render_compare as rc
    ref = dict(np.load(rc.REF_DIR + "/light_sun.npz"))
    cycles = metrics.SeedBlocks(ref["seed_block_means"])

    def run():
        rc.build_scene("light_sun")
        imgs = [rc.render_lantern(seed=900000 + 1000 * trial + i, spp=32)[0] for i in range(16)]
        return imgs, cycles, {"block": rc.BLOCK}
    yield "lantern vs stored Cycles, light_sun", run


def pairs_paired(trial):
    import os

    def run():
        scene = scenes.features_box(32, 32)
        out = {}
        for accel in ("embree", "bvh"):
            os.environ["LANTERN_ACCEL"] = accel
            out[accel] = [np.asarray(lantern.render(scene, spp=8, seed=950000 + 1000 * trial + i,
                                                    max_depth=6, backend="cpu"), np.float64)
                          for i in range(16)]
        os.environ.pop("LANTERN_ACCEL")
        return (*metrics.paired_sets(out["bvh"], out["embree"]), {})
    yield "bvh vs embree, paired seeds, features pt", run


def pairs_scale(trial):
    sys.path.insert(0, str(ROOT / "tests" / "python"))
    import test_bidirectional as tb  # its _scaled and renders, the test's settings

    def run():
        ref = tb.renders(scenes.glossy_box(32, 32), "cis", 8, 960000 + 1000 * trial)
        scaled = tb.renders(tb._scaled(scenes.glossy_box(32, 32), 1e-3), "cis", 8,
                            960000 + 1000 * trial)
        return (*metrics.paired_sets(scaled, ref), {})
    yield "scale invariance 1e-3, paired seeds, glossy cis", run


def pairs_fixture(trial):
    sys.path.insert(0, str(ROOT / "tests" / "python"))
    import test_bidirectional as tb

    def run(integ, ref, **settings):
        scene = scenes.fixture_box(32, 32)
        seed0 = 970000 + 1000 * trial
        a = tb.renders(scene, integ, 16, seed0, **settings)
        b = tb.renders(scene, ref, 16, seed0)
        return (*metrics.paired_sets(a, b), {})
    yield "fixture lvc vs bdpt, paired seeds", lambda: run("lvc", "bdpt")
    yield "fixture cis(bsdf) vs lvc, paired seeds", lambda: run("cis", "lvc", cis_target="bsdf")


def pairs_gpu_paired(trial):
    import os

    def run():
        scene = scenes.cornell_box(32, 32)
        out = {}
        for accel in ("embree", "bvh"):
            os.environ["LANTERN_ACCEL"] = accel
            out[accel] = [lantern.Session(scene, integrator="pt", seed=980000 + 1000 * trial + i,
                                          backend="cpu", max_depth=8, spp_per_iteration=64)
                          for i in range(16)]
            for s in out[accel]:
                s.step()
            out[accel] = [s.image() for s in out[accel]]
        os.environ.pop("LANTERN_ACCEL")
        return (*metrics.paired_sets(out["bvh"], out["embree"]), {})
    yield "gpu rule (paired) on cpu: bvh vs embree, cornell pt", run


def pairs_instance(trial):
    sys.path.insert(0, str(ROOT / "tests" / "python"))
    import test_instance_move as tim  # its _matrix, _moved and settings

    def run():
        from lantern import session
        scene = scenes.cornell_box(width=tim.SIZE, height=tim.SIZE)
        m = tim._matrix()
        moved = tim._moved(scene, m)
        a, b = [], []
        for k in range(tim.K):
            seed = 970000 + 1000 * trial + k
            s = session.Session(scene, backend="cpu", seed=seed, instancing=True)
            s.step()
            s.move_instance(tim.BOX, m)
            f = session.Session(moved, backend="cpu", seed=seed)
            for _ in range(tim.SPP):
                s.step()
                f.step()
            a.append(s.image().astype(np.float64))
            b.append(f.image().astype(np.float64))
        return (*metrics.paired_sets(a, b), {})
    yield "moved instance vs fresh render, paired seeds, cornell pt (bvh)", run


def pairs_adaptive(trial):
    sys.path.insert(0, str(ROOT / "tests" / "python"))
    import test_adaptive_sampling as tas  # its scene, run() and settings

    def run():
        ad = [tas.run(adaptive_threshold=tas.THRESHOLD["pt"], adaptive_min_samples=8,
                      seed=980000 + 1000 * trial + k, integrator="pt",
                      spp_per_iteration=4).image().astype(np.float64)
              for k in range(tas.AGREE_SEEDS)]
        spp = tas.FULL_SPP["pt"]
        full = [tas.run(spp=spp, seed=990000 + 1000 * trial + k, integrator="pt",
                        spp_per_iteration=spp).image().astype(np.float64)
                for k in range(tas.AGREE_SEEDS)]
        return ad, full, {"block": tas.BLOCK}
    yield "adaptive vs full, half-emitter box pt", run


def pairs_film(trial):
    sys.path.insert(0, str(ROOT / "tests" / "python"))
    import test_film as tf  # the catcher scene and its exact shadow

    def run():
        from lantern.film import render_alpha
        scene = tf.catcher_scene(wall=True)
        a = [render_alpha(scene, spp=32, seed=1000 * trial + 500000 + k, max_depth=4)
             [:, tf.CATCHER_COLUMNS] for k in range(tf.K)]
        y0 = 1.0 - (np.arange(32) + 0.5) / 16.0
        d = np.abs(-1.0 + (np.array(tf.CATCHER_COLUMNS) + 0.5) / 16.0 - tf.WALL_X)
        expected = np.array([[[tf.wall_shadow(dc, yr)] for dc in d] for yr in y0])
        return a, expected, {"block": 4, "bias_cap": tf.CATCHER_CAP}
    yield "shadow catcher vs its exact wall shadow (test_film)", run


def pairs_exact_images(trial):
    """The exact images of the audit round (their tests' settings): the alpha card
    (test_textures, pt), the ball under a world hidden from the camera (test_world), the glass
    ball's reflection alone (test_world_visibility)."""
    sys.path.insert(0, str(ROOT / "tests" / "python"))
    import test_textures as tt
    import test_world as tw
    import test_world_visibility as tv
    seed0 = 1000 * trial + 700000

    def card():
        imgs = [lantern.render(tt.alpha_card_scene(0.3), spp=tt.ALPHA_SPP, integrator="pt",
                               seed=seed0 + k, max_depth=2, backend="cpu") for k in range(tt.K)]
        expected, mask = tt.alpha_card_expected(0.3)
        return imgs, expected, {"block": 4, "mask": mask, "bias_cap": tt.EXACT}
    yield "alpha card pt vs its exact image (test_textures)", card

    def hidden():
        scene = tw.furnace_scene(16)
        scene.world = {"color": [0.0] * 3, "map": np.full((4, 8, 3), 0.5, np.float32),
                       "visible_camera": False}
        inside = np.zeros((8, 8), bool)
        inside[2:6, 2:6] = True
        inside[[2, 2, 5, 5], [2, 5, 2, 5]] = False
        return (tw.renders(scene, "pt", 16, seed0, k_seeds=16), [0.5] * 3,
                {"block": 2, "mask": inside, "bias_cap": 1e-4, "se_floor": 1e-6})
    yield "ball under a world hidden from the camera vs 0.5 (test_world)", hidden

    def glass():  # through its view window of the ball's middle, one block
        return tv.reflection_renders(seed0), tv.reflection_expected(), {"block": 16}
    yield "glass reflection only vs its exact image (test_world_visibility)", glass


def pairs_rotation(trial):
    sys.path.insert(0, str(ROOT / "tests" / "python"))
    import test_world as tw  # the rotation test's scene and settings

    def run():
        import math
        scene = tw.hdri_scene(16)
        scene.world["map"] = tw.sky_map(sun_value=tw.ROT_SUN)
        scene.world["to_map"] = tw.rotation_z(2.0 * math.pi * 16 / 64).tolist()
        seed0 = 1000 * trial + 600000
        turned = tw.renders(scene, "pt", tw.ROT_SPP, seed0, k_seeds=16)
        scene.world["map"] = np.ascontiguousarray(np.roll(tw.sky_map(sun_value=tw.ROT_SUN), 16,
                                                          axis=1))
        scene.world["to_map"] = np.eye(3).tolist()
        rolled = tw.renders(scene, "pt", tw.ROT_SPP, seed0, k_seeds=16)
        return (*metrics.paired_sets(turned, rolled), {"block": 4})
    yield "map rotation vs rolled map, paired seeds (test_world)", run


def pairs_hdri(trial):
    sys.path.insert(0, str(ROOT / "tests" / "python"))
    import test_world as tw  # the HDRI test's scene (its 4x4 sun) and samples

    def renders(integrator, spp, seed0):
        scene = tw.hdri_scene()
        scene.world["sun"] = tw.sky_sun()  # as the test: the world's sun disc in view
        return tw.renders(scene, integrator, spp, seed0, k_seeds=16)

    seed0 = 1000 * trial + 900000
    cache = {}

    def bdpt():
        if "bdpt" not in cache:
            cache["bdpt"] = renders("bdpt", tw.HDRI_SPP, seed0 + 500)
        return cache["bdpt"]

    def unpaired():
        return bdpt(), renders("pt", tw.HDRI_PT_SPP, seed0), {"block": 8}

    def paired():
        lvc = renders("lvc", tw.HDRI_SPP, seed0 + 500)  # bdpt's seeds
        return (*metrics.paired_sets(lvc, bdpt()), {"block": 8})
    yield "hdri bdpt vs pt (test_world)", unpaired
    yield "hdri lvc vs bdpt, paired seeds (test_world)", paired


def pairs_layers(trial):
    """test_layers_passes' Combined (both view layers) and uncropped border against Cycles:
    8 seeds of 16 spp an engine, each trial its own seeds on both sides (needs bpy)."""
    sys.path.insert(0, str(ROOT / "blend_scenes"))
    sys.path.insert(0, str(ROOT / "tests" / "cycles"))
    import tempfile

    import exr_passes
    import lantern_bpy
    import layers_passes
    import test_layers_passes as tl
    lantern_bpy.load_addon()
    cache = {}

    def renders():
        if not cache:
            tmp = Path(tempfile.mkdtemp())
            for engine, setup, seed0, case in (
                    ("cycles", tl._cycles, 10000 + 100 * trial, "full"),
                    ("lantern", tl._lantern, 20000 + 100 * trial, "full"),
                    ("lantern", tl._lantern, 20000 + 100 * trial, "nocrop")):
                for k in range(tl.SEEDS):
                    scene = layers_passes.layers_passes()
                    setup(scene, seed0 + k)
                    if case != "full":
                        layers_passes.set_border(scene, crop=False)
                    cache.setdefault((engine, case), []).append(
                        exr_passes.render_passes(scene, tmp / f"{engine}_{case}{k}.exr"))
        return cache

    def combined(layer):
        r = renders()
        return (tl._combined(r["lantern", "full"], layer), tl._combined(r["cycles", "full"], layer),
                {"block": 8})

    def border(layer):
        r = renders()
        cut = (slice(64 - tl.BY1, 64 - tl.BY0), slice(tl.BX0, tl.BX1))
        return ([x[cut] for x in tl._combined(r["lantern", "nocrop"], layer)],
                [x[cut] for x in tl._combined(r["cycles", "full"], layer)], {"block": 8})
    for layer in tl.LAYERS:
        yield f"layers_passes {layer} Combined vs Cycles", lambda layer=layer: combined(layer)
        yield f"layers_passes {layer} border vs Cycles", lambda layer=layer: border(layer)


def pairs_passes(trial):
    """test_layers_passes' data passes (Normal, Denoising Albedo, Denoising Normal, Diffuse
    Color; both view layers) against Cycles, 8 seeds of 16 spp an engine, each trial its own
    seeds on both sides (needs bpy)."""
    sys.path.insert(0, str(ROOT / "blend_scenes"))
    sys.path.insert(0, str(ROOT / "tests" / "cycles"))
    import tempfile

    import exr_passes
    import lantern_bpy
    import layers_passes
    import test_layers_passes as tl
    lantern_bpy.load_addon()
    cache = {}

    def renders():
        if not cache:
            tmp = Path(tempfile.mkdtemp())
            for engine, setup, seed0 in (("cycles", tl._cycles, 30000 + 100 * trial),
                                         ("lantern", tl._lantern, 40000 + 100 * trial)):
                for k in range(tl.SEEDS):
                    scene = layers_passes.layers_passes()
                    setup(scene, seed0 + k)
                    cache.setdefault(engine, []).append(
                        exr_passes.render_passes(scene, tmp / f"{engine}{k}.exr"))
        return cache

    def one(layer, name):
        r = renders()
        return (tl._pass_seeds(r["lantern"], layer, name),
                tl._pass_seeds(r["cycles"], layer, name), {"block": 8})
    for layer in tl.LAYERS:
        for name in tl.DATA_PASSES:
            yield (f"layers_passes {layer} {name} vs Cycles",
                   lambda layer=layer, name=name: one(layer, name))


def _bl_empty_scene():
    """tests/blender's `empty` fixture: factory settings, no objects, Lantern, 32 x 24."""
    sys.path.insert(0, str(ROOT / "tests" / "blender"))
    import lantern_bpy
    lantern_bpy.load_addon()
    from blender_helpers import empty_scene
    return empty_scene()


_BL_SCENES = {}


def pairs_bl_catcher(trial):
    """test_bl_world.py::test_shadow_catcher_through_f12: the exported catcher-and-wall scene's
    alpha (16 seeds of 8 spp) against the wall's exact shadow (needs bpy)."""
    sys.path.insert(0, str(ROOT / "tests" / "blender"))
    import test_bl_world as tw
    from lantern.film import render_alpha

    def run():
        if "catcher" not in _BL_SCENES:
            tf = tw._film_test_module()
            bscene = _bl_empty_scene()
            tw.catcher_wall_scene(bscene, tf)
            _BL_SCENES["catcher"] = (tw.export(None)[0], bscene.lantern.max_depth,
                                     tw.catcher_expected(tf), tf.CATCHER_CAP)
        scene, depth, expected, cap = _BL_SCENES["catcher"]
        a = [render_alpha(scene, spp=tw.CATCHER_SPP, seed=1000 * trial + 900000 + k,
                          max_depth=depth)[:, tw.CATCHER_COLS] for k in range(tw.CATCHER_SEEDS)]
        return a, expected, {"block": 4, "bias_cap": cap}
    yield "F12 shadow catcher vs its exact wall shadow (test_bl_world)", run


def pairs_bl_hdri(trial):
    """test_bl_world.py::test_hdri_renders_finite_and_lit: the exported HDRI-lit Lambert plane
    (16 seeds of 128 spp) against its exact irradiance (needs bpy)."""
    sys.path.insert(0, str(ROOT / "tests" / "blender"))
    import test_bl_world as tw

    def run():
        if "hdri" not in _BL_SCENES:
            _BL_SCENES["hdri"] = tw.hdri_plane(_bl_empty_scene())
        scene, expected = _BL_SCENES["hdri"]
        imgs = [lantern.render(scene, spp=tw.HDRI_SPP, seed=1000 * trial + 950000 + k)
                for k in range(16)]
        return [x[tw.HDRI_PLANE][..., :3] for x in imgs], expected, {"block": 4,
                                                                     "bias_cap": 1e-4}
    yield "HDRI world on a Lambert plane vs its exact irradiance (test_bl_world)", run


_COAT = {}


def coat_normal_renders(trial):
    """tests/cycles/test_coat_normal.py's renders for one trial: K Cycles and K Lantern seeds of
    SPP (each trial its own seeds on both sides), the interior blocks and the limb mask."""
    sys.path.insert(0, str(ROOT / "tests" / "cycles"))
    import lantern_bpy
    import render_compare as rc
    import test_coat_normal as tc
    lantern_bpy.load_addon()
    if trial not in _COAT:
        _COAT.clear()
        tc._scene()
        interior, limb = tc._interior_blocks()
        cyc = [rc.render_cycles(seed=50000 + 100 * trial + k, spp=tc.SPP)[0]
               for k in range(tc.K)]
        lan = [rc.render_lantern(seed=60000 + 100 * trial + k, spp=tc.SPP, threads=2)[0]
               for k in range(tc.K)]
        _COAT[trial] = (lan, cyc, interior, limb)
    return _COAT[trial]


def pairs_coat_normal(trial):
    """test_coat_normal.py's interior comparison: Principled Coat Normal against Cycles, 12
    seeds of 128 spp a renderer, 4x4 blocks away from the limb (needs bpy). Its limb ratio is
    counted by tools/false_alarm_coat_limb.py from the same renders."""
    def run():
        lan, cyc, interior, _ = coat_normal_renders(trial)
        return lan, cyc, {"block": 4, "mask": interior, "rel_floor": 1e-3}
    yield "coat normal interior vs Cycles (test_coat_normal)", run


def pairs_sun_disc(trial):
    """test_sky_cycles.py::test_sun_disc_irradiance_matches_cycles, Lantern's side: the disc
    its camera sees (8 seeds of 16 spp, summed over the pixels' solid angles, less the sky)
    against the light's strength, cap 0.3 %, for both skies (needs bpy)."""
    sys.path.insert(0, str(ROOT / "tests" / "render"))
    import test_sky_cycles as ts

    def run(i):
        if ("disc", i) not in _BL_SCENES:
            import lantern_bpy
            lantern_bpy.load_addon()
            node, omega, _, _ = ts.disc_view(ts.DISC_PROPS[i])
            light, scene, sky = ts.lantern_disc(node, omega)
            _BL_SCENES["disc", i] = (scene, omega, sky, np.asarray(light["strength"]))
        scene, omega, sky, mine = _BL_SCENES["disc", i]
        discs = ts.disc_sums(scene, omega, sky, seed0=1000 * trial + 960000)
        return discs, mine, {"block": 1, "bias_cap": ts.DISC_CAP}
    for i, props in enumerate(ts.DISC_PROPS):
        yield (f"sun disc {props.get('sky_type', 'MULTIPLE_SCATTERING')} vs its light "
               f"(test_sky_cycles)", lambda i=i: run(i))


FAMILIES_BL = {"passes": pairs_passes, "bl_catcher": pairs_bl_catcher,
               "bl_hdri": pairs_bl_hdri, "coat_normal": pairs_coat_normal,
               "sun_disc": pairs_sun_disc}


def pairs_pano(trial):
    sys.path.insert(0, str(ROOT / "tests" / "python"))
    import test_camera_pano as tp  # the panorama box and the test's samples

    def run():
        scene = tp.pano_box()
        scene.world["visible_camera"] = False
        seed0 = 1000 * trial + 700000
        return (tp.renders(scene, "lt", tp.SPP["lt"], seed0),
                tp.renders(scene, "pt", tp.PT_SPP, seed0 + 500), {})
    yield "lt vs pt through the panorama (test_camera_pano)", run


def pairs_lighttree(trial):
    sys.path.insert(0, str(ROOT / "tests" / "python"))
    import test_light_tree as tlt  # its scenes and samples (test_bidirectional's renders)

    def run():
        scene = tlt.SCENES["many"]()
        seed0 = 1000 * trial + 800000
        return (tlt.renders(scene, "bdpt", tlt.SPP, seed0),
                tlt.renders(scene, "pt", tlt.PT_REF, seed0 + 500), {})
    yield "bdpt vs pt, many lights with the tree (test_light_tree)", run


def pairs_lt_furnace(trial):
    sys.path.insert(0, str(ROOT / "tests" / "python"))
    import test_world as tw  # its scene, coverage, seeds and samples

    def run():
        return tw.lt_furnace_ratios(seed0=1000 * trial + 310000), 1.0, {"block": 1,
                                                                        "bias_cap": 1e-4}
    yield "lt furnace, image totals vs the ball's (test_world)", run


def pairs_tungsten(trial):
    sys.path.insert(0, str(ROOT / "tests" / "python"))
    import test_mitsuba as tm  # its renders at the references' footprints, masks and caps

    def cornell():
        r = tm.cornell_comparison(seed0=1000 * trial + 700000)
        return r["imgs"], r["ref"], {"mask": r["blocks"], "bias_cap": tm.CORNELL_CAP}

    def veach():
        r = tm.veach_comparison(indirect_seeds=0, seed0=1000 * trial + 710000)
        return r["imgs"], r["ref"], {"mask": r["blocks"], "bias_cap": tm.VEACH_CAP}
    yield "cornell-box vs Tungsten (test_mitsuba)", cornell
    yield "veach-mis max_depth 2 vs Tungsten (test_mitsuba)", veach


FAMILIES = {"cross": pairs_cross, "analytic": pairs_analytic, "backend": pairs_backend,
            "paired": pairs_paired, "scale": pairs_scale, "cycles": pairs_cycles,
            "fixture": pairs_fixture, "gpu_paired": pairs_gpu_paired,
            "instance": pairs_instance, "adaptive": pairs_adaptive, "film": pairs_film,
            "rotation": pairs_rotation, "pano": pairs_pano, "lighttree": pairs_lighttree,
            "hdri": pairs_hdri, "layers": pairs_layers, "tungsten": pairs_tungsten,
            **FAMILIES_BL, "exact_images": pairs_exact_images,
            "lt_furnace": pairs_lt_furnace}



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


FAMILIES.update({"dof_moments": pairs_dof_moments, "dof": pairs_dof,
                 "bl_region": pairs_bl_region, "bl_border": pairs_bl_border,
                 "texels": pairs_texels, "node_integrators": pairs_node_integrators,
                 "bounces": pairs_bounces})


def load_family_modules():
    """Families kept in modules of their own: every tools/fa_*.py with a FAMILIES dict (name ->
    pairs function, as above) joins FAMILIES; a name given twice is an error."""
    import importlib
    for path in sorted((ROOT / "tools").glob("fa_*.py")):
        mod = importlib.import_module(path.stem)
        for name, fn in getattr(mod, "FAMILIES", {}).items():
            if name in FAMILIES:
                raise SystemExit(f"false_alarm: family '{name}' of {path.name} is defined twice")
            FAMILIES[name] = fn


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--trials", type=int, default=20)
    p.add_argument("--families", default="cross,analytic,backend")
    p.add_argument("--out", default=None)
    args = p.parse_args(argv)
    load_family_modules()
    rows = {}
    t0 = time.perf_counter()
    for fam in [f.strip() for f in args.families.split(",") if f.strip()]:
        for trial in range(args.trials):
            for label, make in FAMILIES[fam](trial):
                a, b, kw = make()
                compare = kw.pop("compare", metrics.compare_renders)
                res = compare(a, b, **kw)
                row = rows.setdefault(label, {"family": fam, "trials": 0, "worst_p_x_n": [],
                                              **{f"fails@{al:g}": 0 for al in ALPHAS}})
                row["trials"] += 1
                for al in ALPHAS:
                    r = compare(a, b, alpha=al, **kw)
                    row[f"fails@{al:g}"] += int(not r.passed)
                row["worst_p_x_n"].append(round(float(res.blocks.p.min() * res.blocks.n), 4))
                print(f"{fam} trial {trial}: {label}: {'ok' if res.passed else 'FALSE ALARM'}"
                      f" ({time.perf_counter() - t0:.0f} s)", flush=True)
                save(args.out, rows, t0)  # after every trial: a run cut short keeps its counts
    print(json.dumps({k: {kk: vv for kk, vv in v.items() if kk != "worst_p_x_n"}
                      for k, v in rows.items()}, indent=1))
    return 0


def save(path, rows, t0):
    if not path:
        return
    out = {"machine": f"{platform.node()} {platform.processor() or platform.machine()}, "
                      f"{platform.python_version()}", "command": " ".join(sys.argv),
           "seconds": round(time.perf_counter() - t0, 1), "rows": rows}
    Path(path).write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    sys.exit(main())
