"""Where pt's variance lies against Cycles' on the lamp in a shade in fog (issue 29, softfog):
per-pixel variance over K seeds at equal samples, for the whole image and for the pixels above
Cycles' image mean (the shade's inside and the fog around the bulb), at a few bounce limits
(Cycles max_bounces b, Lantern max_depth b + 2); and the image means there. Run inside bpy's
Python:

    nice python bench/softfog_pixels.py --spp 64 --seeds 8 --bounces 1 16 \\
        --out bench/results/2026-12-05-softfog/pixels.txt"""
import argparse
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "bench"))
import volumes_vs_cycles as vs_cycles  # noqa: E402  (adds tests/cycles, tools)
import automedia_cycles as ac  # noqa: E402
import render_compare as rc  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene", default="lamp_shade_soft10", choices=list(ac.SCENES))
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--bounces", type=int, nargs="+", default=[1, 16])
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    import bpy
    import lantern
    rc.lantern_bpy.load_addon()
    from lantern_blender.export import export_scene

    emit = vs_cycles.emitter(args.out)
    emit(f"# {' '.join(sys.argv)}")
    emit(f"# {vs_cycles.machine()}; {args.scene}, {args.spp} spp x {args.seeds} seeds, 1 thread")
    vs_cycles.build_scene(ac.SCENES[args.scene], threads=1)
    scene, _ = export_scene(bpy.context.evaluated_depsgraph_get())
    for b in args.bounces:
        rc.BOUNCES = b
        lan, cyc, tl, tc = [], [], [], []
        for k in range(args.seeds):
            c0 = time.process_time()
            s = lantern.Session(scene, integrator="pt", backend="cpu", max_depth=b + 2,
                                seed=1 + k, spp_per_iteration=args.spp, threads=1)
            s.step()
            lan.append(np.asarray(s.image(), np.float64)[..., :3].mean(axis=2))
            tl.append(time.process_time() - c0)
            c0 = time.process_time()
            cyc.append(np.asarray(rc.render_cycles(seed=900 + k, spp=args.spp)[0],
                                  np.float64)[..., :3].mean(axis=2))
            tc.append(time.process_time() - c0)
        lan, cyc = np.stack(lan), np.stack(cyc)
        vl, vc = lan.var(axis=0, ddof=1), cyc.var(axis=0, ddof=1)
        bright = cyc.mean(axis=0) > cyc.mean()
        for label, m in (("all", np.ones_like(bright)), ("bright", bright), ("rest", ~bright)):
            emit(f"bounces {b} {label} ({int(m.sum())} px): mean pt {lan.mean(axis=0)[m].mean():.4f}"
                 f" cycles {cyc.mean(axis=0)[m].mean():.4f}; variance pt {vl[m].mean():.4e} "
                 f"cycles {vc[m].mean():.4e} (pt / cycles {vl[m].mean() / vc[m].mean():.2f})")
        top = np.argsort(vl.ravel())[::-1][:6]
        emit(f"bounces {b} pt's top pixels (row, col: pt var / cycles var, means): " + "; ".join(
            f"({j // vl.shape[1]}, {j % vl.shape[1]}: {vl.ravel()[j]:.3g} / {vc.ravel()[j]:.3g},"
            f" {lan.mean(axis=0).ravel()[j]:.3g} / {cyc.mean(axis=0).ravel()[j]:.3g})"
            for j in top))
        emit(f"bounces {b} CPU s per seed: pt {np.median(tl):.2f}, cycles {np.median(tc):.2f}")


if __name__ == "__main__":
    main()
