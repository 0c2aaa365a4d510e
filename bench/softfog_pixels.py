"""Where pt's variance lies against Cycles' on the lamp in a shade in fog (issue 29, softfog):
per-pixel variance over K seeds at equal samples, for the whole image and for the pixels above
the image mean (the shade's inside and the fog around the bulb), at a few bounce limits
(Cycles max_bounces b, Lantern max_depth b + 2); and the image means there. Run inside bpy's
Python:

    nice python bench/softfog_pixels.py --spp 64 --seeds 8 --bounces 1 16 \\
        --out bench/results/2026-12-05-softfog/pixels.txt

Cycles' transparent_max_bounces is `--transparent` (default: b, render_compare's setting). It
limits the volume boundaries a shadow ray may cross (Cycles' integrate_shadow_max_transparent_hits:
transparent_max_bounce - transparent_bounce - 1; a volume-only mesh is a transparent hit there),
so at b = 1 every shadow ray that crosses the fog box's faces is blocked in Cycles, not in
Lantern (whose boundaries are never counted): compare at small b with --transparent 64
(bench/results/2026-12-05-ptfog2/). The split "bright" / "rest" is by the pooled mean of both
renderers (by Cycles' alone it selects pixels Cycles' noise made bright)."""
import argparse
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "bench"))
if __name__ == "__main__":
    # one CPU before bpy loads TBB: no idle TBB worker to spin through Cycles' one-thread
    # renders and bill them (bench/side_process.py, bench/results/2026-12-05-benchproc/)
    sys.path.insert(0, os.path.join(ROOT, "bench"))
    import side_process  # noqa: E402
    side_process.one_cpu()
import volumes_vs_cycles as vs_cycles  # noqa: E402  (adds tests/cycles, tools)
import automedia_cycles as ac  # noqa: E402
import render_compare as rc  # noqa: E402


def render_cycles_transparent(seed, spp, bounces, transparent):
    """Cycles as render_compare.render_cycles, transparent_max_bounces `transparent`."""
    import tempfile
    import bpy
    rc.cycles_settings(bpy.context.scene, seed, spp, bounces=bounces,
                       transparent_bounces=transparent)
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "cycles.exr")
        bpy.context.scene.render.filepath = path
        bpy.ops.render.render(write_still=True)
        return rc.lantern_bpy.read_image_bpy(path)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene", default="lamp_shade_soft10", choices=list(ac.SCENES))
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--bounces", type=int, nargs="+", default=[1, 16])
    ap.add_argument("--transparent", type=int, default=None,
                    help="Cycles transparent_max_bounces (default: the bounces)")
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    import bpy
    import lantern
    rc.lantern_bpy.load_addon()
    from lantern_blender.export import export_scene

    emit = vs_cycles.emitter(args.out)
    emit(f"# {' '.join(sys.argv)}")
    emit(f"# {vs_cycles.machine()}; {args.scene}, {args.spp} spp x {args.seeds} seeds, 1 thread, "
         f"Cycles transparent_max_bounces {args.transparent or 'b'}")
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
            del s  # a live Session doubles Cycles' CPU time (bench/automedia_cycles.py)
            tl.append(time.process_time() - c0)
            c0 = time.process_time()
            if args.transparent is None:
                c = rc.render_cycles(seed=900 + k, spp=args.spp)[0]
            else:
                c = render_cycles_transparent(900 + k, args.spp, b, args.transparent)
            cyc.append(np.asarray(c, np.float64)[..., :3].mean(axis=2))
            tc.append(time.process_time() - c0)
        lan, cyc = np.stack(lan), np.stack(cyc)
        vl, vc = lan.var(axis=0, ddof=1), cyc.var(axis=0, ddof=1)
        pooled = (lan.mean(axis=0) + cyc.mean(axis=0)) / 2
        bright = pooled > pooled.mean()
        for label, m in (("all", np.ones_like(bright)), ("bright", bright), ("rest", ~bright)):
            ml, mc = lan[:, m].mean(axis=1), cyc[:, m].mean(axis=1)  # per seed
            se = np.hypot(ml.std(ddof=1), mc.std(ddof=1)) / np.sqrt(args.seeds)
            emit(f"bounces {b} {label} ({int(m.sum())} px): mean pt {ml.mean():.4f}"
                 f" cycles {mc.mean():.4f} (z {(ml.mean() - mc.mean()) / se:+.2f}); "
                 f"variance pt {vl[m].mean():.4e} "
                 f"cycles {vc[m].mean():.4e} (pt / cycles {vl[m].mean() / vc[m].mean():.2f})")
        top = np.argsort(vl.ravel())[::-1][:6]
        emit(f"bounces {b} pt's top pixels (row, col: pt var / cycles var, means): " + "; ".join(
            f"({j // vl.shape[1]}, {j % vl.shape[1]}: {vl.ravel()[j]:.3g} / {vc.ravel()[j]:.3g},"
            f" {lan.mean(axis=0).ravel()[j]:.3g} / {cyc.mean(axis=0).ravel()[j]:.3g})"
            for j in top))
        emit(f"bounces {b} CPU s per seed: pt {np.median(tl):.2f}, cycles {np.median(tc):.2f}")


if __name__ == "__main__":
    main()
