"""CPU time per seed of Cycles and pt rendered alternately in one bpy process (ptfog2): per
seed Cycles (render_compare.render_cycles, 1 thread) then pt (lantern.Session, 1 thread,
spp_per_iteration 1, max_depth 18), process CPU and wall seconds each. Written to find why
bench/automedia_cycles.py (all of pt's seeds, then all of Cycles') read Cycles' CPU time at
5.8-10 s for 256 spp where this read 5.0: a Lantern Session alive while Cycles renders doubles
Cycles' process CPU time on the 2-core VM (9.6 against 4.4 s; the last seed's Session was alive
there, the previous seed's here). --drop-session deletes each Session before the next Cycles
render. Run inside bpy's Python:

    nice python bench/alternate_timing.py --scene lamp_shade_soft --spp 64 256 --seeds 4 \\
        --out bench/results/2026-12-05-ptfog2/timing.txt"""
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
    ap.add_argument("--scene", default="lamp_shade_soft", choices=list(ac.SCENES))
    ap.add_argument("--spp", type=int, nargs="+", default=[64, 256])
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--order", choices=["alternate", "blocks"], default="alternate",
                    help="blocks: all pt seeds, then all Cycles seeds (bench/automedia_cycles.py)")
    ap.add_argument("--drop-session", action="store_true",
                    help="delete each Lantern Session before the next Cycles render (without: "
                         "the previous seed's Session is alive while Cycles renders)")
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    import bpy
    import lantern
    rc.lantern_bpy.load_addon()
    from lantern_blender.export import export_scene

    emit = vs_cycles.emitter(args.out)
    emit(f"# {' '.join(sys.argv)}")
    emit(f"# {vs_cycles.machine()}; {args.scene}, 1 thread each, order {args.order}, "
         f"drop_session {args.drop_session}")
    vs_cycles.build_scene(ac.SCENES[args.scene], threads=1)
    scene, _ = export_scene(bpy.context.evaluated_depsgraph_get())
    live = []  # the Lantern Session kept alive (none with --drop-session)
    for spp in args.spp:
        tc, tl = [], []

        def cycles(k):
            c0, w0 = time.process_time(), time.perf_counter()
            rc.render_cycles(seed=900 + k, spp=spp)
            tc.append(time.process_time() - c0)
            return f"cycles CPU {tc[-1]:.2f} s (wall {time.perf_counter() - w0:.2f})"

        def pt(k):
            live.clear()  # the previous seed's Session dies here
            c0, w0 = time.process_time(), time.perf_counter()
            s = lantern.Session(scene, integrator="pt", backend="cpu", max_depth=18, seed=1 + k,
                                spp_per_iteration=1, threads=1)
            while s.spp < spp:
                s.step()
            tl.append(time.process_time() - c0)
            if not args.drop_session:
                live.append(s)
            return f"pt CPU {tl[-1]:.2f} s (wall {time.perf_counter() - w0:.2f})"

        for k in range(args.seeds):
            first = cycles(k) + "; " if args.order == "alternate" else ""
            emit(f"spp {spp} seed {k}: {first}{pt(k)}; load {os.getloadavg()[0]:.1f}")
        if args.order == "blocks":  # the last pt seed's Session alive, as automedia_cycles had it
            for k in range(args.seeds):
                emit(f"spp {spp} seed {k}: {cycles(k)}; load {os.getloadavg()[0]:.1f}")
        emit(f"spp {spp}: median CPU s per seed cycles {np.median(tc):.2f}, pt {np.median(tl):.2f} "
             f"(pt / cycles {np.median(tl) / np.median(tc):.2f})")

if __name__ == "__main__":
    main()
