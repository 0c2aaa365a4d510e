"""Render one tester case (a seed of a logged run, its avoid set) on both sides and keep every
seed's image (npz), then say where the image means differ and which side's seeds are
heavy-tailed: per block, each side's mean, the largest single seed's share of its sum, and the
brightest pixel. difftest4 (bench/results/2026-12-06-difftest4).

    nice .venv/bin/python bench/difftest4_probe.py --log bench/results/2026-12-06-difftest3/pt/log.jsonl \
        --seed 5006 --seeds 16 --spp 16 --out bench/results/2026-12-06-difftest4/probe-5006.npz
"""
import argparse
import json
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import difftest as dt  # noqa: E402


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--log", required=True)
    p.add_argument("--seed", type=int, required=True)
    p.add_argument("--seeds", type=int, default=16)
    p.add_argument("--base", type=int, default=0)
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--integrator", default=None, help="comma-separated; default the log's")
    p.add_argument("--out", required=True)
    a = p.parse_args()
    entry = next(json.loads(x) for x in open(a.log) if json.loads(x)["seed"] == a.seed)
    case = dt.ds.generate(a.seed, entry["profile"], 32, set(entry["avoid"]))
    assert dt.ds.describe(case) == entry["describe"], "the case draws differently now"
    integs = (a.integrator or entry["settings"]["integrator"]).split(",")
    dt.db.build(case)
    scene, warnings = dt.export_lantern()
    print("warnings", warnings)
    seeds = [a.base + 1 + k for k in range(a.seeds)]
    cyc = np.stack(dt.render_cycles(case["bounces"], seeds, a.spp, 1))
    lans = {i: np.stack(dt.render_lantern(scene, case["bounces"], seeds, a.spp, i, 1))
            for i in integs}
    np.savez_compressed(a.out, cycles=cyc, **lans)
    for i, lan in lans.items():
        print(f"--- {i} ({a.seeds} seeds x {a.spp} spp, seeds {seeds[0]}..)")
        report(lan, cyc)
        res = dt.compare(list(lan), list(cyc), controls=False)
        print(res.line())
        print(res.text)


def report(lan, cyc):
    for name, x in (("lantern", lan), ("cycles", cyc)):
        k = x.shape[0]
        bl = x.reshape(k, 4, 8, 4, 8, 3).mean(axis=(2, 4))      # seed, by, bx, c
        tot = bl.sum(axis=0)
        share = bl.max(axis=0) / np.maximum(tot, 1e-30)
        i = np.unravel_index(np.argmax(share * (tot > 1e-3 * tot.max())), share.shape)
        print(f"{name}: image mean {x.mean(axis=(0, 1, 2))}, per-seed image means "
              f"{np.round(x.mean(axis=(1, 2, 3)), 4).tolist()}")
        print(f"  brightest pixel {x.max():.4g} at {np.unravel_index(np.argmax(x), x.shape)};"
              f" most one-seed block {i}: one seed holds {share[i]:.0%} of its sum, block "
              f"mean {tot[i] / k:.4g}")


if __name__ == "__main__":
    main()
