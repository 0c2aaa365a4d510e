"""Light tree against the global power CDF (issue 14 item 2): per-pixel noise at equal spp and
efficiency 1 / (noise^2 x time), one thread, K seeds, on the rooms of blend_scenes/efficiency.py
(built with lantern.scenes), a many-light stage and a one-light scene.

noise = mean over pixels of the spread (sample standard deviation) of the luminance between
seeds, over the image's mean luminance (issue 14's measure). time = CPU seconds of one
render (Session.step at spp samples per pixel, one thread; the process's CPU time, which a
shared, loaded machine disturbs far less than wall time, also recorded), median over seeds.

Each (scene, integrator, mode) runs in its own process: LANTERN_LIGHT_TREE=0 is read when a
scene is built, and `--baseline-core DIR` (a python/ folder with another build's lantern, e.g.
/work/main/python) times the one-light scene on the code before the tree.

    python bench/light_tree_noise.py --res 96x96 --spp 32 --seeds 8 \\
        --out bench/results/2026-12-01-light-tree
"""
import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
SCENES = {  # name -> (lantern.scenes builder, keyword arguments)
    "room_area_point": ("room_area_point", {}),
    "room_spot_sun_world": ("room_spot_sun_world", {}),
    "many_lights": ("many_lights_stage", {"n": 24, "panel": True}),
    "one_light": ("cornell_box", {}),
    "small_room_two_lights": ("small_room_two_lights", {}),
    "small_room_area": ("small_room_two_lights", {"lights": "area"}),
    "small_room_point": ("small_room_two_lights", {"lights": "point"}),
}


def worker(args):
    import lantern
    from lantern import scenes
    builder, kw = SCENES[args.scene]
    w, h = (int(v) for v in args.res.split("x"))
    scene = getattr(scenes, builder)(w, h, **kw)
    imgs, times, walls = [], [], []
    for k in range(args.seeds):
        extra = {"light_candidates": int(args.mode[3:])} if args.mode.startswith("ris") else {}
        s = lantern.Session(scene, integrator=args.integrator, seed=100 + k, backend="cpu",
                            threads=1, max_depth=args.max_depth, spp_per_iteration=args.spp,
                            **extra)
        t0, c0 = time.perf_counter(), time.process_time()
        s.step()
        walls.append(time.perf_counter() - t0)
        times.append(time.process_time() - c0)
        imgs.append(s.image())
    lum = np.einsum("kyxc,c->kyx", np.asarray(imgs, dtype=np.float64), [0.2126, 0.7152, 0.0722])
    mean = lum.mean()
    noise = float(lum.std(axis=0, ddof=1).mean() / mean)
    t = float(np.median(times))
    print(json.dumps({"scene": args.scene, "integrator": args.integrator, "mode": args.mode,
                      "mean": float(mean), "noise": noise, "time_s": t,
                      "wall_s": float(np.median(walls)),
                      "efficiency": 1.0 / (noise * noise * t)}))


def run(scene, integrator, mode, args):
    env = dict(os.environ)
    env["LANTERN_LIGHT_TREE"] = "0" if mode == "cdf" else "1"
    py = str(HERE.parent / "python")
    if mode == "baseline":
        py = args.baseline_core
    env["PYTHONPATH"] = py
    cmd = [sys.executable, __file__, "--worker", "--scene", scene, "--integrator", integrator,
           "--mode", mode, "--res", args.res, "--spp", str(args.spp), "--seeds", str(args.seeds),
           "--max-depth", str(args.max_depth)]
    out = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def machine():
    cpu = ""
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {"cpu": cpu, "cores": os.cpu_count(), "platform": platform.platform(),
            "python": platform.python_version(), "load_avg": os.getloadavg(),
            "date": time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime())}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--scene")
    ap.add_argument("--mode")
    ap.add_argument("--integrator", default="pt")
    ap.add_argument("--scenes", default=",".join(list(SCENES)[:4]))
    ap.add_argument("--integrators", default="pt")
    ap.add_argument("--res", default="96x96")
    ap.add_argument("--spp", type=int, default=32)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--max-depth", type=int, default=8, help="2: direct light only")
    ap.add_argument("--ris", default="", help="also resampled NEE with these M, e.g. 2,4")
    ap.add_argument("--baseline-core", default="",
                    help="python/ folder of the build before the tree: times one_light there")
    ap.add_argument("--out", default="")
    args = ap.parse_args()
    if args.worker:
        return worker(args)
    rows = []
    info = {"before": machine()}
    for scene in args.scenes.split(","):
        for integrator in args.integrators.split(","):
            modes = ["cdf", "tree"] + [f"ris{m}" for m in args.ris.split(",") if m]
            if scene == "one_light" and args.baseline_core:
                modes.append("baseline")
            for mode in modes:
                r = run(scene, integrator, mode, args)
                rows.append(r)
                print(f"{scene:20s} {integrator:5s} {mode:8s} noise {r['noise']:.4f} "
                      f"time {r['time_s']:.3f} s  efficiency {r['efficiency']:.1f}", flush=True)
    info["after"] = machine()
    info["settings"] = {"res": args.res, "spp": args.spp, "seeds": args.seeds, "threads": 1,
                        "max_depth": args.max_depth}
    lines = ["| scene | integrator | global CDF noise | tree noise | CDF time (s) | "
             "tree time (s) | efficiency tree / CDF |", "|---|---|---|---|---|---|---|"]
    for scene in args.scenes.split(","):
        for integrator in args.integrators.split(","):
            c = next(r for r in rows if (r["scene"], r["integrator"], r["mode"]) ==
                     (scene, integrator, "cdf"))
            t = next(r for r in rows if (r["scene"], r["integrator"], r["mode"]) ==
                     (scene, integrator, "tree"))
            lines.append(f"| {scene} | {integrator} | {c['noise']:.4f} | {t['noise']:.4f} | "
                         f"{c['time_s']:.3f} | {t['time_s']:.3f} | "
                         f"{t['efficiency'] / c['efficiency']:.2f} |")
    for r in rows:
        if r["mode"].startswith("ris"):
            t = next(x for x in rows if (x["scene"], x["integrator"], x["mode"]) ==
                     (r["scene"], r["integrator"], "tree"))
            lines.append(f"\n{r['scene']} {r['integrator']} resampled M = {r['mode'][3:]}: noise "
                         f"{r['noise']:.4f}, time {r['time_s']:.3f} s, efficiency / tree alone "
                         f"{r['efficiency'] / t['efficiency']:.2f}")
    base = [r for r in rows if r["mode"] == "baseline"]
    for b in base:
        t = next(r for r in rows if (r["scene"], r["integrator"], r["mode"]) ==
                 (b["scene"], b["integrator"], "tree"))
        lines.append(f"\n{b['scene']} {b['integrator']}: {t['time_s']:.3f} s on this branch, "
                     f"{b['time_s']:.3f} s on the baseline core ({args.baseline_core}); noise "
                     f"{t['noise']:.4f} vs {b['noise']:.4f}")
    table = "\n".join(lines)
    print(table)
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "results.json").write_text(json.dumps({"machine": info, "rows": rows}, indent=1))
        (out / "table.md").write_text(table + "\n")


if __name__ == "__main__":
    main()
