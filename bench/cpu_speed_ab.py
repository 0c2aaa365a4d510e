"""Interleaved A/B CPU timing of two builds of lantern (two folders that each hold a `lantern`
package with its _core), one process per run, CPU time of the render steps (process_time:
less sensitive to a shared machine's load than wall time; at more than one thread it is the
sum over the threads, so the wall time is printed beside it):

    python bench/cpu_speed_ab.py --a /tmp/base_pkg --b /tmp/new_pkg --reps 7 \\
        --integrators pt,lvc,cis --scenes fixture_box,cornell_box --threads 1,2

Prints per (scene, integrator, threads) the median seconds of A and B, B / A - 1 of the
medians, the standard error of the mean paired log-ratio (the runs go A B B A A B ..., so a
drift of the machine's load cancels within each pair of pairs), the runs' ranges and the
1-minute load average before and after the row; writes nothing else. Issue 13: speed within
3 % of the build before.

A scene is a lantern.scenes builder name, or file:PATH (a saved .lantern scene, its film scaled
to --size wide). --callgrind counts instead the instructions of the render steps under
valgrind's callgrind, one process per build: the child calls getsid() right before and right
after the --cg-steps steps after the warm-up, callgrind dumps its counters at each call
(--dump-before=getsid), and the part between the two dumps is the steps, all threads, each
build's own (no warm-up, start-up or exit in it). Start-up and the warm-up run without
instrumentation (--instr-atstart=no; the child switches it on with callgrind_control after
the warm-up), which makes a run several times faster; instruction counts need no cache
simulation, so the steps' counts are the same either way. The earlier version took the whole process
less A's warm-up-only process for both builds, which counted B's warm-up step, and B's
start-up, as B's: it overstated a change by about half. A figure the machine's load does not
change; PYTHONHASHSEED=0 keeps the interpreter's part the same from run to run."""
import argparse
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile

CHILD = r"""
import os, sys, time
sys.path.insert(0, sys.argv[1])
import lantern
from lantern import scenes
name, size, threads = sys.argv[3], int(sys.argv[4]), int(sys.argv[6])
if name.startswith("file:"):
    scene = lantern.load_scene(name[5:])
    f = scene.film
    f["width"], f["height"] = size, max(1, round(f["height"] * size / f["width"]))
else:
    scene = getattr(scenes, name)(size, size)
s = lantern.Session(scene, integrator=sys.argv[2], seed=1, spp_per_iteration=4, backend="cpu",
                    threads=threads)
s.step()
if os.environ.get("CG_INSTR_ON"):  # under callgrind --instr-atstart=no: count from here on
    import subprocess
    subprocess.run(["callgrind_control", "-i", "on", str(os.getpid())], check=True,
                   capture_output=True)
os.getsid(0)  # callgrind's marker (--dump-before=getsid): the steps start
t, w = time.process_time(), time.perf_counter()
for _ in range(int(sys.argv[5])):
    s.step()
t, w = time.process_time() - t, time.perf_counter() - w
os.getsid(0)  # the steps end
print(t, w)
"""

ENV = dict(os.environ, PYTHONHASHSEED="0")


def run(pkg, integ, scene, size, threads, steps=3):
    """(CPU seconds, wall seconds) of `steps` steps after the warm-up, in a fresh process."""
    out = subprocess.run([sys.executable, "-c", CHILD, pkg, integ, scene, str(size), str(steps),
                          str(threads)], capture_output=True, text=True, check=True,
                         env=ENV).stdout
    cpu, wall = out.split()[-2:]
    return float(cpu), float(wall)


def instructions(pkg, integ, scene, size, steps, keep=None):
    """Instructions of `steps` render steps after the warm-up, one thread, under callgrind: the
    part of the process between the child's two getsid() calls (the module is stripped, so no
    toggle by function name; a libc call as marker instead). keep: a path to copy that part's
    callgrind file to (callgrind_annotate per function, with an unstripped build)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "cg.out")
        subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
                        "--instr-atstart=no", "--dump-before=getsid", sys.executable, "-c",
                        CHILD, pkg, integ, scene, str(size), str(steps), "1"],
                       capture_output=True, text=True, check=True,
                       env=dict(ENV, CG_INSTR_ON="1"))
        parts = sorted(f for f in os.listdir(tmp) if f.startswith("cg.out"))
        if parts != ["cg.out", "cg.out.1", "cg.out.2"]:
            raise RuntimeError(f"expected 3 callgrind parts (start-up, steps, exit): {parts}")
        if keep:
            shutil.copyfile(os.path.join(tmp, "cg.out.2"), keep)
        for line in open(os.path.join(tmp, "cg.out.2")):
            if line.startswith("summary:") or line.startswith("totals:"):
                return int(line.split()[1])
    raise RuntimeError("callgrind wrote no totals")


def label(scene):
    return os.path.basename(scene[5:]).removesuffix(".lantern") if scene.startswith(
        "file:") else scene


def load1():
    return os.getloadavg()[0]


def timed_row(args, scene, integ, threads):
    a, b, ratios = [], [], []
    load_before = load1()
    for rep in range(args.reps):  # A B, B A, A B, ...: a steady drift cancels in pairs of pairs
        order = [("a", args.a), ("b", args.b)]
        if rep % 2:
            order.reverse()
        got = {k: run(pkg, integ, scene, args.size, threads, args.steps) for k, pkg in order}
        a.append(got["a"])
        b.append(got["b"])
        ratios.append(math.log(got["b"][0] / got["a"][0]))
    load_after = load1()
    ca, cb = [x[0] for x in a], [x[0] for x in b]
    ma, mb = statistics.median(ca), statistics.median(cb)
    se = statistics.stdev(ratios) / math.sqrt(len(ratios)) if len(ratios) > 1 else float("nan")
    wa, wb = statistics.median(x[1] for x in a), statistics.median(x[1] for x in b)
    return (f"| {label(scene)} | {integ} | {threads} | {ma:.3f} | {mb:.3f} | {mb / ma - 1:+.1%} "
            f"| {se:.1%} | {min(ca):.3f}-{max(ca):.3f} | {min(cb):.3f}-{max(cb):.3f} "
            f"| {wa:.3f} / {wb:.3f} | {load_before:.1f} / {load_after:.1f} |")


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--a", required=True)
    ap.add_argument("--b", required=True)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--integrators", default="pt,lvc,cis")
    ap.add_argument("--scenes", default="fixture_box,cornell_box")
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--threads", default="1", help="comma-separated thread counts (timing)")
    ap.add_argument("--steps", type=int, default=3, help="timed steps after the warm-up")
    ap.add_argument("--callgrind", action="store_true",
                    help="instructions of --cg-steps steps after the warm-up, per build, instead")
    ap.add_argument("--cg-steps", type=int, default=2)
    args = ap.parse_args()
    scenes = args.scenes.split(",")
    integs = args.integrators.split(",")
    if args.callgrind:
        n = args.cg_steps
        print(f"| scene | integrator | A: {n} steps (instructions) | B: {n} steps | B / A - 1 |")
        print("|---|---|---:|---:|---:|")
        for scene in scenes:
            for integ in integs:
                a = instructions(args.a, integ, scene, args.size, n)
                b = instructions(args.b, integ, scene, args.size, n)
                print(f"| {label(scene)} {args.size}px | {integ} | {a:,} | {b:,} | "
                      f"{b / a - 1:+.2%} |", flush=True)
        sys.exit(0)
    print("| scene | integrator | threads | A median CPU (s) | B median CPU (s) | B / A - 1 "
          "| se (paired) | A range | B range | wall A / B (s) | load before / after |")
    print("|---|---|---:|---:|---:|---:|---:|---|---|---|---|")
    for threads in [int(t) for t in args.threads.split(",")]:
        for scene in scenes:
            for integ in integs:
                print(timed_row(args, scene, integ, threads), flush=True)
