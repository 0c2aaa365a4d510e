"""Efficiency of the bidirectional integrators against pt on subsurface (docs/subsurface.md,
"Bidirectional integrators"): the sphere on a floor of tests/python/test_subsurface_bidir.py
with Random Walk (Skin), 32 x 32, one thread. Per integrator K independent seeds of S spp;
noise = the mean over pixels of the per-pixel variance across seeds (of the RGB mean), time =
the median seconds per render; efficiency = 1 / (noise x time), also relative to pt's. The
machine and its load are printed: on a shared machine only large differences mean anything.

    PYTHONPATH=python python bench/sss_bidir_efficiency.py [--seeds 8] [--spp 16] [--out F.json]"""
import argparse
import json
import os
import platform
import statistics
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tests", "python"))
import lantern  # noqa: E402
from test_subsurface_bidir import lit_sphere  # noqa: E402


def skin_scene(size):
    s = lit_sphere(size=size)
    s.materials[0]["subsurface_method"] = "random_walk_skin"
    return s


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--size", type=int, default=32)
    ap.add_argument("--integrators", default="pt,bdpt,lvc,cis")
    ap.add_argument("--out")
    a = ap.parse_args()
    scene = skin_scene(a.size)
    print(f"machine: {platform.processor() or platform.machine()}, load {os.getloadavg()}")
    rows = {}
    for integ in a.integrators.split(","):
        imgs, times = [], []
        for k in range(a.seeds):
            t = time.perf_counter()
            img = lantern.render(scene, spp=a.spp, seed=1000 + k, max_depth=16,
                                 integrator=integ, threads=1)
            times.append(time.perf_counter() - t)
            imgs.append(np.asarray(img, np.float64)[..., :3].mean(axis=-1))
        x = np.stack(imgs)
        var = float(x.var(axis=0, ddof=1).mean())
        sec = statistics.median(times)
        rows[integ] = {"mean": float(x.mean()), "pixel_var": var, "seconds": sec,
                       "efficiency": 1.0 / (var * sec)}
    base = rows.get("pt", {}).get("efficiency")
    for integ, r in rows.items():
        rel = r["efficiency"] / base if base else float("nan")
        print(f"{integ:5s} mean {r['mean']:.5f} pixel var {r['pixel_var']:.3e} "
              f"time {r['seconds']:.3f} s efficiency {r['efficiency']:.3e} (x{rel:.2f} pt)")
        r["relative_to_pt"] = rel
    print(f"load after: {os.getloadavg()}")
    if a.out:
        with open(a.out, "w") as f:
            json.dump({"args": vars(a), "machine": platform.processor() or platform.machine(),
                       "rows": rows}, f, indent=1)


if __name__ == "__main__":
    main()
