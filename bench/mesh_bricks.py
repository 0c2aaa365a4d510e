"""Majorant bricks for mesh volumes (volleft; docs/volumes.md): a sparse noise smoke cube, a
mesh volume of density FACTOR x clamp(Noise fBM Fac(position, scale 3) - THRESHOLD, 0, 1)
(tests/python/test_volume_hetero_bdpt.py's noise_density_program; THRESHOLD 0.6: pockets of
smoke in a mostly empty box) in the Cornell box, rendered by pt, one thread, with one majorant
per medium (LANTERN_MAJORANT_BRICKS=0, main's) and with 16^3 bricks of interval-bound
majorants, alternating A/B in one process. Per variant: process CPU time per render (K seeds x
SPP), the image mean with its standard error over seeds (the two must agree: both unbiased),
the mean per-pixel variance over seeds, and the efficiency 1 / (variance x time). Run from the
repository root (the checkout's python/lantern with its _core):

    nice python bench/mesh_bricks.py --out bench/results/2026-12-06-volleft/mesh_bricks.txt"""
import argparse
import os
import platform
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "python"))
sys.path.insert(0, os.path.join(ROOT, "tests", "python"))
import lantern  # noqa: E402
import test_volume_hetero_bdpt as t  # noqa: E402
from lantern import scenes  # noqa: E402


def sparse_smoke(factor, threshold):
    scene = scenes.cornell_box(t.SIZE, t.SIZE, boxes=False)
    m = scene.add_material("smoke")
    prog = t.noise_density_program(factor)
    prog["consts"][31] = threshold
    scene.materials[m].update(volume=dict(t.SMOKE), volume_only=True, programs=[prog])
    t._volume_mesh(scene, "smoke", m, *t.SMOKE_BOX)
    return scene


def render(bricks, seeds, spp, factor, threshold):
    os.environ["LANTERN_MAJORANT_BRICKS"] = "1" if bricks else "0"
    imgs, warnings = [], []
    t0 = time.process_time()
    for seed in range(1, seeds + 1):
        s = lantern.Session(sparse_smoke(factor, threshold), integrator="pt", backend="cpu",
                            seed=seed, spp_per_iteration=spp, threads=1)
        s.step()
        imgs.append(np.asarray(s.image(), dtype=np.float64)[..., :3])
        warnings = s.warnings
    dt = time.process_time() - t0
    im = np.stack(imgs)
    means = im.reshape(seeds, -1).mean(axis=1)
    return dict(cpu=dt, mean=means.mean(), se=means.std(ddof=1) / np.sqrt(seeds),
                var=im.var(axis=0, ddof=1).mean(), warnings=warnings)


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            return next(line.split(":", 1)[1].strip() for line in f if "model name" in line)
    except (OSError, StopIteration):
        return platform.processor() or platform.machine()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--factor", type=float, default=20.0)
    ap.add_argument("--threshold", type=float, default=0.6)
    ap.add_argument("--out", default="")
    a = ap.parse_args()
    lines = [f"# {' '.join(sys.argv)}", f"# {cpu_model()}, {os.cpu_count()} cores, load "
             f"{os.getloadavg()[0]:.1f} at start; pt, one thread, {a.seeds} seeds x {a.spp} spp, "
             f"{t.SIZE}x{t.SIZE}; density {a.factor} x clamp(Fac - {a.threshold}, 0, 1)"]
    print(lines[-1])
    got = {False: [], True: []}
    for rep in range(a.reps):
        for bricks in (False, True):
            r = render(bricks, a.seeds, a.spp, a.factor, a.threshold)
            got[bricks].append(r)
            line = (f"rep {rep} {'bricks  ' if bricks else 'one     '} cpu {r['cpu']:.2f} s "
                    f"mean {r['mean']:.5f} +- {r['se']:.5f} pixel var {r['var']:.4g} "
                    f"{r['warnings']}")
            print(line)
            lines.append(line)
    for bricks in (False, True):
        rs = got[bricks]
        cpu = np.mean([r["cpu"] for r in rs])
        var = np.mean([r["var"] for r in rs])
        mean = np.mean([r["mean"] for r in rs])
        se = rs[0]["se"]  # the reps render the same seeds: their images are the same
        line = (f"{'bricks' if bricks else 'one   '}: cpu {cpu:.2f} s, pixel var {var:.4g}, "
                f"image mean {mean:.5f} +- {se:.5f}, efficiency 1/(var x cpu) {1 / (var * cpu):.1f}")
        print(line)
        lines.append(line)
    if a.out:
        os.makedirs(os.path.dirname(a.out), exist_ok=True)
        with open(a.out, "w") as f:
            f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
