"""What each comparison of tests/python/test_bidirectional.py resolves at its test's settings:
the printed "detects a whole-image bias >= x", the control block's resolution, and whether
the 1 % / 5 % negative controls are caught (tests/README.md, "What each family resolves").

    PYTHONPATH=python:tests/python nice python -m lantern.testing.measure_controls [name ...]

MEASURE_SPP_REF / MEASURE_SPP (environment) override the scene sets' reference and
integrator samples per seed, to see what fewer or more samples would resolve.
"""
import sys
import time

import numpy as np

import test_bidirectional as tb
from lantern import agreement, metrics, scenes


REF_SPP = SPP = 0  # the test's settings unless MEASURE_SPP_REF / MEASURE_SPP say otherwise


def report(name, a, b):
    res = metrics.compare_renders(a, b, block=8)
    by, bx = agreement.control_block(res)
    blk = float(np.min(res.block_resolution()[by, bx]))
    ctl = agreement.negative_controls(a, b, 8, 0.01, 0.05)
    missed = [label for label, c in ctl if c.passed]
    print(f"{name}: {'agree' if res.passed else 'DIFFER'}; detects >= {res.detectable_bias():.2%}; "
          f"control block ({by}, {bx}) resolves {blk:.1%}; 1 %/5 % controls missed: "
          f"{missed or 'none'}", flush=True)


def scene_set(scene_name):
    scene = tb.SCENES[scene_name]()
    ref_name = tb.REFERENCE.get(scene_name, "pt")
    ref = tb.renders(scene, ref_name, REF_SPP or tb.REF_SPP_SCENE.get(scene_name,
                                                                 tb.SPP_REF[ref_name]), 1000)
    for integrator, settings in tb.BIDIRECTIONAL:
        if integrator == ref_name and not settings:
            continue
        report(f"{scene_name} {integrator} {settings} vs {ref_name}",
               tb.renders(scene, integrator, SPP or tb.SPP_SCENE.get(scene_name, tb.SPP), 2000,
                          **settings), ref)


def world():
    scene = scenes.glass_lantern(tb.SIZE, tb.SIZE)
    scene.lights = []
    scene.world = {"color": [0.6, 0.7, 0.8]}
    pt = tb.renders(scene, "pt", tb.SPP_REF["pt"], 1000)
    for integrator in ("bdpt", "cis"):
        report(f"world {integrator}", tb.renders(scene, integrator, 64, 3000), pt)


def caustic():
    scene = scenes.glossy_box(tb.SIZE, tb.SIZE, delta_light=True, roughness=0.3)
    scene.lights = []
    scene.add_light("sun", direction=[0.2, 0.6, -0.3], strength=[1.5] * 3, angle=0.0)
    report("sun caustic cis vs lt", tb.renders(scene, "cis", 64, 3000),
           tb.renders(scene, "lt", 64, 1000))


def _paired(a, b):
    level = np.mean(b, axis=0, dtype=np.float64)
    return [np.asarray(x, np.float64) - y + level for x, y in zip(a, b)], level


def cis_lvc():  # paired seeds, as test_resampled_and_uniform_picks_agree
    scene = scenes.fixture_box(tb.SIZE, tb.SIZE)
    report("cis(bsdf) vs lvc, paired", *_paired(
        tb.renders(scene, "cis", 64, 5000, cis_target="bsdf"), tb.renders(scene, "lvc", 64, 5000)))


def fixture_chain():  # test_integrators_agree[fixture]: _fixture_chain's paired seeds
    scene = scenes.fixture_box(tb.SIZE, tb.SIZE)
    n, spp = tb.FIXTURE_SEEDS, SPP or tb.FIXTURE_SPP
    lvc = tb.renders(scene, "lvc", spp, 2000, k_seeds=n)
    report("fixture lvc vs bdpt, paired", *_paired(lvc, tb.renders(scene, "bdpt", spp, 2000,
                                                                    k_seeds=n)))
    for integrator, settings in tb.BIDIRECTIONAL:
        if (integrator in ("bdpt", "lvc") and not settings) or "cis_target" in settings:
            continue
        report(f"fixture {integrator} {settings} vs lvc, paired", *_paired(
            tb.renders(scene, integrator, spp, 2000, **settings), lvc[:tb.K]))


def scale():
    ref = tb.renders(scenes.glossy_box(tb.SIZE, tb.SIZE), "cis", 32, 100)
    for k in (1e-3, 1e4):
        report(f"scaled {k:g}", tb.renders(tb._scaled(scenes.glossy_box(tb.SIZE, tb.SIZE), k),
                                           "cis", 32, 200), ref)


def cache_split():
    import lantern
    scene = scenes.fixture_box(tb.SIZE, tb.SIZE)
    imgs = []
    for k in range(tb.K):
        s = lantern.Session(scene, integrator="cis", seed=100 + k, spp_per_iteration=64,
                            max_depth=8, cache_budget_mb=1, backend="cpu")
        s.step()
        imgs.append(s.image())
    report("cache split", imgs, tb.renders(scene, "cis", 64, 200))


JOBS = {"world": world, "caustic": caustic, "cis_lvc": cis_lvc, "scale": scale,
        "cache_split": cache_split}
JOBS.update({n: (lambda n=n: scene_set(n)) for n in tb.SCENES})
JOBS["fixture"] = fixture_chain  # the test pairs the fixture's seeds

if __name__ == "__main__":
    import os
    REF_SPP = int(os.environ.get("MEASURE_SPP_REF", 0))
    SPP = int(os.environ.get("MEASURE_SPP", 0))
    for name in sys.argv[1:] or list(JOBS):
        t0 = time.perf_counter()
        JOBS[name]()
        print(f"-- {name}: {time.perf_counter() - t0:.0f} s wall, "
              f"{time.process_time():.0f} s CPU so far", flush=True)
