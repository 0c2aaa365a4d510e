"""Interleaved A/B CPU timing of two builds of lantern (two folders that each hold a `lantern`
package with its _core), one process per run, CPU time of the render steps (process_time, one
thread: less sensitive to a shared machine's load than wall time):

    python bench/cpu_speed_ab.py --a /tmp/base_pkg --b /tmp/new_pkg --reps 7 \\
        --integrators pt,lvc,cis --scenes fixture_box,cornell_box

Prints per (scene, integrator) the median seconds of A and B and B / A - 1, with the spread of
the runs; writes nothing else. Issue 13: speed within 3 % of the build before.

A scene is a lantern.scenes builder name, or file:PATH (a saved .lantern scene, its film scaled
to --size wide). --callgrind counts instead the instructions of two steps after the warm-up under valgrind
(callgrind; each build's whole process less its own process without those steps, so that a
build's warm-up step counts as its warm-up, not as its steps): a figure the machine's load does
not change."""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile

CHILD = r"""
import sys, time
sys.path.insert(0, sys.argv[1])
import lantern
from lantern import scenes
name, size = sys.argv[3], int(sys.argv[4])
if name.startswith("file:"):
    scene = lantern.load_scene(name[5:])
    f = scene.film
    f["width"], f["height"] = size, max(1, round(f["height"] * size / f["width"]))
else:
    scene = getattr(scenes, name)(size, size)
s = lantern.Session(scene, integrator=sys.argv[2], seed=1, spp_per_iteration=4, backend="cpu",
                    threads=1)
s.step()
t = time.process_time()
for _ in range(int(sys.argv[5])):
    s.step()
print(time.process_time() - t)
"""


def run(pkg, integ, scene, size, steps=3):
    out = subprocess.run([sys.executable, "-c", CHILD, pkg, integ, scene, str(size), str(steps)],
                         capture_output=True, text=True, check=True).stdout
    return float(out.split()[-1])


def instructions(pkg, integ, scene, size, steps):
    """Instructions of the whole child process under callgrind (the module is stripped, so no
    toggle by function): one warm-up step and `steps` more."""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "cg.out")
        subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
                        sys.executable, "-c", CHILD, pkg, integ, scene, str(size), str(steps)],
                       capture_output=True, text=True, check=True)
        for line in open(out):
            if line.startswith("summary:") or line.startswith("totals:"):
                return int(line.split()[1])
    raise RuntimeError("callgrind wrote no totals")


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--a", required=True)
    ap.add_argument("--b", required=True)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--integrators", default="pt,lvc,cis")
    ap.add_argument("--scenes", default="fixture_box,cornell_box")
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--callgrind", action="store_true",
                    help="instructions of two steps after the warm-up, per build, instead")
    args = ap.parse_args()
    if args.callgrind:
        # steps = (process with the warm-up and 2 steps) - (the same build's process with the
        # warm-up only): the warm-up step runs the changed code too, so subtracting A's from
        # both would count B's warm-up difference as B's steps
        print("| scene | integrator | A0 (warm-up only) | B0 | A: 2 steps (instructions) | "
              "B: 2 steps | B / A - 1 |")
        print("|---|---|---:|---:|---:|---:|---:|")
        for scene in args.scenes.split(","):
            for integ in args.integrators.split(","):
                a0 = instructions(args.a, integ, scene, args.size, 0)
                b0 = instructions(args.b, integ, scene, args.size, 0)
                a = instructions(args.a, integ, scene, args.size, 2) - a0
                b = instructions(args.b, integ, scene, args.size, 2) - b0
                print(f"| {scene} | {integ} | {a0:,} | {b0:,} | {a:,} | {b:,} | "
                      f"{b / a - 1:+.2%} |", flush=True)
        sys.exit(0)
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
