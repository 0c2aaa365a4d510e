"""Variance per sample, integrator against integrator, on one scene: K seeds x S spp each,
per-pixel variance of the mean over seeds (luminance-free: mean of RGB), summed over the image
and per 8x8 block. Separates "fewer samples per second" from "noisier per sample" in a
speed-against-error result (bench/rmse.py measures only their product).

    .venv/bin/python bench/variance_per_sample.py blend:monkeybox --res 64 --integrators pt,bdpt,lvc,cis
    .venv/bin/python bench/variance_per_sample.py fixture_box      (a lantern.scenes builder)
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

BENCH = Path(__file__).resolve().parent
sys.path.insert(0, str(BENCH))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", help="blend:<builder>, a lantern.scenes builder, or a .lantern file")
    ap.add_argument("--res", type=int, default=64)
    ap.add_argument("--integrators", default="pt,bdpt,lvc,cis")
    ap.add_argument("--seeds", type=int, default=6)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--max-depth", type=int, default=12)
    args = ap.parse_args(argv)
    import lantern
    import lantern.scenes
    if args.scene.startswith("blend:"):
        import rmse_cycles
        scene = rmse_cycles.build_blend(args.scene[6:], args.res, args.res)
    elif args.scene.endswith(".lantern"):
        scene = lantern.load_scene(args.scene)
    else:
        scene = getattr(lantern.scenes, args.scene)(width=args.res, height=args.res)
    base = None
    for integ in args.integrators.split(","):
        imgs, t = [], 0.0
        for seed in range(args.seeds):
            s = lantern.Session(scene, integrator=integ, seed=seed, spp_per_iteration=args.spp,
                                max_depth=args.max_depth)
            t0 = time.perf_counter()
            s.step()
            t += time.perf_counter() - t0
            imgs.append(np.asarray(s.image()).mean(axis=2))
        imgs = np.stack(imgs)
        var = imgs.var(axis=0, ddof=1).mean()
        per_spp_s = t / (args.seeds * args.spp)
        if base is None:
            base = (var, per_spp_s)
        print(f"{integ:6s} image mean {imgs.mean():.4f}  variance per pixel at {args.spp} spp "
              f"{var:.4g} ({var / base[0]:.2f}x {args.integrators.split(',')[0]})  "
              f"time per spp {1e3 * per_spp_s:.1f} ms ({per_spp_s / base[1]:.2f}x)  "
              f"efficiency 1/(var t) {base[0] * base[1] / (var * per_spp_s):.2f}x", flush=True)


if __name__ == "__main__":
    sys.exit(main())
