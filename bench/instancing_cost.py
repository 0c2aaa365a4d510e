"""What two-level instancing costs a static render: rays per CPU second (one thread,
process_time of the render steps, so the shared machine's load matters less) with
instancing off (the flat structure final renders use) and on (a bottom-level BVH per mesh,
what viewport sessions use), for Embree and the built-in BVH, on a scene of one mesh (the
Cornell box and a 20k-triangle sphere, merged) and on the Cornell box itself (7 meshes). --base PKG adds a build from
before (a folder holding its `lantern` package, e.g. /work/main/python), instancing off.
Runs interleave, one process each; medians and ranges are printed as a table:

    python bench/instancing_cost.py --reps 5 [--base /work/main/python] [--size 96]

--callgrind counts instead the instructions per ray of the render steps under valgrind (the
process with the steps less the same process without them): a figure the load does not move."""
import argparse
import os
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CHILD = r"""
import os, sys, time
import numpy as np
sys.path.insert(0, sys.argv[1])
import lantern
from lantern import scenes
name, inst, size, steps = sys.argv[3], sys.argv[4] == "1", int(sys.argv[5]), int(sys.argv[6])
scene = scenes.cornell_box(size, size)
if name == "one_mesh":  # the box and a 20k-triangle sphere in it, as one mesh
    sp, si = scenes.icosphere(5, radius=0.35, center=(-0.3, 0.2, 1.3))
    scene.meshes.append({"positions": sp, "indices": si,
                         "material_ids": np.zeros(len(si), np.uint32)})
    pos, idx, mat, base = [], [], [], 0
    for m in scene.meshes:
        pos.append(m["positions"]); idx.append(np.asarray(m["indices"]) + base)
        mat.append(m["material_ids"]); base += len(m["positions"])
    scene.meshes = [{"name": "merged", "positions": np.concatenate(pos).astype(np.float32),
                     "indices": np.concatenate(idx).astype(np.uint32),
                     "material_ids": np.concatenate(mat).astype(np.uint32)}]
kw = {"instancing": True} if inst else {}
s = lantern.Session(scene, integrator="pt", seed=1, spp_per_iteration=4, backend="cpu",
                    threads=1, **kw)
s.step()
r0 = s.stats["rays_total"]
t = time.process_time()
for _ in range(steps):
    s.step()
dt = time.process_time() - t
print(dt, s.stats["rays_total"] - r0)
"""


def run(pkg, accel, scene, inst, size, steps):
    env = dict(os.environ, LANTERN_ACCEL=accel)
    out = subprocess.run([sys.executable, "-c", CHILD, pkg, accel, scene, "1" if inst else "0",
                          str(size), str(steps)], capture_output=True, text=True, check=True,
                         env=env).stdout.split()
    return float(out[-1]) / float(out[-2])  # rays per CPU second


def instructions(pkg, accel, scene, inst, size, steps):
    """Instructions of the child process under callgrind, and the rays it traced."""
    import tempfile
    env = dict(os.environ, LANTERN_ACCEL=accel)
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "cg.out")
        res = subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
                              sys.executable, "-c", CHILD, pkg, accel, scene,
                              "1" if inst else "0", str(size), str(steps)],
                             capture_output=True, text=True, check=True, env=env)
        rays = int(res.stdout.split()[-1])
        for line in open(out):
            if line.startswith("summary:") or line.startswith("totals:"):
                return int(line.split()[1]), rays
    raise RuntimeError("callgrind wrote no totals")


def callgrind(args, configs):
    print("| scene | accel | " + " | ".join(f"{c[0]} instr/ray" for c in configs) +
          " | two-level / flat - 1 |")
    print("|---|---|" + "---:|" * (len(configs) + 1))
    for scene in args.scenes.split(","):
        for accel in args.accels.split(","):
            per = {}
            for label, pkg, inst in configs:
                base, _ = instructions(pkg, accel, scene, inst, args.size, 0)
                total, rays = instructions(pkg, accel, scene, inst, args.size, args.steps)
                per[label] = (total - base) / rays
            cells = " | ".join(f"{per[c[0]]:.0f}" for c in configs)
            print(f"| {scene} | {accel} | {cells} | {per['two-level'] / per['flat'] - 1:+.1%} |",
                  flush=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--size", type=int, default=96)
    ap.add_argument("--steps", type=int, default=3)
    ap.add_argument("--base", default=None, help="a build from before: its python/ folder")
    ap.add_argument("--accels", default="embree,bvh")
    ap.add_argument("--callgrind", action="store_true")
    ap.add_argument("--scenes", default="one_mesh,cornell_box")
    args = ap.parse_args()
    here = str(ROOT / "python")
    configs = [("flat", here, False), ("two-level", here, True)]
    if args.base:
        configs.insert(0, ("before (flat)", args.base, False))
    if args.callgrind:
        return callgrind(args, configs)
    head = " | ".join(f"{c[0]} Mrays/s" for c in configs)
    print(f"| scene | accel | {head} | two-level / flat - 1 |")
    print("|---|---|" + "---:|" * (len(configs) + 1))
    for scene in args.scenes.split(","):
        for accel in args.accels.split(","):
            got = {c[0]: [] for c in configs}
            for _ in range(args.reps):
                for label, pkg, inst in configs:
                    got[label].append(run(pkg, accel, scene, inst, args.size, args.steps))
            med = {k: statistics.median(v) for k, v in got.items()}
            cells = " | ".join(f"{med[c[0]] / 1e6:.3f} ({min(got[c[0]]) / 1e6:.3f}-"
                               f"{max(got[c[0]]) / 1e6:.3f})" for c in configs)
            print(f"| {scene} | {accel} | {cells} | {med['two-level'] / med['flat'] - 1:+.1%} |",
                  flush=True)


if __name__ == "__main__":
    main()
