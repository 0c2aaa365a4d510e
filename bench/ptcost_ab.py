"""pt's CPU time per sample, two builds of lantern alternating (A B, B A, ...), one fresh process
per run, one thread, as bench/efficiency_cycles.py renders pt: spp_per_iteration 1, 64 steps,
max_depth 18 (Cycles' 16 bounces + 2), the BVH built before the timing. Each run prints the CPU
seconds of its steps (time.process_time) and the SHA-1 of its image, so that a change claimed to
keep the bits is seen to keep them on these scenes:

    python bench/save_blend_scene.py cornell_box 64x64 /tmp/s/cornell_box.lantern   # (bpy)
    python bench/ptcost_ab.py --a /tmp/base_pkg --b /tmp/new_pkg --reps 5 \\
        --scenes /tmp/s/cornell_box.lantern,/tmp/s/room_area_point.lantern --accel embree,bvh

(--a / --b: folders that each hold a `lantern` package with its _core). Prints per (scene,
accel) the median CPU seconds of A and B, B / A - 1 of the medians with the standard error of
the mean paired log-ratio, whether every image of B equals A's bit for bit, and the 1-minute
load before and after the row."""
import argparse
import math
import os
import statistics
import subprocess
import sys

CHILD = r"""
import hashlib, sys, time
sys.path.insert(0, sys.argv[1])
import lantern
scene = lantern.load_scene(sys.argv[2])
s = lantern.Session(scene, integrator="pt", seed=int(sys.argv[4]), spp_per_iteration=1,
                    backend="cpu", threads=1, max_depth=18)
t = time.process_time()
for _ in range(int(sys.argv[3])):
    s.step()
t = time.process_time() - t
import numpy as np
print(t, hashlib.sha1(np.asarray(s.image()).tobytes()).hexdigest())
"""


def run(pkg, scene, steps, seed, accel):
    env = dict(os.environ, PYTHONHASHSEED="0")
    if accel:
        env["LANTERN_ACCEL"] = accel
    out = subprocess.run([sys.executable, "-c", CHILD, pkg, scene, str(steps), str(seed)],
                         capture_output=True, text=True, check=True, env=env).stdout.split()
    return float(out[-2]), out[-1]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--a", required=True)
    ap.add_argument("--b", required=True)
    ap.add_argument("--scenes", required=True, help="comma-separated .lantern files")
    ap.add_argument("--accel", default="embree", help="comma-separated: embree, bvh")
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--steps", type=int, default=64)
    args = ap.parse_args()
    print(f"# {' '.join(sys.argv)}")
    print("| scene | accel | A CPU s (median) | B CPU s (median) | B / A - 1 | se (paired log) | "
          "A range | B range | bits | load before / after |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for scene in args.scenes.split(","):
        name = os.path.basename(scene).removesuffix(".lantern")
        for accel in args.accel.split(","):
            load0 = os.getloadavg()[0]
            ta, tb, logs, same = [], [], [], True
            for rep in range(args.reps):
                order = [("a", args.a), ("b", args.b)]
                if rep % 2:
                    order.reverse()
                got = {k: run(pkg, scene, args.steps, 1 + rep, accel) for k, pkg in order}
                ta.append(got["a"][0])
                tb.append(got["b"][0])
                logs.append(math.log(got["b"][0] / got["a"][0]))
                same = same and got["a"][1] == got["b"][1]
            ma, mb = statistics.median(ta), statistics.median(tb)
            se = statistics.stdev(logs) / math.sqrt(len(logs)) if len(logs) > 1 else float("nan")
            print(f"| {name} | {accel} | {ma:.4f} | {mb:.4f} | {100 * (mb / ma - 1):+.1f} % | "
                  f"{100 * se:.1f} % | {min(ta):.3f}-{max(ta):.3f} | {min(tb):.3f}-{max(tb):.3f} | "
                  f"{'identical' if same else 'DIFFER'} | {load0:.1f} / {os.getloadavg()[0]:.1f} |",
                  flush=True)


if __name__ == "__main__":
    main()
