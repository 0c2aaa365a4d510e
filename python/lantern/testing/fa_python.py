"""False-alarm families of the Python-API tests (tests/python) that false_alarm.py's own
families leave out. Loaded by false_alarm.py (load_family_modules); run as

    PYTHONPATH=python nice python -m lantern.testing.false_alarm --trials 20 --families lt_scenes

Each family calls its test's own scenes, render helpers and rule, each trial with its own seeds;
where a family says "cheaper" the samples per seed are cut (the seeds, the references shared
within a trial and the rule stay the test's):
- lt_scenes: test_light_tracing.test_lt_matches_pt on cornell_area, cornell_mesh_light,
  cornell_spot, cornell_sphere, cornell_sun (cornell_point is false_alarm.py's cross);
  cheaper: both sides' spp over LT_CUT;
- accel: test_cpu_accel.test_same_seeds_agree_statistically, paired seeds, on flags (pt, cis)
  and features (cis; features pt is false_alarm.py's paired), the test's settings;
- lighttree2: test_light_tree's room (bdpt, lvc, cis vs pt), the tree against the global CDF
  (paired seeds) and the resampled direct light (M = 4, many and room); cheaper: spp over
  TREE_CUT;
- pano2: test_camera_pano's panorama against the world map (straight and turned, exact, the
  test's settings) and bdpt, cis against pt through the panorama (the test's settings);
- adaptive_lvc: test_adaptive_sampling.test_adaptive_images_agree_with_full_ones for lvc;
- film2: test_film's plane under the hidden world (exact 0.4) and alpha coverage (alpha 1 and
  0.3: covered columns and the folded edge, exact), the tests' settings;
- conductor: test_conductor_furnace's six white metal balls against the world (one rule: each
  ball at alpha / 6, as the test), the test's settings;
- enormous_spp: test_reliability.test_enormous_spp_per_iteration_is_correct's rule (pt and
  cis at 4096 spp in one iteration against the furnace's value, Bonferroni over the two),
  each trial its own seeds (pt one seed, cis 12);
- merge: test_merge.test_four_chunks_agree_with_one_render (16 repetitions of 4 chunks of 32
  spp merged against one render of 128), the test's settings, through the CLI.
"""
import os
import sys
import tempfile
from pathlib import Path
from types import SimpleNamespace

import numpy as np

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "tests" / "python"))

from lantern import metrics, student_t  # noqa: E402

LT_CUT = 8     # lt_scenes: the test's spp per seed over this
TREE_CUT = 4   # lighttree2: the test's spp per seed over this


def _tested(passed, p, n):
    return SimpleNamespace(passed=passed, blocks=SimpleNamespace(p=np.atleast_1d(p), n=n))


def pairs_lt_scenes(trial):
    import test_light_tracing as tl
    seed0 = 1000 * trial + 4000000
    for j, make in enumerate((tl.cornell_area, tl.cornell_mesh_light, tl.cornell_spot,
                              tl.cornell_sphere, tl.cornell_sun)):
        def run(make=make, j=j):
            scene = make()
            spp_pt, spp_lt = tl.SPP.get(make.__name__, (256, 128))
            pt = tl.renders(scene, "pt", spp_pt // LT_CUT, seed0 + 100 * j)
            lt = tl.renders(scene, "lt", spp_lt // LT_CUT, seed0 + 100 * j + 50)
            return lt, pt, {"block": 8}
        yield f"{make.__name__} lt vs pt (test_light_tracing)", run


class _Env:
    """monkeypatch.setenv for test_cpu_accel.render outside pytest."""

    def setenv(self, name, value):
        os.environ[name] = value


def pairs_accel(trial):
    import test_cpu_accel as ta
    seed0 = 1000 * trial + 4100000
    for scene_name, integrator in (("flags", "pt"), ("flags", "cis"), ("features", "cis")):
        def run(scene_name=scene_name, integrator=integrator):
            scene = ta.SCENES[scene_name]()
            env = _Env()
            emb = [ta.render(env, "embree", scene, integrator, seed0 + i).astype(np.float64)
                   for i in range(ta.K)]
            bvh = [ta.render(env, "bvh", scene, integrator, seed0 + i).astype(np.float64)
                   for i in range(ta.K)]
            os.environ.pop("LANTERN_ACCEL", None)
            return (*metrics.paired_sets(bvh, emb), {"block": 8})
        yield (f"{scene_name} {integrator} bvh vs embree, paired seeds "
               "(test_cpu_accel)", run)


def pairs_lighttree2(trial):
    import test_light_tree as tlt
    seed0 = 1000 * trial + 4200000
    ref_spp, spp = tlt.PT_REF // TREE_CUT, tlt.SPP // TREE_CUT
    refs = {}

    def reference(name):
        if name not in refs:
            refs[name] = tlt.renders(tlt.SCENES[name](), "pt", ref_spp,
                                     seed0 + (0 if name == "many" else 500))
        return refs[name]
    for j, integrator in enumerate(("bdpt", "lvc", "cis")):
        def run(integrator=integrator, j=j):
            r = tlt.renders(tlt.SCENES["room"](), integrator, spp, seed0 + 600 + 50 * j)
            return r, reference("room"), {"block": 8}
        yield f"room {integrator} vs pt, the tree (test_light_tree)", run

    def cdf():
        os.environ["LANTERN_LIGHT_TREE"] = "0"
        try:
            flat = tlt.renders(tlt.SCENES["many"](), "pt", ref_spp, seed0)  # the same seeds
        finally:
            os.environ.pop("LANTERN_LIGHT_TREE")
        tree = reference("many")
        assert not (tree[0] == flat[0]).all(), "LANTERN_LIGHT_TREE=0 changed nothing"
        return (*metrics.paired_sets(tree, flat), {"block": 8})
    yield "many pt tree vs global CDF, paired seeds (test_light_tree)", cdf
    for j, name in enumerate(("many", "room")):
        def ris(name=name, j=j):
            r = tlt.renders(tlt.SCENES[name](), "pt", tlt.RIS_SPP.get(name, tlt.SPP) // TREE_CUT,
                            seed0 + 800 + 50 * j, light_candidates=4)
            return r, reference(name), {"block": 8}
        yield f"{name} pt M=4 vs pt (test_light_tree)", ris


def pairs_pano2(trial):
    import test_camera_pano as tp
    seed0 = 1000 * trial + 4300000
    for turned in (False, True):
        def run(turned=turned):
            imgs, expected = tp.panorama_map(turned, seed0 + (50 if turned else 0))
            return imgs, expected, {"block": 4, "bias_cap": tp.PANO_CAP}
        yield (f"panorama {'turned ' if turned else ''}vs the world map "
               "(test_camera_pano)", run)
    cache = {}

    def pt():
        if "pt" not in cache:
            cache["pt"] = tp.renders(tp.pano_box(), "pt", tp.PT_SPP, seed0 + 100)
        return cache["pt"]
    for j, integrator in enumerate(("bdpt", "cis")):
        def run(integrator=integrator, j=j):
            other = tp.renders(tp.pano_box(), integrator, tp.SPP[integrator],
                               seed0 + 200 + 50 * j)
            return other, pt(), {"block": 8}
        yield f"panorama {integrator} vs pt (test_camera_pano)", run


def pairs_adaptive_lvc(trial):
    import test_adaptive_sampling as tas
    seed0 = 1000 * trial + 4400000

    def run():
        ad = [tas.run(adaptive_threshold=tas.THRESHOLD["lvc"], adaptive_min_samples=8,
                      seed=seed0 + k, integrator="lvc",
                      spp_per_iteration=4).image().astype(np.float64)
              for k in range(tas.AGREE_SEEDS)]
        spp = tas.FULL_SPP["lvc"]
        full = [tas.run(spp=spp, seed=seed0 + 500 + k, integrator="lvc",
                        spp_per_iteration=spp).image().astype(np.float64)
                for k in range(tas.AGREE_SEEDS)]
        return ad, full, {"block": tas.BLOCK}
    yield "adaptive vs full, half-emitter box lvc (test_adaptive_sampling)", run


def pairs_film2(trial):
    import test_film as tf
    seed0 = 1000 * trial + 4500000

    def hidden():
        imgs = tf.hidden_world_renders(seed0)
        return [img[:, :8] for img in imgs], [0.4] * 3, {"block": 8, "bias_cap": 1e-4}
    yield "plane under the hidden world vs 0.4 (test_film)", hidden
    for j, alpha in enumerate((1.0, 0.3)):
        cache = {}

        def renders(alpha=alpha, j=j, cache=cache):
            if "a" not in cache:
                cache["a"] = tf.alpha_renders(alpha, seed0 + 100 + 50 * j)
            return cache["a"]

        def covered(alpha=alpha, renders=renders):
            return ([x[:, :12] for x in renders()], alpha, {"block": 4, "bias_cap": 1e-4})

        def folded(alpha=alpha, renders=renders):
            return tf.folded_edge(renders()), 0.5 * alpha, {"block": 4, "bias_cap": 1e-4}
        yield f"alpha {alpha} covered columns vs alpha (test_film)", covered
        yield f"alpha {alpha} folded edge vs alpha / 2 (test_film)", folded


def _balls_rule(imgs, expected, alpha=1e-3, masks=(), **kw):
    """test_white_rough_metal_reflects_everything: each ball's comparison at alpha / n; fails
    where any ball fails. p x n: the smallest block p times all the balls' blocks."""
    n = len(masks)
    results = [metrics.compare_renders(imgs, expected, alpha=alpha / n, mask=m, **kw)
               for m in masks]
    p = min(float(r.blocks.p.min()) for r in results)
    return _tested(all(r.passed for r in results), p, sum(r.blocks.n for r in results))


def pairs_conductor(trial):
    import test_conductor_furnace as tc
    seed0 = 1000 * trial + 4600000

    def run():
        imgs = [tc.render(tc.metal_balls(), seed=seed0 + k) for k in range(tc.K)]
        masks = [tc.ball_mask(i) for i in range(len(tc.ROUGHNESS))]
        return imgs, [tc.WORLD] * 3, {"compare": _balls_rule, "masks": masks, "block": 4,
                                      "bias_cap": 5e-4, "se_floor": 1e-6}
    yield "white metal furnace, six roughnesses vs the world (test_conductor_furnace)", run


def _enormous_rule(estimates, _unused, alpha=1e-3):
    """test_enormous_spp_per_iteration_is_correct: |mean - expected| <= 1e-4 expected +
    z_threshold(2, alpha, dof) se for each integrator. p: the two-sided t tail of the excess
    over the cap; n = 2."""
    ok, ps = True, []
    for mean, se, dof, expected in estimates:
        allowed = 1e-4 * expected + metrics.z_threshold(2, alpha, dof) * se
        ok &= abs(mean - expected) <= allowed
        excess = max(0.0, abs(mean - expected) - 1e-4 * expected) / se
        ps.append(float(student_t.two_sided_tail(excess, dof)))
    return _tested(bool(ok), min(ps), len(ps))


def pairs_enormous_spp(trial):
    import test_reliability as tr

    def run():
        est = [tr.enormous_spp_estimate(integrator, seeds, seed0=4700000 + 100 * trial)
               for integrator, seeds in tr.ENORMOUS_SEEDS]
        return est, None, {"compare": _enormous_rule}
    yield "4096 spp in one iteration, pt and cis vs the furnace (test_reliability)", run


def pairs_merge(trial):
    import test_merge as tm

    def run():
        seed0 = 1000 * trial + 4800000
        merged, full = tm.merged_and_full(Path(tempfile.mkdtemp()), seed0, seed0 + 500)
        return [m[..., :3] for m in merged], [f[..., :3] for f in full], {"block": 8}
    yield "4 merged chunks vs one render (test_merge)", run


FAMILIES = {"lt_scenes": pairs_lt_scenes, "accel": pairs_accel, "lighttree2": pairs_lighttree2,
            "pano2": pairs_pano2, "adaptive_lvc": pairs_adaptive_lvc, "film2": pairs_film2,
            "conductor": pairs_conductor, "enormous_spp": pairs_enormous_spp,
            "merge": pairs_merge}
