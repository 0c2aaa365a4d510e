"""Wall time per sample of a diffuse-only scene on several builds, interleaved so that each
sees the same machine load: the Cornell box, 64 x 64, 4 spp per iteration, 1 thread, best of
3 steps per run and of `reps` runs per build (best-of resists other work on a shared machine;
bench/material_cost.py counts instructions, which load does not disturb at all).

    .venv/bin/python bench/diffuse_walltime.py old=/tmp/old/python new=python [--reps 6]

Each NAME=DIR names a directory holding a `lantern` package (another build: `git archive` a
commit, build its `_core` module, copy it into its python/lantern)."""
import argparse
import json
import subprocess
import sys

RUN = r'''
import sys, time, json
sys.path.insert(0, sys.argv[1])
import lantern
from lantern import scenes
sc = scenes.cornell_box(width=64, height=64)
out = {}
for integ in ("pt", "cis"):
    s = lantern.Session(sc, integrator=integ, seed=1, spp_per_iteration=4, threads=1)
    s.step()
    best = 1e9
    for _ in range(3):
        t = time.perf_counter(); s.step(); best = min(best, time.perf_counter() - t)
    out[integ] = best / 4 * 1000
print(json.dumps(out))
'''


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("builds", nargs="+", help="NAME=DIR")
    ap.add_argument("--reps", type=int, default=6)
    args = ap.parse_args()
    builds = dict(b.split("=", 1) for b in args.builds)
    best = {b: {"pt": float("inf"), "cis": float("inf")} for b in builds}
    for _ in range(args.reps):
        for name, path in builds.items():
            out = subprocess.run([sys.executable, "-c", RUN, path], capture_output=True,
                                 text=True, check=True).stdout.strip().splitlines()[-1]
            for k, v in json.loads(out).items():
                best[name][k] = min(best[name][k], v)
    for name, d in best.items():
        print(f"{name}: pt {d['pt']:.2f} ms per spp, cis {d['cis']:.2f} ms per spp")


if __name__ == "__main__":
    main()
