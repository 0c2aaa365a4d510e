"""False-alarm families of the Python-API comparisons (false_alarm.py's docstring lists each:
cross, analytic, backend, paired, scale, fixture, gpu_paired, instance, adaptive, film,
exact_images, rotation, hdri, pano, lighttree, lt_furnace, tungsten, and cycles, which needs
bpy). Each family yields (label, make) per trial; make() returns (a, b, compare keywords)."""

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[3]   # the checkout: the families render its tests' scenes
sys.path.insert(0, str(ROOT / "tools"))      # render_compare, lantern_bpy

import lantern  # noqa: E402
from lantern import metrics, scenes  # noqa: E402


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
                        backend="cpu", integrator="pt") for i in range(8)],
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
                        backend="cpu", integrator="pt")
                        for i in range(16)], expected, {"bias_cap": 1e-4})


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
                                                    max_depth=6, backend="cpu",
                                                    integrator="pt"), np.float64)
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
            s = session.Session(scene, backend="cpu", seed=seed, instancing=True, integrator="pt")
            s.step()
            s.move_instance(tim.BOX, m)
            f = session.Session(moved, backend="cpu", seed=seed, integrator="pt")
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
            "hdri": pairs_hdri, "tungsten": pairs_tungsten, "exact_images": pairs_exact_images,
            "lt_furnace": pairs_lt_furnace}
