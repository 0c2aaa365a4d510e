"""Lantern pt's noise against Cycles' at equal samples on the differential tester's random light
sets (issue 28 item 3: "for every scene of the tester's light sets, pt's noise at equal spp is at
most Cycles'"). A benchmark, not a test: it measures and records, it asserts nothing.

Each scene is a case of tools/difftest_scene.generate (full profile, its seed): the stage (room,
floor or void), objects, camera and its 1-6 lights of every kind (point, spot, area of every
shape, sun; radii, soft falloff, lights 1-20 cm from walls and the ceiling, some visible), with
the surfaces made rough so that the lights dominate: walls, floor and objects a grey Diffuse BSDF
(0.8), or with --surface mixed the objects a rough Principled (roughness 0.5); no world, no glass
shells or emissive spheres (the cases' emitters behind glass are another question). Cases
without a light are skipped.

Both renderers render K seeds at the same spp on one thread (Cycles bounces B, Lantern max_depth
B + 2, difftest's settings: no clamping, denoising, adaptive sampling or light threshold).
noise = sqrt(mean over pixels of the per-pixel variance of the luminance between seeds) / the
image's mean luminance (bench/efficiency_cycles.py's measure); ratio = pt's / Cycles', with a 90 %
interval from 400 bootstrap resamples of the seeds (each side resampled independently). The image
means' ratio is printed beside it, so a noise figure comes with the bias it carries.

    nice .venv/bin/python bench/light_sets_noise.py --first 0 --scenes 40 \\
        --out bench/results/2026-12-04-light-sets
"""
import argparse
import json
import math
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))
# one CPU before bpy loads TBB: no idle TBB worker to spin through Cycles' one-thread renders
# and bill them (bench/side_process.py, bench/results/2026-12-05-benchproc/)
sys.path.insert(0, str(ROOT / "bench"))
import side_process  # noqa: E402
side_process.one_cpu()
import difftest as dt  # noqa: E402  (puts the checkout's lantern first, as the tester does)
import difftest_scene as ds  # noqa: E402

DIFFUSE = {"nodes": {"n0": {"type": "ShaderNodeBsdfDiffuse", "props": {},
                            "inputs": {"Color": [0.8, 0.8, 0.8, 1.0]}}},
           "links": [], "out": ["n0", "BSDF"]}
ROUGH = {"nodes": {"n0": {"type": "ShaderNodeBsdfPrincipled", "props": {},
                          "inputs": {"Base Color": [0.8, 0.8, 0.8, 1.0], "Roughness": 0.5}}},
         "links": [], "out": ["n0", "BSDF"]}
LUM = np.array([0.2126, 0.7152, 0.0722])


def light_set_case(seed, size, bounces, surface):
    """The tester's case of `seed` with rough surfaces, no world and no glass or emitter
    objects; None when it has no light."""
    case = ds.generate(seed, "full", size)
    if not case["lights"]:
        return None
    objs = [o for o in case["objects"] if o.get("material") not in ("glass", "emitter")]
    for o in objs:
        stage = o["kind"] == "room" or o.get("material") == "floor"
        o["material"] = "diffuse" if stage or surface == "diffuse" else "rough"
    case["objects"] = objs
    case["materials"] = {"diffuse": DIFFUSE, "rough": ROUGH}
    case["world"] = None
    case["bounces"] = bounces
    return case


def noise(stack):
    """(noise, mean luminance) of K images (K, H, W, 3)."""
    lum = stack @ LUM
    mean = float(lum.mean())
    return math.sqrt(float(lum.var(axis=0, ddof=1).mean())) / mean, mean


def ratio_interval(lan, cyc, rng, n=400):
    k = len(lan)
    r = []
    for _ in range(n):
        a = noise(lan[rng.integers(0, k, k)])[0]
        b = noise(cyc[rng.integers(0, k, k)])[0]
        r.append(a / b)
    return [float(x) for x in np.quantile(r, [0.05, 0.95])]


def describe_lights(case):
    out = []
    for lt in case["lights"]:
        d = lt["type"].lower()
        if lt["type"] == "AREA":
            d += "/" + lt.get("shape", "SQUARE").lower()
        if lt.get("radius"):
            d += f" r{lt['radius']:.2f}"
        if lt.get("soft_falloff"):
            d += " soft"
        out.append(d)
    return ", ".join(out)


def machine():
    cpu = platform.processor() or ""
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(l.split(":", 1)[1].strip() for l in f if l.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return {"cpu": cpu, "cores": os.cpu_count(), "load": os.getloadavg()[0],
            "python": platform.python_version()}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--first", type=int, default=0, help="first tester seed")
    ap.add_argument("--scenes", type=int, default=40, help="scenes with lights to render")
    ap.add_argument("--size", type=int, default=32)
    ap.add_argument("--seeds", type=int, default=16)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--bounces", type=int, default=2)
    ap.add_argument("--surface", choices=("diffuse", "mixed"), default="mixed")
    ap.add_argument("--only", type=int, nargs="*", help="these tester seeds only")
    ap.add_argument("--out", default=str(ROOT / "build" / "light_sets"))
    args = ap.parse_args(argv)
    import lantern
    import difftest_build as db
    os.makedirs(args.out, exist_ok=True)
    rng = np.random.default_rng(0)
    rows = []
    seeds = [1 + k for k in range(args.seeds)]
    todo = args.only if args.only else range(args.first, 10 ** 6)
    for seed in todo:
        if len(rows) >= args.scenes:
            break
        case = light_set_case(seed, args.size, args.bounces, args.surface)
        if case is None:
            continue
        db.build(case)
        scene, warnings = dt.export_lantern()
        t0 = time.process_time()
        lan = np.stack(dt.render_lantern(scene, args.bounces, seeds, args.spp, "pt", 1))
        t_lan = (time.process_time() - t0) / len(seeds)
        t0 = time.perf_counter()
        cyc = np.stack(dt.render_cycles(args.bounces, seeds, args.spp, 1))
        t_cyc = (time.perf_counter() - t0) / len(seeds)
        ml, mc = float((lan @ LUM).mean()), float((cyc @ LUM).mean())
        if not (mc > 1e-7 and ml > 1e-7):
            print(f"[{seed}] black, skipped", flush=True)
            continue
        nl, nc = noise(lan)[0], noise(cyc)[0]
        lo, hi = ratio_interval(lan, cyc, rng)
        row = {"seed": seed, "lights": describe_lights(case), "n_lights": len(case["lights"]),
               "stage": case["objects"][0]["kind"] if case["objects"] else "void",
               "noise_pt": nl, "noise_cycles": nc, "ratio": nl / nc, "ratio_90": [lo, hi],
               "mean_ratio": ml / mc, "sec_pt_cpu": t_lan, "sec_cycles_wall": t_cyc,
               "warnings": warnings}
        rows.append(row)
        print(f"[{seed}] {row['stage']}; {row['lights']}: pt {nl:.2%} Cycles {nc:.2%}, "
              f"ratio {nl / nc:.3f} [{lo:.3f}, {hi:.3f}], means {ml / mc:.4f}", flush=True)
        with open(os.path.join(args.out, "results.json"), "w") as f:
            json.dump({"machine": machine(), "lantern": lantern.__file__,
                       "settings": vars(args), "rows": rows}, f, indent=1)
    r = np.array([x["ratio"] for x in rows])
    if len(r):
        worse = [x["seed"] for x in rows if x["ratio_90"][0] > 1.0]
        print(f"{len(r)} scenes: noise ratio pt / Cycles median {np.median(r):.3f}, "
              f"geometric mean {math.exp(np.log(r).mean()):.3f}, max {r.max():.3f}; "
              f"pt noisier beyond its 90 % interval on {len(worse)}: {worse}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
