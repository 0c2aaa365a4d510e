"""Noise and CPU time of pt, bdpt, lvc and cis on the media scenes of
tests/python/test_volume_bdpt.py (the lamp in a shade in fog, the fog room with a spot), for the
efficiency of medium vertices in the bidirectional integrators (docs/volumes.md). K seeds of
each; the per-pixel variance over seeds (pixels whose mean is > 1 % of the image mean, each
relative to a pooled mean of all integrators), the process CPU time per seed and the efficiency
1 / (mean relative pixel variance x CPU time), also relative to pt's. Not against Cycles (the
Cycles scenes' soft-falloff lights start no light paths). Run:

    nice python bench/volume_bdpt_noise.py --scenes lamp_shade fog_spot --spp 64 --seeds 8 \\
        --out bench/results/2026-12-04-volbdpt/noise.txt"""
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
import test_volume_bdpt as tb  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", nargs="+", default=["lamp_shade", "fog_spot"])
    ap.add_argument("--integrators", nargs="+", default=["pt", "bdpt", "lvc", "cis"])
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--depth", type=int, default=8)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    machine = (f"{platform.node()} {platform.processor() or platform.machine()}, "
               f"{os.cpu_count()} cores")
    lines = [f"# {' '.join(sys.argv)}", f"# machine: {machine}; threads 1; 32x32; "
             f"max_depth {args.depth}; {args.spp} spp x {args.seeds} seeds"]
    for name in args.scenes:
        runs = {}
        for integ in args.integrators:
            imgs, secs = [], []
            for k in range(args.seeds):
                s = lantern.Session(tb.ALL[name](), integrator=integ, backend="cpu", seed=1 + k,
                                    max_depth=args.depth, spp_per_iteration=args.spp, threads=1)
                t0 = time.process_time()
                s.step()
                secs.append(time.process_time() - t0)
                assert not any("rendering with pt" in w for w in s.warnings), s.warnings
                imgs.append(np.asarray(s.image())[..., :3].mean(axis=-1))
            runs[integ] = (np.stack(imgs), float(np.mean(secs)))
        pooled = np.mean([r[0].mean(0) for r in runs.values()], axis=0)
        mask = pooled > 0.01 * pooled.mean()
        eff_pt = None
        for integ, (a, sec) in runs.items():
            var = (a.var(0, ddof=1)[mask] / pooled[mask] ** 2).mean()
            mean_rel = a.mean() / pooled.mean() - 1.0
            eff = 1.0 / (var * sec)
            eff_pt = eff if integ == "pt" else eff_pt
            rel = f"{eff / eff_pt:.2f}x pt" if eff_pt else ""
            line = (f"{name:12s} {integ:5s} image mean {a.mean():.5f} ({mean_rel:+.2%} of pooled) "
                    f"rel. pixel var {var:.4g} cpu/seed {sec:.2f} s efficiency {eff:.4g} {rel}")
            print(line, flush=True)
            lines.append(line)
    with open(args.out, "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
