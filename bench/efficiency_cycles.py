"""Lantern against Cycles: efficiency = 1 / (noise^2 x time), one thread each, the same run
(issue 14's measure). Per scene, K independent seeds of each renderer at the same spp, rendered
interleaved (seed k of Cycles, then seed k of each Lantern integrator) so that a change in the
machine's load falls on all of them alike; Cycles and Lantern each in a child process of its own
on one CPU (bench/side_process.py, since branch benchproc: otherwise an idle TBB worker of
bpy's spins all through Cycles' one-thread render, and takes CPU time, and with a busy machine
wall time, from it).

    .venv/bin/python bench/efficiency_cycles.py                         # the default scene list
    .venv/bin/python bench/efficiency_cycles.py --scenes cornell_box,room_area_point \\
        --integrators pt,lvc,cis --seeds 6 --spp 64 --res 64 --out bench/results/<date>-efficiency

noise = sqrt(mean over pixels of the per-pixel variance between seeds) / image mean (RGB
averaged), and the same for the median variance over the pixels with signal (robust to
fireflies); time = the mean
wall time of one render (Cycles: `bpy.ops.render.render` with persistent data after a warm-up
render, so the scene is synchronised once; Lantern: `Session.step()`, the BVH built before;
`auto`, the default integrator, in steps of one sample as the add-on renders, its pilot inside
the time, and with it in the run every Lantern integrator in such steps).
The image-mean ratio against Cycles (with its standard error from the seeds) is printed beside
the efficiency, so a speed figure always comes with the bias it carries.

`--scenes all`: every builder of blend_scenes/ (scenes.SCENES with the world scenes, and the
benchmark scenes of bench_registry.py: Monkeybox, Whiteroom, Bedroom, the four small hard
cases), each at --res x --res (a scene that fails to build or render is listed with its error,
not fatal). The table and the plot carry auto / pt, the default integrator against path
tracing (issue 27's line: at least 0.9 on ordinary scenes)."""

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

BENCH = Path(__file__).resolve().parent
ROOT = BENCH.parent
sys.path.insert(0, str(BENCH))
if "--serve" in sys.argv:  # a child rendering one side: on one CPU before bpy loads TBB
    import side_process  # noqa: E402
    side_process.one_cpu()

DEFAULT_SCENES = ("cornell_box,light_point,light_point_sphere,light_spot,light_area_square,light_area_disk,"
                  "light_sun,emissive_mesh,world_color,world_hdri,room_area_point,"
                  "room_spot_sun_world,many_lights,bench_fixture")


def _noise(stack):
    """(rms relative noise, median-pixel relative noise, image mean) of K images (K, H, W, 3)."""
    lum = stack.mean(axis=3)
    mean = float(lum.mean())
    var = lum.var(axis=0, ddof=1)
    lit = lum.mean(axis=0) > 0  # the median over pixels that see something (not the void)
    med = float(np.median(var[lit])) if lit.any() else float("nan")
    return math.sqrt(float(var.mean())) / mean, math.sqrt(med) / mean, mean


def _serve(args):
    """A child process (side_process.serve): builds the scene and renders one side's seeds on
    request. "cycles": never imports lantern (build_blend without the export; a warm-up render
    synchronises the scene once); "lantern": the scene exported, one Session per request."""
    import tempfile
    import side_process
    import rmse_cycles
    state = {}

    def setup():
        if args.serve == "cycles":
            rmse_cycles.build_blend(args.scenes, args.res, args.res, export=False)
            rmse_cycles.render(1, 1, threads=1)  # warm-up: synchronise the scene once
        else:
            from rmse import import_lantern
            state["lantern"] = import_lantern()
            state["scene"] = rmse_cycles.build_blend(args.scenes, args.res, args.res)
        return {"pid": os.getpid()}

    def handle(req):
        out = os.path.join(tempfile.gettempdir(), f"efficiency_side_{os.getpid()}.npy")
        if args.serve == "cycles":
            c0 = time.process_time()
            img, s = rmse_cycles.render(req["seed"], args.spp, threads=1)
            cpu = time.process_time() - c0
            assert "lantern" not in sys.modules, "the Cycles process imported lantern"
        else:
            name_, _, rr = req["integ"].partition(":rr=")  # "pt:rr=3": roulette from depth 3
            extra = {"rr_depth": int(rr)} if rr else {}
            steps = req["steps"]
            sess = state["lantern"].Session(
                state["scene"], integrator=name_, seed=req["seed"], threads=1,
                spp_per_iteration=args.spp // steps, max_depth=rmse_cycles.BOUNCES + 2,
                backend="cpu", **extra)
            c0, t0 = time.process_time(), time.perf_counter()
            for _ in range(steps):
                sess.step()
            cpu, s = time.process_time() - c0, time.perf_counter() - t0
            img = sess.image()
            del sess
        np.save(out, np.asarray(img, np.float64)[..., :3])
        return {"npy": out, "wall": s, "cpu": cpu}

    side_process.serve(args.reply_fd, setup, handle)


def run_scene(name, args):
    """Cycles and the Lantern integrators on scene `name`, each side in a child process of its
    own on one CPU (bench/side_process.py), the seeds still interleaved between them."""
    import side_process
    integrators = args.integrators.split(",")
    images = {k: [] for k in ["cycles"] + integrators}
    times = {k: [] for k in images}
    common = [str(Path(__file__).resolve()), "--scenes", name, "--res", str(args.res),
              "--spp", str(args.spp)]
    with side_process.Side(common + ["--serve", "cycles"]) as cyc, \
            side_process.Side(common + ["--serve", "lantern"]) as lan:
        for seed in range(args.seeds):
            sides = [("cycles", cyc, {"seed": 101 + seed})]
            for integ in integrators:
                # auto as the add-on runs it: iterations of one sample, its pilot inside the
                # time; with auto in the run, every Lantern integrator so (auto / pt is then the
                # choice and the pilot, not the cost of 64 steps against one)
                steps = args.spp if integ == "auto" or "auto" in integrators else 1
                sides.append((integ, lan, {"seed": 1 + seed, "integ": integ, "steps": steps}))
            for key, side, req in sides:
                r = side.call(**req)
                images[key].append(np.load(r["npy"]))
                times[key].append(r["cpu"] if args.cpu_time else r["wall"])
    rows = []
    c_rms, c_med, c_mean = _noise(np.stack(images["cycles"]))
    c_t = float(np.mean(times["cycles"]))
    c_se = float(np.stack(images["cycles"]).mean(axis=(1, 2, 3)).std(ddof=1)) / math.sqrt(args.seeds)
    for k in ["cycles"] + integrators:
        stack = np.stack(images[k])
        rms, med, mean = _noise(stack)
        t = float(np.mean(times[k]))
        se = float(stack.mean(axis=(1, 2, 3)).std(ddof=1)) / math.sqrt(args.seeds)
        eff_rms = 1.0 / (rms * rms * t)
        eff_med = 1.0 / (med * med * t)
        rows.append({
            "scene": name, "renderer": k, "spp": args.spp, "seeds": args.seeds,
            "res": args.res, "time_s": t, "noise_rms": rms, "noise_median": med,
            "mean": mean, "mean_ratio": mean / c_mean,
            "mean_ratio_se": math.hypot(se / c_mean, c_se * mean / c_mean ** 2),
            "eff_rms_vs_cycles": eff_rms * (c_rms * c_rms * c_t),
            "eff_median_vs_cycles": eff_med * (c_med * c_med * c_t),
            "load_avg": os.getloadavg()[0]})
    return rows


def table(rows):
    out = ["| scene | renderer | time (s) | noise rms | noise median px | mean / Cycles | "
           "efficiency / Cycles (rms) | (median px) | / pt (rms) |",
           "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "error" in r:
            out.append(f"| {r['scene']} | (failed) | {r['error']} | | | | | | |")
            continue
        pt = next((q for q in rows if q["scene"] == r["scene"] and q.get("renderer") == "pt"
                   and "error" not in q), None)
        vs_pt = (f"{r['eff_rms_vs_cycles'] / pt['eff_rms_vs_cycles']:.2f}"
                 if pt and r["renderer"] not in ("cycles", "pt") else "")
        out.append(
            f"| {r['scene']} | {r['renderer']} | {r['time_s']:.3f} | {100 * r['noise_rms']:.2f}% | "
            f"{100 * r['noise_median']:.2f}% | {r['mean_ratio']:.4f} ± {r['mean_ratio_se']:.4f} | "
            f"{r['eff_rms_vs_cycles']:.2f} | {r['eff_median_vs_cycles']:.2f} | {vs_pt} |")
    return "\n".join(out)


def all_scenes():
    """Every builder of blend_scenes/ (rmse_cycles._blend_builders), in its order."""
    import rmse_cycles
    return ",".join(rmse_cycles._blend_builders())


def plot(rows, path):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    rows = [r for r in rows if "error" not in r]
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    renderers = [k for k in dict.fromkeys(r["renderer"] for r in rows) if k != "cycles"]
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(max(6, 0.45 * len(scenes)), 7), sharex=True)
    width = 0.8 / max(1, len(renderers))
    for j, k in enumerate(renderers):
        vals = [next((r["eff_rms_vs_cycles"] for r in rows
                      if r["scene"] == s and r["renderer"] == k), np.nan) for s in scenes]
        ax.bar(np.arange(len(scenes)) + j * width, vals, width, label=f"Lantern {k}")
    ax.axhline(1.0, color="k", lw=0.8)
    ax.set_yscale("log")
    ax.set_ylabel("efficiency / Cycles' (1 / noise² t)")
    ax.legend(fontsize=8)
    # the default integrator against path tracing, with issue 27's 0.9 line
    others = [k for k in renderers if k != "pt"]
    w2 = 0.8 / max(1, len(others))
    for j, k in enumerate(others):
        vals = []
        for s in scenes:
            a = next((r["eff_rms_vs_cycles"] for r in rows
                      if r["scene"] == s and r["renderer"] == k), np.nan)
            p = next((r["eff_rms_vs_cycles"] for r in rows
                      if r["scene"] == s and r["renderer"] == "pt"), np.nan)
            vals.append(a / p)
        ax2.bar(np.arange(len(scenes)) + j * w2, vals, w2, label=f"{k} / pt")
    ax2.axhline(1.0, color="k", lw=0.8)
    ax2.axhline(0.9, color="r", lw=0.8, ls="--")
    ax2.set_yscale("log")
    ax2.set_ylabel("efficiency / pt's")
    ax2.legend(fontsize=8)
    ax2.set_xticks(np.arange(len(scenes)) + 0.4 - width / 2)
    ax2.set_xticklabels(scenes, rotation=60, ha="right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", default=DEFAULT_SCENES)
    ap.add_argument("--integrators", default="auto,pt,lvc,cis",
                    help="comma-separated; NAME:rr=N sets Russian roulette's first depth")
    ap.add_argument("--seeds", type=int, default=6)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--res", type=int, default=64)
    ap.add_argument("--out", default=None, help="folder for results.json, table.md, plot.png")
    ap.add_argument("--cpu-time", action="store_true",
                    help="the process's CPU time instead of wall time (a loaded machine; Cycles "
                         "with one thread in its process, its EXR written and read included)")
    ap.add_argument("--serve", choices=["cycles", "lantern"], help=argparse.SUPPRESS)
    ap.add_argument("--reply-fd", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.serve:
        return _serve(args)
    if args.seeds < 2:
        ap.error("--seeds must be at least 2 (noise is the spread between seeds)")
    from light_tree_noise import machine
    rows = []
    names = all_scenes() if args.scenes == "all" else args.scenes
    for name in names.split(","):
        t0 = time.perf_counter()
        try:
            rows += run_scene(name, args)
        except Exception as e:  # noqa: BLE001 -- one scene's failure is a row, not the end
            rows.append({"scene": name, "error": f"{type(e).__name__}: {e}"[:160]})
        print(table([r for r in rows if r["scene"] == name]).split("\n", 2)[2])
        print(f"  ({time.perf_counter() - t0:.0f} s)", flush=True)
    text = table(rows)
    print(text)
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "results.json").write_text(json.dumps(
            {"machine": machine(), "args": vars(args), "rows": rows}, indent=1))
        (out / "table.md").write_text(text + "\n")
        plot(rows, out / "plot.png")


if __name__ == "__main__":
    main()
