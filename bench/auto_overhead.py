"""What integrator "auto" costs where it keeps path tracing (docs/auto_integrator.md): on the
CPU, an auto render that chooses pt at every checkpoint returns pt's image bit for bit, so
there its efficiency against pt is pt's time over auto's, with no noise estimate needed (the
efficiency table's +-30 % from 6 seeds does not apply). Renders alternate (pt, auto) per seed,
one thread, one sample an iteration as the add-on's final render; CPU time per render.

    .venv/bin/python bench/auto_overhead.py --scenes cornell_box,room_area_point \\
        --res 64,128 --spp 64 --seeds 8

Per seed: auto's time over pt's, whether the images are the same bits, and auto's iterations
in each integrator (a seed whose pilot chose cis for a while renders other bits, at cis's cost).
"""
import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python"))
import lantern  # noqa: E402
from lantern import scenes  # noqa: E402


def render(scene, integrator, seed, spp):
    t0 = time.process_time()
    s = lantern.Session(scene, integrator=integrator, seed=seed, spp_per_iteration=1, threads=1,
                        backend="cpu")
    for _ in range(spp):
        s.step()
    return np.asarray(s.image()), time.process_time() - t0, s.stats


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", default="cornell_box,room_area_point")
    ap.add_argument("--res", default="64,128")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seeds", type=int, default=8)
    a = ap.parse_args()
    for name in a.scenes.split(","):
        for res in (int(r) for r in a.res.split(",")):
            scene = getattr(scenes, name)(res, res)
            t_pt, t_auto, rows = [], [], []
            for k in range(a.seeds):
                img_pt, tp, _ = render(scene, "pt", 100 + k, a.spp)
                img_auto, ta, st = render(scene, "auto", 100 + k, a.spp)
                t_pt.append(tp)
                t_auto.append(ta)
                rows.append(f"{ta / tp:.3f}{'=' if np.array_equal(img_pt, img_auto) else '*'}"
                            f"(cis {st['auto_cis_iterations']})")
            ratio = sum(t_auto) / sum(t_pt)
            print(f"{name} {res}x{res} {a.spp} spp, {a.seeds} seeds: pt {np.mean(t_pt):.3f} s, "
                  f"auto {np.mean(t_auto):.3f} s a render; auto / pt time {ratio:.3f} "
                  f"(efficiency {1 / ratio:.3f} where the bits are pt's); per seed "
                  + " ".join(rows), flush=True)


if __name__ == "__main__":
    main()
