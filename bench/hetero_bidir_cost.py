"""Cost and efficiency of heterogeneous and emissive media in the bidirectional integrators
(docs/volumes.md "Heterogeneous and emissive media in bdpt, lvc, cis and lt"): the scenes of
tests/python/test_volume_hetero_bdpt.py rendered by pt, lt (where it renders), bdpt and cis
with K seeds, one thread, the ceiling light hidden from the camera; per integrator the CPU time per render, the mean per-pixel variance
over the seeds (of the image, all channels) and the efficiency 1 / (variance x time) relative
to pt's. Writes a table (stdout and --out) with the machine.

    python bench/hetero_bidir_cost.py --size 16 --spp 16 --seeds 4 --out bench/results/...
"""
import argparse
import os
import platform
import sys
import time

import numpy as np

HERE = os.path.dirname(__file__)
sys.path.insert(0, os.path.join(HERE, "..", "python"))
sys.path.insert(0, os.path.join(HERE, "..", "tests", "python"))
import lantern  # noqa: E402
import test_volume_hetero_bdpt as T  # noqa: E402
from lantern import scenes  # noqa: E402

# the ceiling light hidden from the camera: its edge pixels (the same in every integrator)
# would dominate the mean variance
_cornell = scenes.cornell_box
T.scenes.cornell_box = lambda *a, **k: _cornell(*a, **dict(k, light_visible=False))


def run(scene_fn, integ, size, spp, seeds, depth):
    imgs, times = [], []
    for k in range(seeds):
        sc = scene_fn()
        sc.film.update(width=size, height=size)
        t0 = time.process_time()
        s = lantern.Session(sc, integrator=integ, seed=100 + k, backend="cpu", max_depth=depth,
                            spp_per_iteration=spp, threads=1)
        s.step()
        imgs.append(np.asarray(s.image())[..., :3].astype(np.float64))
        times.append(time.process_time() - t0)
        handed = any("rendering with pt" in w for w in s.warnings)
    imgs = np.array(imgs)
    return imgs.mean(), imgs.var(axis=0, ddof=1).mean(), float(np.mean(times)), handed


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", type=int, default=16)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--depth", type=int, default=6)
    ap.add_argument("--out")
    a = ap.parse_args()
    lines = [f"machine: {platform.node()} {platform.processor() or platform.machine()}, "
             f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}; one thread; "
             f"{a.size}x{a.size}, {a.spp} spp, {a.seeds} seeds, max_depth {a.depth}",
             f"{'scene':15s} {'integ':5s} {'mean':>8s} {'var/px':>10s} {'cpu s':>7s} "
             f"{'eff/pt':>7s}"]
    print(lines[0])
    for name, fn in T.SCENES.items():
        base = None
        for integ in ("pt", "lt", "bdpt", "cis"):
            mean, var, t, handed = run(fn, integ, a.size, a.spp, a.seeds, a.depth)
            if handed:
                lines.append(f"{name:15s} {integ:5s} (hands over to pt)")
                continue
            eff = 1.0 / (var * t)
            base = base or eff
            lines.append(f"{name:15s} {integ:5s} {mean:8.4f} {var:10.3e} {t:7.2f} "
                         f"{eff / base:7.2f}")
            print(lines[-1], flush=True)
    if a.out:
        with open(a.out, "w") as f:
            f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
