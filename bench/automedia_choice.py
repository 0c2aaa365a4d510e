"""The efficiencies behind tests/python/test_auto_media.py's choices: pt, cis and auto on its
media scenes (the lamp in a shade in fog, the open fog stage under a sun, the fog room with a
spot; 32x32, max_depth 8), K seeds each, one thread. Efficiency = 1 / (mean pixel variance over
seeds x process CPU seconds per seed), relative to pt's, and by auto's own measure (the mean
pixel's standard deviation of the luminance, squared, in place of the mean variance); auto's
choices and its own estimate of cis over pt per seed. Run:

    nice python bench/automedia_choice.py --spp 64 --seeds 8 --spp-per-iteration 1 \\
        --out bench/results/2026-12-04-automedia/choice.txt"""
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
import test_auto_media as tam  # noqa: E402

SCENES = {"lamp_shade": tam.lamp_shade, "open_fog": tam.open_fog, "fog_spot": tam.fog_spot}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", nargs="+", default=list(SCENES))
    ap.add_argument("--integrators", nargs="+", default=["pt", "cis", "auto"])
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--spp-per-iteration", type=int, default=8)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--depth", type=int, default=tam.DEPTH)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)

    def emit(line):
        print(line, flush=True)
        with open(args.out, "a") as f:
            f.write(line + "\n")

    emit(f"# {' '.join(sys.argv)}")
    emit(f"# machine: {platform.node()} {platform.machine()}, {os.cpu_count()} cores, load "
         f"{os.getloadavg()[0]:.1f}; 1 thread; 32x32; max_depth {args.depth}; {args.spp} spp "
         f"x {args.seeds} seeds, spp_per_iteration {args.spp_per_iteration}")
    for name in args.scenes:
        eff = {}
        for integ in args.integrators:
            imgs, secs, chose = [], [], []
            for k in range(args.seeds):
                c0 = time.process_time()
                # "auto_media": integrator auto with its choice in media on (off by default)
                s = lantern.Session(SCENES[name](), integrator=integ.split("_")[0],
                                    auto_media=integ == "auto_media", backend="cpu", seed=1 + k,
                                    max_depth=args.depth,
                                    spp_per_iteration=args.spp_per_iteration, threads=1)
                while s.spp < args.spp:
                    s.step()
                secs.append(time.process_time() - c0)
                imgs.append(np.asarray(s.image(), dtype=np.float64)[..., :3])
                if integ.startswith("auto"):
                    chose.append(f"{s.stats['auto_choice']}({s.stats['auto_cis_over_pt']:.2f})")
            imgs = np.stack(imgs)
            var = float(imgs.var(axis=0, ddof=1).mean())
            # auto's own measure (allocation.cpp estimate()): the mean over pixels of the
            # luminance's standard deviation, squared
            lum = imgs @ np.array([0.2126, 0.7152, 0.0722])
            sd = float(lum.std(axis=0, ddof=1).mean())
            t = float(np.median(secs))
            eff[integ] = (1.0 / (var * t), 1.0 / (sd * sd * t))
            rel = [eff[integ][j] / eff["pt"][j] if "pt" in eff else float("nan")
                   for j in (0, 1)]
            emit(f"{name:11s} {integ:5s} image mean {imgs.mean():.5f} mean pixel variance "
                 f"{var:.4e} cpu/seed {t:.2f} s efficiency {eff[integ][0]:.4g} {rel[0]:.2f}x "
                 f"pt; by auto's measure (mean pixel sd {sd:.4e}) {rel[1]:.2f}x pt"
                 + (f"; auto chose {' '.join(chose)}" if chose else ""))


if __name__ == "__main__":
    main()
