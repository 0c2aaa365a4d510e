"""Integrator "auto" against pt and cis (issue 27): per-pixel efficiency 1 / (noise^2 x time),
one thread, K seeds, on the scenes of lantern.scenes (no Blender needed).

noise = mean over pixels of the spread (sample standard deviation) of the luminance between
seeds, over the image's mean luminance; time = CPU seconds of one render (process time, which
a loaded machine disturbs less than wall time), median over seeds; the integrators' renders
interleaved (seed k of each in turn). Also a deterministic cost
(`work`: rays traced plus 0.36 of a ray per cis candidate, M = 10 per camera vertex of cis,
allocation.h's count), and the efficiency by it, which no machine load disturbs. A render is `--spp`
iterations of one sample each (as the add-on's final render), so auto's pilot (pt, pt, cis)
is inside the measured time and noise. Also printed: what auto chose and its own estimate of
cis's efficiency over pt's.

    .venv/bin/python bench/auto_efficiency.py --res 64x64 --spp 64 --seeds 6 \\
        --out bench/results/2026-12-04-auto

A scene may also be `file:PATH`, a .lantern file rendered at --res (the Bedroom: tools/
export_bench_scenes.py bedroom, then --scenes file:build/bench_scenes/bedroom.lantern --res 99x54).
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
SCENES = {  # name -> (lantern.scenes builder, keyword arguments)
    "cornell": ("cornell_box", {}),
    "room_area_point": ("room_area_point", {}),
    "room_spot_sun_world": ("room_spot_sun_world", {}),
    "many_lights": ("many_lights_stage", {"n": 24, "panel": True}),
    "fixture": ("fixture_box", {}),
    "glass_lantern": ("glass_lantern", {}),
    "glossy": ("glossy_box", {}),
    "principled": ("principled_box", {}),
}


_FILES = {}


def build_scene(scene_name, args):
    """A scene of SCENES at --res, or `file:PATH` (a .lantern file, e.g. the Bedroom exported by
    tools/export_bench_scenes.py) with its film set to --res (keep the file's aspect ratio: the
    camera's screen window is the file's)."""
    import lantern
    from lantern import scenes
    w, h = (int(v) for v in args.res.split("x"))
    if scene_name.startswith("file:"):
        if scene_name not in _FILES:
            _FILES[scene_name] = lantern.load_scene(scene_name[5:])
        scene = _FILES[scene_name]
        scene.film["width"], scene.film["height"] = w, h
        return scene
    builder, kw = SCENES[scene_name]
    return getattr(scenes, builder)(w, h, **kw)


def render_one(scene, integrator, seed, args):
    """One render of --spp one-sample steps: (image, CPU seconds, stats)."""
    import lantern
    s = lantern.Session(scene, integrator=integrator, seed=seed, backend="cpu", threads=1,
                        max_depth=args.max_depth, spp_per_iteration=1)
    c0 = time.process_time()
    for _ in range(args.spp):
        s.step()
    return s.image(), time.process_time() - c0, s.stats


def measure_all(scene_name, integrators, args):
    """Every integrator, seeds interleaved (seed k of each in turn), so that a change in the
    machine's load falls on all of them alike."""
    scene = build_scene(scene_name, args)
    runs = {i: [] for i in integrators}
    for k in range(args.seeds):
        for integ in integrators:
            runs[integ].append(render_one(scene, integ, 1000 + k, args))
    return [summarise(scene_name, integ, runs[integ]) for integ in integrators]


def summarise(scene_name, integrator, runs):
    imgs, times, chosen, rays, work = [], [], [], [], []
    for img, t, st in runs:
        times.append(t)
        imgs.append(img)
        # deterministic cost counts (the same seed, the same counts on any machine): rays, and
        # rays plus 0.36 of a ray per cis candidate (allocation.h's cost; M per camera vertex)
        rays.append(st["rays_total"])
        cis_vertices = (st["rays_camera"] + st["rays_indirect"]) if integrator == "cis" else 0
        if integrator == "auto" and "auto_cis_vertices" in st:  # cis's own, trials included
            cis_vertices = st["auto_cis_vertices"]
        elif integrator == "auto":  # (an older core) the share by iterations: trials over the
            it = st["auto_pt_iterations"] + st["auto_cis_iterations"]  # whole image only
            cis_vertices = (st["rays_camera"] + st["rays_indirect"]) * (
                st["auto_cis_iterations"] / max(it, 1))
        work.append(st["rays_total"] + 0.36 * 10 * cis_vertices)
        if "auto_choice" in st:
            chosen.append((st["auto_choice"], round(st["auto_cis_over_pt"], 3),
                           round(st.get("auto_pt_tail", 0.0), 2)))
    lum = np.einsum("kyxc,c->kyx", np.asarray(imgs, dtype=np.float64), [0.2126, 0.7152, 0.0722])
    mean = lum.mean()
    noise = float(lum.std(axis=0, ddof=1).mean() / mean)
    t = float(np.median(times))
    c = float(np.median(work))
    return {"scene": scene_name, "integrator": integrator, "mean": float(mean), "noise": noise,
            "time_s": t, "efficiency": 1.0 / (noise * noise * t), "auto": chosen,
            "rays": float(np.median(rays)), "work": c,
            "efficiency_work": 1.0 / (noise * noise * c)}


def step_times(scene_name, integrators, args):
    """CPU time of each step of one render (seed 3) per integrator: where auto's pilot goes."""
    import lantern
    scene = build_scene(scene_name, args)
    for integ in integrators:
        s = lantern.Session(scene, integrator=integ, seed=3, backend="cpu", threads=1,
                            max_depth=args.max_depth, spp_per_iteration=1)
        ts = []
        for _ in range(args.spp):
            c0 = time.process_time()
            s.step()
            ts.append(time.process_time() - c0)
        print(json.dumps({"scene": scene_name, "integrator": integ,
                          "step_cpu_s": [round(t, 4) for t in ts]}))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", action="store_true",
                    help="print each step's CPU time of one render instead")
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--integrators", default="pt,cis,auto")
    ap.add_argument("--res", default="64x64")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seeds", type=int, default=6)
    ap.add_argument("--max-depth", type=int, default=12)
    ap.add_argument("--out", default="")
    args = ap.parse_args()
    if args.steps:
        for scene in args.scenes.split(","):
            step_times(scene, args.integrators.split(","), args)
        return
    from light_tree_noise import machine
    info = {"before": machine()}
    rows = []
    for scene in args.scenes.split(","):
        for r in measure_all(scene, args.integrators.split(","), args):
            rows.append(r)
            print(json.dumps(r), flush=True)
    info["after"] = machine()
    info["settings"] = vars(args)
    lines = ["| scene | " + " | ".join(f"{i} noise | {i} time (s)" for i in
                                        args.integrators.split(",")) +
             " | " + " | ".join(f"{i} / pt" for i in args.integrators.split(",") if i != "pt") +
             " | " + " | ".join(f"{i} / pt (work)" for i in args.integrators.split(",")
                                if i != "pt") +
             " | auto chose (estimate, pt tail) |",
             "|---" * (4 * len(args.integrators.split(",")) - 1) + "|---|"]
    for scene in args.scenes.split(","):
        by = {r["integrator"]: r for r in rows if r["scene"] == scene}
        cells = [f"{100 * by[i]['noise']:.2f} % | {by[i]['time_s']:.2f}"
                 for i in args.integrators.split(",")]
        ratios = [f"{by[i]['efficiency'] / by['pt']['efficiency']:.2f}"
                  for i in args.integrators.split(",") if i != "pt" and "pt" in by]
        ratios_w = [f"{by[i]['efficiency_work'] / by['pt']['efficiency_work']:.2f}"
                    for i in args.integrators.split(",") if i != "pt" and "pt" in by]
        chose = ", ".join(f"{c} ({r}, {t})" for c, r, t in by.get("auto", {}).get("auto", []))
        lines.append(f"| {scene} | " + " | ".join(cells) + " | " + " | ".join(ratios) +
                     " | " + " | ".join(ratios_w) + f" | {chose} |")
    table = "\n".join(lines)
    print(table)
    if args.out:
        os.makedirs(args.out, exist_ok=True)
        with open(os.path.join(args.out, "auto_efficiency.json"), "w") as f:
            json.dump({"machine": info, "rows": rows}, f, indent=1)
        with open(os.path.join(args.out, "table.md"), "w") as f:
            f.write(table + "\n")


if __name__ == "__main__":
    main()
