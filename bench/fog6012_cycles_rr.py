"""Issue 32 / difftest case 6012: Cycles against Cycles. Cycles drops the light of a lamp (and of
the world) that a bounce ray meets inside a volume when Russian roulette ends the path there,
and does not divide by the survival probability when it does not: intersect_closest.h
integrator_intersect_next_kernel calls integrator_intersect_terminate for every hit while
the volume stack is not empty (flags 0 for a lamp or a miss: PATH_RAY_TERMINATE_IN_NEXT_VOLUME,
then shade_volume returns VOLUME_PATH_MISSED), while outside volumes a lamp hit goes to
SHADE_LIGHT_FORWARD untested and a miss to SHADE_BACKGROUND. Roulette is off for bounces up to
Min Light Bounces (scene.cycles.min_light_bounces; Cycles' kernel min_bounce = it + 1), which
changes nothing else in expectation: renders with 0 (the default) and with the bounce count
must agree, and do without the fog, not with it.

    nice .venv/bin/python bench/fog6012_cycles_rr.py --spp 32 --seeds 16 [--edit STATEMENTS] \
        [--full] [--lantern pt,bdpt] [--json out.jsonl]

The case is bench/fog6012_bisect.py's (the room, its fog and lamps; --full: the whole case).
Prints Cycles(min 0) / Cycles(min B) - 1 and, with --lantern, each integrator against each.
"""
import argparse
import copy
import json
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.path.insert(0, os.path.join(ROOT, "bench"))
import difftest as dt  # noqa: E402
import difftest_build as db  # noqa: E402
from fog6012_bisect import CASE, room_only, fog, room, lamps  # noqa: E402,F401


def cycles(case, seeds, spp, min_light):
    import bpy
    bpy.context.scene.cycles.min_light_bounces = min_light
    return dt.render_cycles(case["bounces"], seeds, spp, 1)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--spp", type=int, default=32)
    p.add_argument("--seeds", type=int, default=16)
    p.add_argument("--base", type=int, default=7000)
    p.add_argument("--edit", default="", help="Python statements editing the case `c`")
    p.add_argument("--lantern", default=None, help="also Lantern with these integrators (comma-separated)")
    p.add_argument("--json", default=None)
    p.add_argument("--full", action="store_true", help="the whole case (plane and hair too)")
    a = p.parse_args()
    c = copy.deepcopy(json.load(open(CASE))["case"])
    if not a.full:
        room_only(c)
    exec(a.edit, dict(globals(), c=c))
    db.build(c)
    seeds = [a.base + 1 + k for k in range(a.seeds)]
    big = c["bounces"] + 2
    t0 = time.process_time()
    c0 = cycles(c, seeds, a.spp, 0)
    cb = cycles(c, seeds, a.spp, big)
    out = {"edit": a.edit, "full": a.full, "seeds": a.seeds, "spp": a.spp, "base": a.base}
    r = dt.compare(c0, cb, controls=False)
    print(f"[{a.edit or 'base'}] Cycles min_light_bounces 0 vs {big}: {r.line()}", flush=True)
    print("  per-seed means min 0:", np.round([x.mean() for x in c0], 4).tolist())
    print(f"  per-seed means min {big}:", np.round([x.mean() for x in cb], 4).tolist())
    out["cycles0_vs_cyclesB"] = {"status": r.status, "mean_rel": r.mean_rel,
                                 "detects": r.detects, "text": r.text}
    scene, _ = dt.export_lantern()
    for integ in (a.lantern.split(",") if a.lantern else []):
        lan = dt.render_lantern(scene, c["bounces"], seeds, a.spp, integ, 1)
        print(f"  per-seed means lantern {integ}:",
              np.round([x.mean() for x in lan], 4).tolist())
        for name, cyc in (("0", c0), (str(big), cb)):
            r = dt.compare(lan, cyc, controls=False)
            print(f"[{a.edit or 'base'}] Lantern {integ} vs Cycles min_light_bounces "
                  f"{name}: {r.line()}", flush=True)
            out[f"{integ}_vs_cycles{name}"] = {"status": r.status, "mean_rel": r.mean_rel,
                                               "detects": r.detects, "text": r.text}
    print(f"  cpu {time.process_time() - t0:.0f} s")
    if a.json:
        with open(a.json, "a") as f:
            f.write(json.dumps(out) + "\n")


if __name__ == "__main__":
    main()
