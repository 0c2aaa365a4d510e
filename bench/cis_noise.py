"""Noise at equal spp of pt against the bidirectional integrators (issue 27: cis must be at most
pt's noise per sample), with the seeds' spread as its uncertainty, and where each one's time goes
(Session.stats). One thread, lantern.scenes builders, K independent seeds per integrator,
rendered interleaved (seed k of every integrator, then seed k + 1) so that a change in the
machine's load falls on all of them alike.

    PYTHONPATH=python .venv/bin/python bench/cis_noise.py --scenes cornell_box,room_area_point \\
        --integrators pt,cis,lvc --seeds 8 --spp 16 --res 32

An integrator is a name with optional settings: `cis:candidates=4:connections=2`.
noise = sqrt(mean over pixels of the per-pixel variance between seeds) / image mean (RGB
averaged: bench/efficiency_cycles.py's measure); `ratio` = noise / the first integrator's, with
a jackknife standard error over the seeds (each seed left out in turn, both integrators)."""

import argparse
import json
import math
import os
import sys
import time

import numpy as np


def parse_integrator(spec):
    name, *opts = spec.split(":")
    extra = {}
    for o in opts:
        k, v = o.split("=")
        try:
            extra[k] = int(v)
        except ValueError:
            try:
                extra[k] = float(v)
            except ValueError:
                extra[k] = v
    return name, extra


def noise_of(stack):
    """rms relative noise of K images (K, H, W, 3), its median-pixel variant and the mean."""
    lum = stack.mean(axis=3)
    mean = float(lum.mean())
    var = lum.var(axis=0, ddof=1)
    lit = lum.mean(axis=0) > 0
    med = float(np.median(var[lit])) if lit.any() else float("nan")
    return math.sqrt(float(var.mean())) / mean, math.sqrt(med) / mean, mean


def relative_noise(stack, floor=0.05):
    """sqrt(mean over pixels of variance / (pixel mean^2 + (floor x image mean)^2)): every
    pixel's noise relative to its own value (the auto integrator's pilot measure, 5 % floor)."""
    lum = stack.mean(axis=3)
    m = lum.mean(axis=0)
    f = floor * float(lum.mean())
    return math.sqrt(float((lum.var(axis=0, ddof=1) / (m * m + f * f)).mean()))


def jackknife_ratio(a, b):
    """noise(b) / noise(a) and its jackknife standard error over the K seeds (paired)."""
    k = a.shape[0]
    full = noise_of(b)[0] / noise_of(a)[0]
    reps = [noise_of(np.delete(b, j, 0))[0] / noise_of(np.delete(a, j, 0))[0] for j in range(k)]
    reps = np.array(reps)
    se = math.sqrt((k - 1) / k * float(((reps - reps.mean()) ** 2).sum()))
    return full, se


STAT_KEYS = ("time_light_pass", "time_camera_pass", "time_trace", "time_shade", "time_shadow",
             "time_sort", "time_cache", "time_splat", "time_generate", "time_film",
             "rays_camera", "rays_indirect", "rays_shadow", "rays_light", "rays_connection",
             "rays_light_tracing", "cache_vertices")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", default="cornell_box,room_area_point")
    ap.add_argument("--integrators", default="pt,cis")
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--res", type=int, default=32)
    ap.add_argument("--spi", type=int, default=0,
                    help="samples per iteration (steps = spp / spi; 0: one step of spp)")
    ap.add_argument("--max-depth", type=int, default=None, help="default: the Session's")
    ap.add_argument("--json", default=None, help="write the rows here")
    args = ap.parse_args(argv)
    import lantern
    import lantern.scenes
    rows = []
    for scene_name in args.scenes.split(","):
        if scene_name.startswith("file:"):  # a saved .lantern scene (bench/save_blend_scene.py)
            scene = lantern.load_scene(scene_name[5:])
            f = scene.film
            f["width"], f["height"] = args.res, max(1, round(f["height"] * args.res / f["width"]))
        else:
            scene = getattr(lantern.scenes, scene_name)(width=args.res, height=args.res)
        specs = args.integrators.split(",")
        images = {k: [] for k in specs}
        times = {k: [] for k in specs}
        stats = {k: [] for k in specs}
        for seed in range(args.seeds):
            for spec in specs:
                name, extra = parse_integrator(spec)
                if args.max_depth:
                    extra.setdefault("max_depth", args.max_depth)
                env = {k[4:]: str(v) for k, v in extra.items() if k.startswith("ENV_")}
                extra = {k: v for k, v in extra.items() if not k.startswith("ENV_")}
                os.environ.update(env)  # diagnostics builds only (ENV_NAME=value)
                spi = args.spi or args.spp
                sess = lantern.Session(scene, integrator=name, seed=1 + seed, threads=1,
                                       spp_per_iteration=spi, backend="cpu", **extra)
                t0 = time.perf_counter()
                for _ in range(max(1, args.spp // spi)):
                    sess.step()
                times[spec].append(time.perf_counter() - t0)
                images[spec].append(np.asarray(sess.image(), np.float64)[..., :3])
                for k in env:
                    del os.environ[k]
                st = sess.stats
                stats[spec].append({k: float(st[k]) for k in STAT_KEYS if k in st})
        base = np.stack(images[specs[0]])
        print(f"# {scene_name}: {args.res}x{args.res}, {args.spp} spp "
              f"({args.spi or args.spp} per iteration), {args.seeds} seeds, "
              f"load {os.getloadavg()[0]:.1f}")
        print("| integrator | noise rms | median px | per-pixel rel | mean | ratio to first | "
              "time (s) |")
        print("|---|---:|---:|---:|---:|---:|---:|")
        for spec in specs:
            stack = np.stack(images[spec])
            rms, med, mean = noise_of(stack)
            ratio, se = jackknife_ratio(base, stack)
            t = float(np.mean(times[spec]))
            rel = relative_noise(stack)
            print(f"| {spec} | {100 * rms:.2f}% | {100 * med:.2f}% | {100 * rel:.2f}% | {mean:.5f} | "
                  f"{ratio:.3f} +- {se:.3f} | {t:.3f} |")
            mean_stats = {k: float(np.mean([s[k] for s in stats[spec]])) for k in stats[spec][0]}
            rows.append({"scene": scene_name, "integrator": spec, "res": args.res,
                         "spp": args.spp, "seeds": args.seeds, "noise_rms": rms,
                         "noise_median": med, "noise_pixel_relative": rel, "mean": mean, "ratio": ratio, "ratio_se": se,
                         "time_s": t, "stats": mean_stats})
        sys.stdout.flush()
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
