"""Render (or reuse) the converged reference of one benchmark scene, exactly as bench/rmse.py
makes and caches it (rmse_reference.get: K seeds, noise floor from their spread, cached in
bench/refs/), and copy it to a folder that can be committed: <scene>_<W>x<H>.npz (the cache
file's content: image and per-pixel standard error, float32, seeds, scene hash, ...; copied
back to refs/<scene>_<W>x<H>.npz it is reused), a PNG preview and a JSON line.

    nice -n 10 .venv/bin/python bench/make_reference.py blend:monkeybox --res 64x64 \\
        --integrator bdpt --spp 16384 --seeds 4 --threads 2 \\
        --out bench/results/2026-11-27-references

A later `bench/rmse.py --scenes blend:monkeybox --res 64x64 --ref-integrator bdpt --ref-spp
16384 --ref-seeds 4` (same scene hash, seeds, max depth) reuses the cached reference."""

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

BENCH = Path(__file__).resolve().parent
sys.path.insert(0, str(BENCH))

import bench_scenes  # noqa: E402
import rmse  # noqa: E402
import rmse_cycles  # noqa: E402
import rmse_reference  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", help="a bench/rmse.py scene name, e.g. blend:monkeybox")
    ap.add_argument("--res", required=True, help="WxH")
    ap.add_argument("--integrator", default="bdpt")
    ap.add_argument("--spp", type=int, required=True, help="total spp over all seeds")
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--refs", default=str(BENCH / "refs"))
    ap.add_argument("--rebuild", action="store_true")
    ap.add_argument("--out", help="copy the reference here (npz, png, json)")
    args = ap.parse_args(argv)
    width, height = (int(v) for v in args.res.lower().split("x"))

    lantern = rmse.import_lantern()
    lantern.session.require_core()
    import lantern.imageio
    if args.scene.startswith("blend:"):
        scene = rmse_cycles.build_blend(args.scene[6:], width, height)
    else:
        scene = bench_scenes.build(args.scene, width, height)
    load_before = os.getloadavg()
    progress = rmse.Progress(f"{args.scene}/ref")
    t0 = time.perf_counter()
    c0 = time.process_time()
    ref = rmse_reference.get(
        lantern, scene, args.scene,
        {"integrator": args.integrator, "spp": args.spp, "n_seeds": args.seeds,
         "threads": args.threads, "max_depth": lantern.session.DEFAULT_SETTINGS["max_depth"],
         "avoid_seeds": [0]},
        args.refs, args.rebuild,
        lambda done, total: progress.update(done / total, f"{done}/{total} spp"))
    progress.close()
    elapsed = time.perf_counter() - t0
    img = np.asarray(ref["image"], np.float64)
    meta = {
        "scene": args.scene, "width": width, "height": height,
        "integrator": ref["integrator"], "spp": int(ref["spp"]),
        "spp_per_seed": int(ref["spp_per_seed"]), "n_seeds": int(ref["n_seeds"]),
        "threads": int(ref.get("threads", args.threads)), "max_depth": int(ref["max_depth"]),
        "wall_s": round(float(ref["wall_s"]), 1), "rmse_floor": float(ref["rmse_floor"]),
        "rel_rmse_floor": float(ref["rel_rmse_floor"]), "image_mean": float(img.mean()),
        "image_mean_rgb": [float(v) for v in img.reshape(-1, 3).mean(0)],
        "image_mean_se": float(np.sqrt((np.asarray(ref["se"], np.float64) ** 2).sum())
                               / img.size),
        "scene_hash": ref["scene_hash"], "created": ref["created"], "cached": ref["cached"],
        "load_avg_before": [round(v, 2) for v in load_before],
        "load_avg_after": [round(v, 2) for v in os.getloadavg()],
        "cpu_per_wall": (None if ref["cached"] or elapsed <= 0
                         else round((time.process_time() - c0) / elapsed, 2)),
    }
    print(json.dumps(meta))
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        stem = f"{args.scene.replace('blend:', '')}_{width}x{height}"
        # the cache file's keys (a drop-in for refs/<scene>_<W>x<H>.npz) plus the metadata
        keep = {k: v for k, v in ref.items() if k not in ("path", "cached")}
        keep.update({k: v for k, v in meta.items() if not isinstance(v, list) and k != "cached"})
        np.savez_compressed(out / f"{stem}.npz", **keep)
        lantern.imageio.write_image(out / f"{stem}.png", ref["image"])
        (out / f"{stem}.json").write_text(json.dumps(meta, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
