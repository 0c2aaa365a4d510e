"""pt's image by path length on a fog scene of bench/automedia_cycles.py (issue 29, ptfog2):
renders at Lantern max_depth b + 2 for b = 0..B with the same seeds differ exactly by the paths
of b + 1 bounces (pt's random numbers of a path's first vertices do not depend on max_depth), so
image(b) - image(b - 1) is the contribution of length b alone, seed by seed; its mean and
per-pixel variance over the seeds say where pt's noise is. Cycles is rendered alike (max_bounces
b, transparent_max_bounces `--transparent`, 64 by default: Cycles counts the volume boundaries
its shadow rays cross against it, bench/softfog_pixels.py); its differences are not clean
(its sampler's use of the bounce limit makes some negative), so for Cycles only the cumulative
images are compared. Run inside bpy's Python:

    nice python bench/ptfog_lengths.py --scene lamp_shade_soft --spp 64 --seeds 8 --max-bounces 8 \\
        --out bench/results/2026-12-05-ptfog2/lengths.txt"""
import argparse
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "bench"))
import side_process  # noqa: E402
side_process.one_cpu()  # before bpy loads TBB (bench/side_process.py)
import volumes_vs_cycles as vs_cycles  # noqa: E402  (adds tests/cycles, tools)
import automedia_cycles as ac  # noqa: E402
import render_compare as rc  # noqa: E402
import softfog_pixels as sp  # noqa: E402

# the pixels around the bulb (the shade's inside through its opening) on the 32 x 32 image
BULB = [(4, 17), (4, 18), (5, 17), (5, 18), (5, 19), (6, 18)]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene", default="lamp_shade_soft", choices=list(ac.SCENES))
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--max-bounces", type=int, default=8)
    ap.add_argument("--transparent", type=int, default=64)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    import bpy
    import lantern
    rc.lantern_bpy.load_addon()
    from lantern_blender.export import export_scene

    emit = vs_cycles.emitter(args.out)
    emit(f"# {' '.join(sys.argv)}")
    emit(f"# {vs_cycles.machine()}; {args.scene}, {args.spp} spp x {args.seeds} seeds, 1 thread, "
         f"Cycles transparent_max_bounces {args.transparent}")
    vs_cycles.build_scene(ac.SCENES[args.scene], threads=1)
    scene, _ = export_scene(bpy.context.evaluated_depsgraph_get())
    prev = None
    for b in range(args.max_bounces + 1):
        lan, cyc, tl = [], [], []
        for k in range(args.seeds):
            c0 = time.process_time()
            s = lantern.Session(scene, integrator="pt", backend="cpu", max_depth=b + 2,
                                seed=1 + k, spp_per_iteration=args.spp, threads=1)
            s.step()
            lan.append(np.asarray(s.image(), np.float64)[..., :3].mean(axis=2))
            del s  # a live Session doubles Cycles' CPU time (bench/automedia_cycles.py)
            tl.append(time.process_time() - c0)
            c = sp.render_cycles_transparent(900 + k, args.spp, b, args.transparent)
            cyc.append(np.asarray(c, np.float64)[..., :3].mean(axis=2))
        lan, cyc = np.stack(lan), np.stack(cyc)
        part = lan if prev is None else lan - prev
        prev = lan
        v = part.var(axis=0, ddof=1)
        share = np.sort(v.ravel())[::-1][:5].sum() / v.sum()
        bulb = sum(v[p] for p in BULB) / v.sum()
        emit(f"length {b} (pt): mean {part.mean():.5f}, mean pixel variance {v.mean():.4e}, "
             f"median {np.median(v):.3e}, 5 noisiest pixels' share {share:.2f}, the bulb's 6 "
             f"pixels' share {bulb:.2f}; negative pixels {(part < -1e-6).mean():.4f} (0: exact)")
        vl, vc = lan.var(axis=0, ddof=1), cyc.var(axis=0, ddof=1)
        ml, mc = lan.mean(axis=(1, 2)), cyc.mean(axis=(1, 2))
        se = np.hypot(ml.std(ddof=1), mc.std(ddof=1)) / np.sqrt(args.seeds)
        emit(f"up to {b} bounces: mean pt {ml.mean():.5f} cycles {mc.mean():.5f} (z "
             f"{(ml.mean() - mc.mean()) / se:+.2f}); mean pixel variance pt {vl.mean():.4e} cycles "
             f"{vc.mean():.4e} (pt / cycles {vl.mean() / vc.mean():.2f}), median pixel variance "
             f"pt / cycles {np.median(vl) / np.median(vc):.2f}; pt CPU s per seed "
             f"{np.median(tl):.2f}")


if __name__ == "__main__":
    main()
