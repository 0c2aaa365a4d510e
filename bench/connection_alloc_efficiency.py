"""Per-pixel connection counts (issue 27 item 2, connection_allocation; native/src/integrator/
pixel_alloc.h) against cis with one N everywhere, pt and auto: per-pixel efficiency
1 / (noise^2 x cost), one thread, K seeds, on the scenes of lantern.scenes.

noise = mean over pixels of the spread (sample standard deviation) of the luminance between
seeds, over the image's mean luminance (bench/auto_efficiency.py's); cost = CPU seconds of one
render (process time, median over seeds) and, undisturbed by the machine's load, `work`: rays
traced plus 0.36 of a ray per cis candidate actually evaluated (the `cis_candidates` counter:
M of each camera vertex's pixel). Variants rendered interleaved (seed k of each in turn).

    .venv/bin/python bench/connection_alloc_efficiency.py --res 64x64 --spp 64 --seeds 4 \\
        --out bench/results/2026-12-04-auto5
"""
import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
VARIANTS = {  # name -> (integrator, settings)
    "pt": ("pt", {}),
    "cis": ("cis", {"connection_allocation": False}),
    "cis_alloc": ("cis", {"connection_allocation": True}),
    "lvc": ("lvc", {"connection_allocation": False}),
    "lvc_alloc": ("lvc", {"connection_allocation": True}),
    "auto": ("auto", {"connection_allocation": False}),
    "auto_alloc": ("auto", {"connection_allocation": True}),
}


def render_one(scene, variant, seed, args):
    import lantern
    integ, extra = VARIANTS[variant]
    s = lantern.Session(scene, integrator=integ, seed=seed, backend="cpu", threads=1,
                        max_depth=args.max_depth, spp_per_iteration=1, **extra)
    c0 = time.process_time()
    for _ in range(args.spp):
        s.step()
    return s.image(), time.process_time() - c0, s.stats


def summarise(scene_name, variant, runs):
    imgs = [r[0] for r in runs]
    times = [r[1] for r in runs]
    work, conn = [], []
    for _, _, st in runs:
        cand = st.get("cis_candidates", 0)
        if variant.startswith("auto"):  # its cis iterations' candidates (the counter counts them)
            cand = st.get("cis_candidates", 10 * st.get("auto_cis_vertices", 0))
        work.append(st["rays_total"] + 0.36 * cand)
        conn.append(st.get("mean_connections", -1.0))
    lum = np.einsum("kyxc,c->kyx", np.asarray(imgs, dtype=np.float64), [0.2126, 0.7152, 0.0722])
    mean = lum.mean()
    noise = float(lum.std(axis=0, ddof=1).mean() / mean)
    t = float(np.median(times))
    c = float(np.median(work))
    return {"scene": scene_name, "variant": variant, "mean": float(mean), "noise": noise,
            "time_s": t, "work": c, "efficiency": 1.0 / (noise * noise * t),
            "efficiency_work": 1.0 / (noise * noise * c), "mean_connections": conn,
            "auto": [st.get("auto_choice") for _, _, st in runs]}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default="all")
    ap.add_argument("--variants", default="pt,cis,cis_alloc,auto")
    ap.add_argument("--res", default="64x64")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--max-depth", type=int, default=12)
    ap.add_argument("--out", default="")
    args = ap.parse_args()
    from auto_efficiency import build_scene
    from light_tree_noise import machine
    variants = args.variants.split(",")
    info = {"before": machine()}
    rows = []
    if args.scenes == "all":  # every scene of bench/auto_efficiency.py
        from auto_efficiency import SCENES
        args.scenes = ",".join(SCENES)
    for name in args.scenes.split(","):
        scene = build_scene(name, args)
        runs = {v: [] for v in variants}
        for k in range(args.seeds):
            for v in variants:
                runs[v].append(render_one(scene, v, 1000 + k, args))
        for v in variants:
            r = summarise(name, v, runs[v])
            rows.append(r)
            print(json.dumps(r), flush=True)
    info["after"] = machine()
    info["settings"] = vars(args)
    head = ("| scene | " + " | ".join(f"{v} noise, time (s), work" for v in variants) + " | " +
            " | ".join(f"{v} / pt (time, work)" for v in variants if v != "pt") +
            " | " + " | ".join(f"{v}_alloc / {v} (time, work)" for v in variants
                               if v + "_alloc" in variants) + " | cis_alloc mean N |")
    lines = [head, "|---" * (head.count("|") - 1) + "|"]
    for name in args.scenes.split(","):
        by = {r["variant"]: r for r in rows if r["scene"] == name}
        cells = [f"{100 * by[v]['noise']:.2f} %, {by[v]['time_s']:.2f}, {by[v]['work']:.3g}"
                 for v in variants]
        rel = [f"{by[v]['efficiency'] / by['pt']['efficiency']:.2f}, "
               f"{by[v]['efficiency_work'] / by['pt']['efficiency_work']:.2f}"
               for v in variants if v != "pt"]
        ac = " | ".join(f"{by[v + '_alloc']['efficiency'] / by[v]['efficiency']:.2f}, "
                        f"{by[v + '_alloc']['efficiency_work'] / by[v]['efficiency_work']:.2f}"
                        for v in variants if v + "_alloc" in variants)
        n = by.get("cis_alloc", {}).get("mean_connections", [])
        lines.append(f"| {name} | " + " | ".join(cells) + " | " + " | ".join(rel) +
                     f" | {ac} | {', '.join(f'{x:.2f}' for x in n)} |")
    table = "\n".join(lines)
    print(table)
    if args.out:
        os.makedirs(args.out, exist_ok=True)
        with open(os.path.join(args.out, "connection_alloc.json"), "w") as f:
            json.dump({"machine": info, "rows": rows}, f, indent=1)
        with open(os.path.join(args.out, "table.md"), "w") as f:
            f.write(table + "\n")


if __name__ == "__main__":
    main()
