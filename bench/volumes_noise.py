"""Noise and time of Lantern (pt) on the volume scenes of tests/cycles/test_volumes.py, for
before/after measurements of a sampling change (docs/volumes.md): the scene is exported once,
rendered with K seeds, and the spread over seeds gives per-pixel variance. Reported: the
relative standard error of the image mean over one seed, the mean per-pixel relative standard
deviation (over pixels whose mean is > 1 % of the image mean), the process CPU time per seed
(and the wall time; the shared machine's load moves wall time by tens of percent) and the
efficiency 1 / (mean pixel variance x CPU time); with --cycles the same for Cycles (CPU, the tests'
settings) and the ratio of the two efficiencies. Run inside bpy's Python:

    nice python bench/volumes_noise.py --scenes fog_spot --spp 64 --seeds 8 \\
        --out bench/results/2026-12-04-volumes2/noise.txt"""
import argparse
import os
import platform
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if "--root" in sys.argv:  # another checkout's lantern and scenes (a "before" measurement)
    ROOT = os.path.abspath(sys.argv[sys.argv.index("--root") + 1])
sys.path.insert(0, os.path.join(ROOT, "python"))  # this checkout's lantern
sys.path.insert(0, os.path.join(ROOT, "tests", "cycles"))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import render_compare as rc  # noqa: E402
import test_volumes as tv  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", nargs="+", default=["fog_spot"])
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--label", default="")
    ap.add_argument("--root", default=ROOT, help="the checkout to measure (default: this one)")
    ap.add_argument("--cycles", action="store_true",
                    help="also Cycles (CPU, the tests' settings, the same threads), for the "
                         "efficiency ratio; its time per seed includes writing and reading an EXR")
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    import bpy
    import lantern
    rc.lantern_bpy.load_addon()
    from lantern_blender.export import export_scene
    machine = (f"{platform.node()} {platform.processor() or platform.machine()}, "
               f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}")
    for name in args.scenes:
        tv.SCENES[name]()
        scene, _ = export_scene(bpy.context.evaluated_depsgraph_get())
        imgs, secs = [], []
        for k in range(args.seeds):
            t0, c0 = time.perf_counter(), time.process_time()
            s = lantern.Session(scene, integrator="pt", backend="cpu",
                                max_depth=rc.lantern_depth(rc.BOUNCES), seed=1 + k,
                                spp_per_iteration=args.spp, threads=args.threads)
            while s.spp < args.spp:
                s.step()
            imgs.append(np.asarray(s.image(), dtype=np.float64)[..., :3])
            secs.append((time.perf_counter() - t0, time.process_time() - c0))
        line = _stats(name, f"Lantern pt {args.label}", np.stack(imgs), secs, args, machine)
        if args.cycles:
            bpy.context.scene.render.threads_mode = "FIXED"
            bpy.context.scene.render.threads = args.threads
            cimgs, csecs = [], []
            for k in range(args.seeds):
                t0, c0 = time.perf_counter(), time.process_time()
                cimgs.append(np.asarray(rc.render_cycles(seed=900 + k, spp=args.spp)[0],
                                        dtype=np.float64)[..., :3])
                csecs.append((time.perf_counter() - t0, time.process_time() - c0))
            cline = _stats(name, "Cycles", np.stack(cimgs), csecs, args, machine)
            lv, lt = line[1], line[2]
            cv, ct = cline[1], cline[2]
            ratio = (cv * ct) / (lv * lt)
            text = (f"{name}: efficiency Lantern pt {args.label} / Cycles = {ratio:.3g} "
                    f"(variance x process CPU time per seed, {args.spp} spp, {args.threads} "
                    f"thread(s); "
                    f"image means {line[3]:.5f} / {cline[3]:.5f})")
            print(text, flush=True)
            with open(args.out, "a") as f:
                f.write(text + "\n")


def _stats(name, who, imgs, secs, args, machine):
    """Writes one result line; returns (line, mean pixel variance, time per seed, image mean)."""
    mean = imgs.mean(axis=0)
    var = imgs.var(axis=0, ddof=1)
    lum_mean = mean.mean()
    rel_img = imgs.mean(axis=(1, 2, 3)).std(ddof=1) / lum_mean
    mask = mean > 0.01 * lum_mean
    rel_px = float(np.mean(np.sqrt(var[mask]) / mean[mask]))
    wall = float(np.median([w for w, _ in secs]))
    t = float(np.median([c for _, c in secs]))  # process CPU seconds: the load moves them less
    eff = 1.0 / (var.mean() * t)
    line = (f"{name} {who}: {args.seeds} seeds x {args.spp} spp, {args.threads} "
            f"thread(s); image mean {lum_mean:.5f}; rel. se of the image mean "
            f"{rel_img:.4f}; mean pixel rel. sd {rel_px:.4f}; mean pixel variance "
            f"{var.mean():.3e}; {t:.2f} CPU s ({wall:.2f} s wall) per seed; efficiency "
            f"1/(var CPU t) {eff:.4g}; "
            f"{machine}")
    print(line, flush=True)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, "a") as f:
        f.write(line + "\n")
    return line, float(var.mean()), t, float(lum_mean)


if __name__ == "__main__":
    main()
