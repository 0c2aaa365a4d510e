"""Per-pixel adaptive sampling, Lantern beside Cycles at the same noise threshold (issue 17):
equal-time error with and without it, one thread each.

Per engine, K seeds of each mode: "full" (every pixel to --spp) and "adaptive" (Cycles' noise
threshold --threshold, its automatic min samples, at most --spp), rendered interleaved so a
change in the machine's load falls on all alike. Each engine is scored against its own
converged image (Cycles at --ref-spp; Lantern pt at --ref-spp, both over 4 seeds), so a
translation difference does not count as noise. Per mode: RMSE (mean over seeds), the median
lit pixel's relative RMS error over the seeds (the typical pixel, where RMSE weighs the
noisiest regions), wall time of
a render (Cycles: `bpy.ops.render.render` with persistent data after a warm-up; Lantern: the
steps, the BVH built before), efficiency 1 / (RMSE^2 x time), and for Lantern the mean samples
a pixel took. The gain is adaptive's efficiency over full's, per engine.

    .venv/bin/python bench/adaptive_cycles.py [--scene light_area_square] [--spp 256] \\
        [--threshold 0.01] [--seeds 4] [--res 48] [--ref-spp 4096] [--out DIR]"""

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

BENCH = Path(__file__).resolve().parent
ROOT = BENCH.parent
sys.path.insert(0, str(BENCH))


def cycles_render(rmse_cycles, seed, spp, threshold=0.0, threads=1):
    """Cycles with the comparison settings; adaptive sampling on when threshold > 0 (its
    automatic min samples, as Lantern's default). (image, seconds)."""
    if threshold <= 0:
        return rmse_cycles.render(seed, spp, threads)
    import os
    import tempfile

    import bpy
    sys.path.insert(0, str(ROOT / "tools"))
    import lantern_bpy
    scene = bpy.context.scene
    rmse_cycles._settings(scene, seed, spp, threads)  # render() would set these again
    scene.cycles.use_adaptive_sampling = True
    scene.cycles.adaptive_threshold = threshold
    scene.cycles.adaptive_min_samples = 0
    with tempfile.TemporaryDirectory() as tmp:
        scene.render.filepath = os.path.join(tmp, "cycles.exr")
        t = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        seconds = time.perf_counter() - t
        img = lantern_bpy.read_image_bpy(scene.render.filepath)
    return np.asarray(img, np.float32)[..., :3], seconds


def lantern_render(lantern, lscene, seed, spp, depth, threshold=0.0, threads=1):
    """(image, seconds of the steps, mean samples a pixel)."""
    settings = {"adaptive_threshold": threshold} if threshold > 0 else {}
    s = lantern.Session(lscene, integrator="pt", seed=seed, threads=threads, max_depth=depth,
                        backend="cpu", **settings)
    t0 = time.perf_counter()
    while s.spp < spp and not s.converged:
        s.step()
    seconds = time.perf_counter() - t0
    return np.asarray(s.image(), np.float64)[..., :3], seconds, float(s.pixel_samples().mean())


def rmse(img, ref):
    return float(np.sqrt(np.mean((img - ref) ** 2)))


def median_rel(imgs, ref):
    """Median over the lit pixels of each pixel's RMS error over the seeds, relative to it:
    the typical pixel's noise, where RMSE is the noisiest regions'."""
    lum = ref.mean(axis=2)
    lit = lum > 1e-3
    err = np.sqrt(np.mean([(im - ref).mean(axis=2) ** 2 for im in imgs], axis=0))
    return float(np.median(err[lit] / lum[lit]))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", default="light_area_square")
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--threshold", type=float, default=0.01)
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--res", type=int, default=48)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--out", default=None, help="folder for results.json and table.md")
    args = ap.parse_args(argv)
    import rmse_cycles
    from light_tree_noise import machine
    from rmse import import_lantern
    lantern = import_lantern()
    print(f"lantern from {lantern.__file__}")
    lscene = rmse_cycles.build_blend(args.scene, args.res, args.res)
    depth = rmse_cycles.BOUNCES + 2
    rmse_cycles.render(1, 1, threads=1)  # warm-up: synchronise the scene once
    t0 = time.perf_counter()
    per = max(1, args.ref_spp // 4)
    ref_c = np.mean([rmse_cycles.render(900 + k, per)[0] for k in range(4)], axis=0)
    ref_l = np.mean([lantern_render(lantern, lscene, 900 + k, per, depth, threads=0)[0]
                     for k in range(4)], axis=0)
    print(f"references ({per * 4} spp each): {time.perf_counter() - t0:.0f} s; image means "
          f"Cycles {ref_c.mean():.4f}, Lantern {ref_l.mean():.4f}", flush=True)
    runs = {(e, m): [] for e in ("cycles", "lantern") for m in ("full", "adaptive")}
    images = {k: [] for k in runs}
    for k in range(args.seeds):
        for mode, thr in (("full", 0.0), ("adaptive", args.threshold)):
            img, sec = cycles_render(rmse_cycles, 101 + k, args.spp, thr)
            runs[("cycles", mode)].append((rmse(img, ref_c), sec, float("nan")))
            images[("cycles", mode)].append(img)
            img, sec, mean_spp = lantern_render(lantern, lscene, 1 + k, args.spp, depth, thr)
            runs[("lantern", mode)].append((rmse(img, ref_l), sec, mean_spp))
            images[("lantern", mode)].append(img)
        print(f"seed {k}: " + ", ".join(f"{e} {m} {v[-1][0]:.5f}/{v[-1][1]:.2f}s"
                                        for (e, m), v in runs.items()), flush=True)
    rows = []
    for (engine, mode), v in runs.items():
        a = np.array(v)
        err, sec = float(a[:, 0].mean()), float(a[:, 1].mean())
        rows.append({"engine": engine, "mode": mode, "rmse": err,
                     "rmse_se": float(a[:, 0].std(ddof=1) / math.sqrt(len(a))),
                     "time_s": sec, "efficiency": 1.0 / (err * err * sec),
                     "median_pixel_rel_err": median_rel(images[(engine, mode)],
                                                        ref_c if engine == "cycles" else ref_l),
                     "mean_spp": float(np.nanmean(a[:, 2])) if engine == "lantern" else None})
    eff = {(r["engine"], r["mode"]): r["efficiency"] for r in rows}
    lines = [f"# Adaptive sampling, Lantern pt beside Cycles: {args.scene}, {args.res} x "
             f"{args.res}, at most {args.spp} spp, threshold {args.threshold:g}, "
             f"{args.seeds} seeds, 1 thread", "",
             "| engine | mode | RMSE | median pixel rel. error | time (s) | mean spp | "
             "efficiency 1/(RMSE² t) | gain |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        gain = r["efficiency"] / eff[(r["engine"], "full")]
        spp = f"{r['mean_spp']:.1f}" if r["mean_spp"] is not None else "-"
        lines.append(f"| {r['engine']} | {r['mode']} | {r['rmse']:.5f} ± {r['rmse_se']:.5f} | "
                     f"{r['median_pixel_rel_err']:.4f} | {r['time_s']:.2f} | {spp} | "
                     f"{r['efficiency']:.4g} | {gain:.2f}x |")
    text = "\n".join(lines)
    print(text)
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "results.json").write_text(json.dumps(
            {"machine": machine(), "args": vars(args), "rows": rows}, indent=1))
        (out / "table.md").write_text(text + "\n")


if __name__ == "__main__":
    main()
