"""pt's noise on Blender's default bulb (a soft-falloff point light of radius 0.1 m) in world fog
in the Cornell box, for an A/B of two builds (softfog: the disk sampled by solid angle against
by area): run once per checkout, LANTERN_PY naming the checkout's python folder:

    LANTERN_PY=/path/to/base/python python bench/soft_disk_ab.py --out results.txt
    LANTERN_PY=$PWD/python python bench/soft_disk_ab.py --out results.txt

32 x 32, K seeds x spp, max_depth 8, one thread; the image mean with its standard error from
the seeds, the mean pixel variance, the share of the 5 noisiest pixels, CPU s per seed."""
import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.environ.get("LANTERN_PY", os.path.join(os.path.dirname(
    os.path.dirname(os.path.abspath(__file__))), "python")))
import lantern  # noqa: E402
from lantern import scenes  # noqa: E402


def bulb_in_fog():
    s = scenes.cornell_box(32, 32)
    s.lights = []
    s.add_light("point", position=[0.0, 0.0, 1.0], power=[60.0] * 3, radius=0.1,
                soft_falloff=True)
    s.world["volume"] = {"sigma_s": [0.4] * 3, "sigma_a": [0.02, 0.03, 0.04]}
    return s


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=16)
    ap.add_argument("--spp", type=int, default=32)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    ims, t = [], time.process_time()
    for k in range(args.seeds):
        s = lantern.Session(bulb_in_fog(), integrator="pt", seed=1 + k, backend="cpu",
                            max_depth=8, spp_per_iteration=args.spp, threads=1)
        s.step()
        ims.append(np.asarray(s.image(), np.float64)[..., :3])
    ims = np.stack(ims)
    m = ims.mean(axis=(1, 2, 3))
    v = ims.var(axis=0, ddof=1).mean(axis=2)
    top = np.sort(v.ravel())[::-1]
    line = (f"{lantern.__file__}: load {os.getloadavg()[0]:.1f}; {args.seeds} seeds x "
            f"{args.spp} spp: image mean {m.mean():.5f} +- {m.std(ddof=1) / np.sqrt(len(m)):.5f}; "
            f"mean pixel variance {v.mean():.4e}; 5 noisiest pixels' share "
            f"{top[:5].sum() / v.sum():.3f}; CPU s per seed "
            f"{(time.process_time() - t) / args.seeds:.2f}")
    print(line)
    with open(args.out, "a") as f:
        f.write(line + "\n")


if __name__ == "__main__":
    main()
