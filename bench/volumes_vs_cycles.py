"""The volume scenes of tests/cycles/test_volumes.py at more samples (docs/volumes.md): K seeds
a side, Lantern (pt) and Cycles (CPU), the agreement test's numbers and each side's wall time
per seed, appended to a results file with the machine. Run inside bpy's Python:

    python bench/volumes_vs_cycles.py --scenes fog_spot glow --spp 512 --seeds 8 \\
        --out bench/results/2026-12-04-volumes/vs_cycles.txt"""
import argparse
import os
import platform
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "python"))  # this checkout's lantern, as the tests' conftest
sys.path.insert(0, os.path.join(ROOT, "tests", "cycles"))
sys.path.insert(0, os.path.join(ROOT, "tools"))
_ARGV = sys.argv
if __name__ == "__main__" and ("--threads" not in _ARGV
                               or _ARGV[_ARGV.index("--threads") + 1] == "1"):
    # one CPU before bpy loads TBB: no idle TBB worker to spin through Cycles' one-thread renders
    # and bill them (bench/side_process.py, bench/results/2026-12-05-benchproc/)
    sys.path.insert(0, os.path.join(ROOT, "bench"))
    import side_process  # noqa: E402
    side_process.one_cpu()
import render_compare as rc  # noqa: E402
import test_volumes as tv  # noqa: E402
from lantern import metrics  # noqa: E402


def machine():
    """The machine and its load, for a results line."""
    return (f"{platform.node()} {platform.processor() or platform.machine()}, "
            f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}")


def emitter(out):
    """A function printing a line and appending it to the results file `out`."""
    def emit(line):
        print(line, flush=True)
        with open(out, "a") as f:
            f.write(line + "\n")
    return emit


def build_scene(build, threads=1):
    """Build a volume scene in bpy with `build` (a tests/cycles scene builder) and fix Cycles'
    thread count to `threads`; returns the bpy scene."""
    build()
    bpy_scene = __import__("bpy").context.scene
    bpy_scene.render.threads_mode, bpy_scene.render.threads = "FIXED", threads
    return bpy_scene


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", nargs="+", default=list(tv.SCENES))
    ap.add_argument("--spp", type=int, default=512)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    where = machine()
    emit = emitter(args.out)
    for name in args.scenes:
        build_scene(tv.SCENES[name], args.threads)
        t0 = time.perf_counter()
        cyc = np.stack([rc.render_cycles(seed=900 + k, spp=args.spp)[0]
                        for k in range(args.seeds)]).astype(np.float64)
        t_cyc = (time.perf_counter() - t0) / args.seeds
        t0 = time.perf_counter()
        lan = np.stack([rc.render_lantern(seed=300 + k, spp=args.spp, threads=args.threads)[0]
                        for k in range(args.seeds)]).astype(np.float64)
        t_lan = (time.perf_counter() - t0) / args.seeds
        res = metrics.compare_renders(lan, cyc, block=rc.BLOCK, se_floor=tv.SE_FLOOR, name=name)
        line = (f"{name}: {args.seeds} seeds x {args.spp} spp a side, {args.threads} thread(s); "
                f"mean ratio Lantern/Cycles {lan.mean() / cyc.mean():.4f}; {res}; wall per seed "
                f"Lantern {t_lan:.1f} s, Cycles {t_cyc:.1f} s (incl. export/setup); {where}")
        emit(line)


if __name__ == "__main__":
    main()
