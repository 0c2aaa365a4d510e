"""Interleaved A/B CPU timing of two builds of lantern (two folders that each hold a `lantern`
package with its _core), one process per run, CPU time of the render steps (process_time, one
thread: less sensitive to a shared machine's load than wall time):

    python bench/cpu_speed_ab.py --a /tmp/base_pkg --b /tmp/new_pkg --reps 7 \\
        --integrators pt,lvc,cis --scenes fixture_box,cornell_box

Prints per (scene, integrator) the median seconds of A and B and B / A - 1, with the spread of
the runs; writes nothing else. Issue 13: speed within 3 % of the build before."""
import argparse
import statistics
import subprocess
import sys

CHILD = r"""
import sys, time
sys.path.insert(0, sys.argv[1])
import lantern
from lantern import scenes
scene = getattr(scenes, sys.argv[3])(int(sys.argv[4]), int(sys.argv[4]))
s = lantern.Session(scene, integrator=sys.argv[2], seed=1, spp_per_iteration=4, backend="cpu",
                    threads=1)
s.step()
t = time.process_time()
for _ in range(3):
    s.step()
print(time.process_time() - t)
"""


def run(pkg, integ, scene, size):
    out = subprocess.run([sys.executable, "-c", CHILD, pkg, integ, scene, str(size)],
                         capture_output=True, text=True, check=True).stdout
    return float(out.split()[-1])


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--a", required=True)
    ap.add_argument("--b", required=True)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--integrators", default="pt,lvc,cis")
    ap.add_argument("--scenes", default="fixture_box,cornell_box")
    ap.add_argument("--size", type=int, default=128)
    args = ap.parse_args()
    print("| scene | integrator | A median (s) | B median (s) | B / A - 1 | A range | B range |")
    print("|---|---|---:|---:|---:|---|---|")
    for scene in args.scenes.split(","):
        for integ in args.integrators.split(","):
            a, b = [], []
            for _ in range(args.reps):  # interleaved: A, B, A, B, ...
                a.append(run(args.a, integ, scene, args.size))
                b.append(run(args.b, integ, scene, args.size))
            ma, mb = statistics.median(a), statistics.median(b)
            print(f"| {scene} | {integ} | {ma:.3f} | {mb:.3f} | {mb / ma - 1:+.1%} | "
                  f"{min(a):.3f}-{max(a):.3f} | {min(b):.3f}-{max(b):.3f} |", flush=True)
