"""A lamp inside a shade in fog (lantern.scenes.fixture_box, the room filled with world fog):
noise and CPU time of pt and of light tracing (lt, medium vertices since volbidir), one thread,
K seeds each. Reported per integrator: the image mean, the mean per-pixel variance over seeds
(pixels whose mean is > 1 % of the image mean), the process CPU time per seed, and the
efficiency 1 / (variance x time); then the ratio lt / pt of the efficiencies and the means'
agreement (lantern.metrics.compare_renders). bdpt, lvc and cis hand media scenes to pt still
(docs/volumes.md), so they are not measured here.

    PYTHONPATH=python nice python bench/volbidir_noise.py --spp 64 --seeds 8 \\
        --out bench/results/2026-12-04-volbidir/lamp_fog.txt"""
import argparse
import os
import platform
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
import lantern  # noqa: E402
from lantern import metrics, scenes  # noqa: E402


def lamp_fog(size, sigma_s, g):
    scene = scenes.fixture_box(size, size)
    scene.world = {"color": [0.0, 0.0, 0.0],
                   "volume": {"sigma_s": [sigma_s] * 3, "sigma_a": [0.02] * 3, "g": g}}
    return scene


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", type=int, default=48)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--max-depth", type=int, default=8)
    ap.add_argument("--sigma-s", type=float, default=0.2)
    ap.add_argument("--g", type=float, default=0.3)
    ap.add_argument("--integrators", nargs="+", default=["pt", "lt"])
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    scene = lamp_fog(args.size, args.sigma_s, args.g)
    machine = (f"{platform.node()} {platform.processor() or platform.machine()}, "
               f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}")
    lines = [f"lamp in a shade in fog: fixture_box {args.size}x{args.size}, world fog sigma_s "
             f"{args.sigma_s} sigma_a 0.02 g {args.g}, max_depth {args.max_depth}, "
             f"{args.seeds} seeds x {args.spp} spp, 1 thread; {machine}"]
    imgs, eff = {}, {}
    for integ in args.integrators:
        out, cpu = [], []
        for k in range(args.seeds):
            c0 = time.process_time()
            s = lantern.Session(scene, integrator=integ, backend="cpu", seed=1 + k,
                                max_depth=args.max_depth, spp_per_iteration=args.spp, threads=1)
            while s.spp < args.spp:
                s.step()
            out.append(np.asarray(s.image(), dtype=np.float64)[..., :3])
            cpu.append(time.process_time() - c0)
            assert not any("rendering with pt" in w for w in s.warnings), s.warnings
        a = np.stack(out)
        mean = a.mean(axis=0)
        lit = mean.mean(axis=-1) > 0.01 * mean.mean()
        var = a.var(axis=0, ddof=1).mean(axis=-1)[lit].mean()
        t = float(np.mean(cpu))
        imgs[integ], eff[integ] = out, 1.0 / (var * t)
        lines.append(f"  {integ}: image mean {a.mean():.5f}; mean pixel variance {var:.4e}; "
                     f"CPU {t:.2f} s/seed; efficiency {eff[integ]:.4g}")
    if "pt" in eff:
        for integ in eff:
            if integ == "pt":
                continue
            res = metrics.compare_renders(imgs[integ], imgs["pt"], block=8,
                                          name=f"{integ} vs pt")
            lines.append(f"  efficiency {integ} / pt: {eff[integ] / eff['pt']:.2f}x; {res}")
    text = "\n".join(lines)
    print(text, flush=True)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, "a") as f:
        f.write(text + "\n")


if __name__ == "__main__":
    main()
