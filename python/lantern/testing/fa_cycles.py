"""False-alarm families of the comparisons against stored Cycles references (tests/render), for
false_alarm.py (its FAMILIES, loaded by load_family_modules). Each trial renders the
Lantern side with its own seeds at the test's settings; the Cycles side is the stored reference
(8 Cycles seeds), one fixed set shared by the 20 trials, as the `cycles` family does with
light_sun. Needs bpy.

- cycles_refs: render/test_cycles_compare.py on every stored reference but light_sun (the
  `cycles` family), at its RUNS (seeds, spp);
- world_cycles: render/test_world_cycles.py, world_hdri with bdpt, lvc and cis;
- world_film: render/test_world_film.py, the colour and the partly transparent blocks' alpha
  of world_film_holdout and world_film_catcher (their film/ references).
"""

import json
import os
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[3]
for sub in ("tools", "tests/render", "blend_scenes"):
    if str(ROOT / sub) not in sys.path:
        sys.path.insert(0, str(ROOT / sub))


def _stored(ref_dir, name, channels=slice(None)):
    from lantern import metrics
    ref = dict(np.load(os.path.join(ref_dir, name + ".npz")))
    with open(os.path.join(ref_dir, name + ".json")) as f:
        meta = json.load(f)
    cycles = metrics.SeedBlocks(ref["seed_block_means"][..., channels])
    assert len(cycles) == len(meta["seeds"])
    return ref, cycles


def _trial(trial):
    """The trial's seed index: FA_TRIAL_OFFSET (default 0) added, so that a run cut short can
    be continued with the trials it did not reach (their seeds as in one run)."""
    return trial + int(os.environ.get("FA_TRIAL_OFFSET", "0"))


def _addon():
    import lantern_bpy
    lantern_bpy.load_addon()


def pairs_cycles_refs(trial):
    """test_matches_cycles on each stored reference but light_sun: Lantern seeds
    2000000 + 1000 trial + k at the test's (seeds, spp), against the stored Cycles blocks."""
    trial = _trial(trial)
    import render_compare as rc
    import test_cycles_compare as tc
    _addon()

    def run(name):
        _, cycles = _stored(rc.REF_DIR, name)
        rc.build_scene(name)
        seeds, spp = tc.RUNS.get(name, (tc.LANTERN_SEEDS, tc.LANTERN_SPP))
        imgs = [rc.render_lantern(seed=2000000 + 1000 * trial + k, spp=spp)[0]
                for k in range(seeds)]
        return imgs, cycles, {"block": rc.BLOCK}
    for name in tc.REFS:
        if name != "light_sun":
            yield f"lantern vs stored Cycles, {name} (test_cycles_compare)", (
                lambda name=name: run(name))


def pairs_world_cycles(trial):
    """test_world_cycles.py: world_hdri with bdpt, lvc and cis, LANTERN_SEEDS x LANTERN_SPP,
    Lantern seeds 2100000 + 1000 trial + 100 i + k, against the stored Cycles blocks."""
    trial = _trial(trial)
    import render_compare as rc
    import test_world_cycles as tw
    _addon()

    def run(i, integrator):
        _, cycles = _stored(rc.REF_DIR, tw.NAME)
        rc.build_scene(tw.NAME)
        imgs = [rc.render_lantern(seed=2100000 + 1000 * trial + 100 * i + k, spp=tw.LANTERN_SPP,
                                  integrator=integrator)[0] for k in range(tw.LANTERN_SEEDS)]
        return imgs, cycles, {"block": rc.BLOCK}
    for i, integrator in enumerate(("bdpt", "lvc", "cis")):
        yield f"world_hdri {integrator} vs stored Cycles (test_world_cycles)", (
            lambda i=i, integrator=integrator: run(i, integrator))


def pairs_world_film(trial):
    """test_world_film.py: per scene its RUNS (seeds, spp) of render_lantern_rgba, Lantern
    seeds 2200000 + 1000 trial + 100 i + k; the colour against the stored RGB blocks and the
    alpha of the partly transparent blocks (Cycles' block mean in (0.01, 0.99)) against the
    stored alpha blocks, as the two tests compare them."""
    trial = _trial(trial)
    import render_compare as rc
    import test_world_film as tf
    _addon()
    cache = {}

    def renders(i, name):
        if name not in cache:
            tf.build(name)
            seeds, spp = tf.RUNS[name]
            cache[name] = [tf.render_lantern_rgba(2200000 + 1000 * trial + 100 * i + k, spp)[0]
                           for k in range(seeds)]
        return cache[name]

    def colour(i, name):
        _, cycles = _stored(tf.REF_DIR, name, slice(0, 3))
        return [x[..., :3] for x in renders(i, name)], cycles, {"block": rc.BLOCK}

    def alpha(i, name):
        ref, cycles = _stored(tf.REF_DIR, name, slice(3, None))
        cyc = ref["block_mean"][..., 3]
        partial = (cyc > 0.01) & (cyc < 0.99)
        return ([x[..., 3:] for x in renders(i, name)], cycles,
                {"block": rc.BLOCK, "mask": partial})
    for i, name in enumerate(tf.NAMES):
        yield f"{name} colour vs stored Cycles (test_world_film)", (
            lambda i=i, name=name: colour(i, name))
        yield f"{name} alpha vs stored Cycles (test_world_film)", (
            lambda i=i, name=name: alpha(i, name))


FAMILIES = {"cycles_refs": pairs_cycles_refs, "world_cycles": pairs_world_cycles,
            "world_film": pairs_world_film}
