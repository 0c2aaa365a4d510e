"""Efficiency of the bidirectional integrators against pt on a motion scene with a hard light
(issue 32; docs/motion_blur.md): tests/python/test_motion_bidir.py's sliding box lit by a
point light of radius 0 under a camera looking down (the box's sharp shadow slides), at a
larger film. One thread; K independent seeds per configuration, rendered interleaved (seed k of
every configuration, then k + 1) so that a change of the machine's load falls on all alike.

    PYTHONPATH=python:tests/python nice -n 5 .venv/bin/python bench/motion_bidir_efficiency.py \\
        --seeds 8 --spp 16 --res 64 --out bench/results/2026-12-05-motionbidir/efficiency.json

A configuration: integrator[/spp_per_iteration]; every configuration renders --spp samples a
pixel (spp / spp_per_iteration steps). lvc and cis draw one shutter time per pass, so
`cis/16` (one pass, one time for the whole image) against `cis/1` (16 passes, 16 stratified
times) shows that choice's price. noise = mean over pixels of the per-pixel variance between
seeds (RGB averaged), time = mean seconds a render; efficiency = 1 / (variance x time), and
`rel` = efficiency / the first configuration's. The still frame (no motion) is measured too,
so the motion's own share of the noise shows."""

import argparse
import json
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "python"))
sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tests", "python"))
import lantern  # noqa: E402
import test_motion_blur as mb  # noqa: E402
import test_motion_bidir as mbd  # noqa: E402


def scene(res, moving):
    sc = mbd._lit_moving("slide") if moving else mbd._lit(mb._static_at("slide", 0.5))
    sc.film["width"] = sc.film["height"] = res
    return sc


def render(sc, integrator, per_it, spp, seed, depth):
    s = lantern.Session(sc, integrator=integrator, seed=seed, spp_per_iteration=per_it,
                        threads=1, max_depth=depth)
    t0 = time.perf_counter()
    for _ in range(spp // per_it):
        s.step()
    img = np.asarray(s.image(), np.float64)
    return img, time.perf_counter() - t0, list(s.warnings)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--configs", default="pt/16,bdpt/16,cis/1,cis/16,lvc/1,lt/16")
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--res", type=int, default=64)
    ap.add_argument("--depth", type=int, default=5)
    ap.add_argument("--out")
    a = ap.parse_args()
    configs = [(c.split("/")[0], int(c.split("/")[1])) for c in a.configs.split(",")]
    out = {"command": " ".join(sys.argv), "load": os.getloadavg(), "results": []}
    for moving in (True, False):
        sc = scene(a.res, moving)
        imgs = {c: [] for c in configs}
        secs = {c: [] for c in configs}
        for k in range(a.seeds):
            for c in configs:
                img, t, w = render(sc, c[0], c[1], a.spp, 1 + k, a.depth)
                if w:
                    print("warnings:", c, w)
                imgs[c].append(img)
                secs[c].append(t)
        base = None
        for c in configs:
            st = np.stack(imgs[c])
            var = float(st.var(axis=0, ddof=1).mean())
            t = float(np.mean(secs[c]))
            eff = 1.0 / (var * t)
            base = base or eff
            row = {"scene": "slide lit" if moving else "still lit", "integrator": c[0],
                   "spp_per_iteration": c[1], "spp": a.spp, "mean": float(st.mean()),
                   "variance": var, "seconds": t, "efficiency": eff, "rel": eff / base}
            out["results"].append(row)
            print(f"{row['scene']:10s} {c[0]:5s}/{c[1]:<3d} mean {row['mean']:.5f} "
                  f"var {var:.3e} time {t:.3f} s eff {eff:.3e} rel {eff / base:.3f}")
    out["load_after"] = os.getloadavg()
    if a.out:
        os.makedirs(os.path.dirname(a.out), exist_ok=True)
        with open(a.out, "w") as f:
            json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
