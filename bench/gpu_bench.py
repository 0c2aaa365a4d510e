"""The GPU benchmark of issue 6 (runs on any backend; numbers only mean something on `cuda`):

1. rays per second from the session's own counters and stage clocks (pt): camera rays
   (max_depth 1: rays_camera / time_trace), shadow rays (rays_shadow / time_shadow) and
   incoherent bounce rays (rays_indirect over the trace time a max_depth-5 session spends
   beyond the max_depth-1 one with the same seed, i.e. minus its camera rays);
2. time per iteration per stage (every time_* stat / iterations) for pt, lvc and cis;
3. the paper's Table 1: cumulative time of LVC-BDPTmk (lvc), cis without sorting and cis
   (sorted) at the paper's resolutions and samples per iteration (Monkeybox 1024x1024, 8 spp
   per iteration; Whiteroom and Bedroom 1980x1080, 4), after each of 5 iterations, beside the
   paper's GTX Titan milliseconds, with the share of time spent sorting.

    python3 bench/gpu_bench.py [--backend cuda] [--scenes monkeybox,whiteroom,bedroom]
        [--scene-dir build/bench_scenes] [--budget 60] [--out DIR] [--quick]

Scenes are .lantern files: a name is looked up as <scene-dir>/<name>.lantern, then
bench/scenes/<name>.lantern; a missing one is reported and skipped. --budget caps the seconds
one configuration may spend (iterations stop early, the row says so). --quick (for checking the
tool on a CPU): 64x36 pixels, 2 iterations, bench/scenes/bench_glossy.lantern. Writes
gpu_bench.json, gpu_bench.md and machine.json under --out and prints the summary last."""

import argparse
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python"))
sys.path.insert(0, str(ROOT / "bench"))

import lantern  # noqa: E402
from lantern import session as lsession  # noqa: E402

# Table 1 of the paper (Ravichandran & Narayanan, SA'15; GTX Titan): per scene the resolution,
# samples per iteration, effective spp after each iteration, and LVC-BDPTmk / CIS-LBDPT ms.
PAPER = {
    "monkeybox": {"res": (1024, 1024), "spi": 8, "spp": [8, 16, 24, 32, 40],
                  "lvc_ms": [18237, 39534, 61867, 84471, 104630],
                  "cis_ms": [14228, 31376, 46169, 64214, 78082]},
    "whiteroom": {"res": (1980, 1080), "spi": 4, "spp": [4, 8, 12, 16, 20],
                  "lvc_ms": [34890, 68011, 105419, 145022, 182498],
                  "cis_ms": [24780, 48988, 76138, 106276, 126046]},
    "bedroom": {"res": (1980, 1080), "spi": 4, "spp": [4, 8, 12, 16, 20],
                "lvc_ms": [31595, 67509, 103618, 141286, 179323],
                "cis_ms": [20374, 46053, 70717, 94269, 122053]},
}
TABLE1_CONFIGS = [("lvc", {"integrator": "lvc", "sort": False}),
                  ("cis-nosort", {"integrator": "cis", "sort": False}),
                  ("cis", {"integrator": "cis", "sort": True})]


def find_scene(name, scene_dir):
    for p in (Path(name), Path(scene_dir) / f"{name}.lantern",
              ROOT / "bench" / "scenes" / f"{name}.lantern"):
        p = p if p.is_absolute() else ROOT / p
        if p.suffix == ".lantern" and p.is_file():
            return p
    return None


def load(path, res):
    scene = lantern.load_scene(str(path))
    scene.film["width"], scene.film["height"] = int(res[0]), int(res[1])
    return scene


def run(scene, backend, iterations, budget, **settings):
    """Steps a session; returns cumulative wall ms after each iteration, the stats, the
    backend really used, the set-up seconds and whether the budget cut it short."""
    t0 = time.perf_counter()
    s = lantern.Session(scene, backend=backend, **settings)
    setup = time.perf_counter() - t0
    if s.backend != backend:  # fell back (no GPU memory, say): CPU times would mislead
        return {"ms": [], "stats": dict(s.stats), "backend": s.backend, "setup_s": setup,
                "cut": True, "warnings": s.warnings}
    cumulative, start = [], time.perf_counter()
    for _ in range(iterations):
        s.step()
        cumulative.append(1000.0 * (time.perf_counter() - start))
        if time.perf_counter() - start > budget:
            break
    return {"ms": cumulative, "stats": dict(s.stats), "backend": s.backend,
            "setup_s": setup, "cut": len(cumulative) < iterations, "warnings": s.warnings}


def rate(n, seconds):
    return n / seconds if seconds and seconds > 0 and n else None


def ray_rates(scene, backend, spi, iterations, budget):
    """Camera, shadow and incoherent bounce rays per second (pt)."""
    cam = run(scene, backend, iterations, budget, integrator="pt", max_depth=1,
              spp_per_iteration=spi, seed=1)
    deep = run(scene, backend, len(cam["ms"]), budget * 4, integrator="pt", max_depth=5,
               spp_per_iteration=spi, seed=1)
    a, b = cam["stats"], deep["stats"]
    bounce_trace = b.get("time_trace", 0) - a.get("time_trace", 0)
    return {"camera": rate(a.get("rays_camera"), a.get("time_trace")),
            "shadow": rate(b.get("rays_shadow"), b.get("time_shadow")),
            "bounce": rate(b.get("rays_indirect"), bounce_trace),
            "all_pt": rate(b.get("rays_total"), b.get("time_total")),
            "rays": {k: b.get(k) for k in ("rays_camera", "rays_indirect", "rays_shadow")},
            "backend": deep["backend"]}


def per_stage(stats):
    n = max(1, int(stats.get("iterations", 1)))
    return {k[5:]: 1000.0 * v / n for k, v in sorted(stats.items())
            if k.startswith("time_") and k != "time_build" and isinstance(v, (int, float))}


def fmt_rate(r):
    return f"{r / 1e6:,.1f} M/s" if r else "n/a"


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--backend", default="cuda")
    p.add_argument("--scenes", default="monkeybox,whiteroom,bedroom")
    p.add_argument("--scene-dir", default="build/bench_scenes")
    p.add_argument("--iterations", type=int, default=5)
    p.add_argument("--budget", type=float, default=60.0,
                   help="seconds one configuration may spend (60)")
    p.add_argument("--res", default=None, help="WxH instead of the paper's resolution")
    p.add_argument("--spp-per-iteration", type=int, default=None)
    p.add_argument("--out", default=None)
    p.add_argument("--quick", action="store_true", help="toy size, for checking the tool")
    args = p.parse_args(argv)
    if args.quick:
        args.res = args.res or "64x36"
        args.iterations = min(args.iterations, 2)
        if args.scenes == p.get_default("scenes"):
            args.scenes = "bench_glossy"
    reason = lsession.backend_unavailable(args.backend)
    if reason:
        print(f"gpu_bench: backend {args.backend!r} unavailable: {reason}", file=sys.stderr)
        return 2
    out = Path(args.out) if args.out else None
    if out:
        out.mkdir(parents=True, exist_ok=True)
    from rmse_report import machine_info
    machine = machine_info(lantern, 0)
    machine["cuda"] = lantern.cuda_info()
    results = {"args": vars(args), "scenes": {}, "skipped": {}}
    for name in [s.strip() for s in args.scenes.split(",") if s.strip()]:
        path = find_scene(name, args.scene_dir)
        if path is None:
            results["skipped"][name] = f"no {name}.lantern in {args.scene_dir} or bench/scenes"
            print(f"gpu_bench: {name}: skipped ({results['skipped'][name]})", flush=True)
            continue
        paper = PAPER.get(Path(name).stem)
        res = tuple(int(v) for v in args.res.split("x")) if args.res else (
            paper["res"] if paper else None)
        spi = args.spp_per_iteration or (paper["spi"] if paper else 4)
        t0 = time.perf_counter()
        scene = load(path, res) if res else lantern.load_scene(str(path))
        res = (scene.film["width"], scene.film["height"])
        entry = {"file": str(path), "res": list(res), "spi": spi,
                 "triangles": scene.summary()["triangles"],
                 "load_s": round(time.perf_counter() - t0, 3)}
        print(f"gpu_bench: {name}: {entry['triangles']} triangles, {res[0]}x{res[1]}, "
              f"{spi} spp/iteration", flush=True)
        entry["rays"] = ray_rates(scene, args.backend, spi, args.iterations, args.budget)
        print(f"  rays/s: camera {fmt_rate(entry['rays']['camera'])}, shadow "
              f"{fmt_rate(entry['rays']['shadow'])}, bounce {fmt_rate(entry['rays']['bounce'])}",
              flush=True)
        entry["table1"], entry["stages_ms"] = {}, {}
        for label, settings in TABLE1_CONFIGS:
            r = run(scene, args.backend, args.iterations, args.budget, spp_per_iteration=spi,
                    seed=1, **settings)
            st = r["stats"]
            entry["table1"][label] = {
                "ms": [round(v, 1) for v in r["ms"]], "cut": r["cut"], "backend": r["backend"],
                "setup_s": round(r["setup_s"], 3),
                "sort_share": (st.get("time_sort", 0) / st["time_total"]
                               if st.get("time_total") else None),
                "sorted_bounces": st.get("sorted_bounces"),
                "unsorted_bounces": st.get("unsorted_bounces"),
                "rays_total": st.get("rays_total"), "warnings": r["warnings"],
                # the backend's own buffers at most, and the device's memory in use by the
                # session at most (with the kernels' local memory): issue 6's 6 GB target
                "device_memory_peak": st.get("device_memory_peak"),
                "device_memory_used": st.get("device_memory_used")}
            entry["stages_ms"][label] = per_stage(st)
            print(f"  {label:>10}: " + ", ".join(f"{v / 1000:.2f}" for v in r["ms"]) +
                  f" s cumulative{' (budget cut)' if r['cut'] else ''} on {r['backend']}",
                  flush=True)
        pt = run(scene, args.backend, min(2, args.iterations), args.budget, integrator="pt",
                 spp_per_iteration=spi, seed=1, max_depth=16)
        entry["stages_ms"]["pt"] = per_stage(pt["stats"])
        if paper and res == tuple(paper["res"]) and spi == paper["spi"]:
            entry["paper"] = paper
        results["scenes"][name] = entry
        write(out, results, machine)  # after each scene: a timeout keeps what finished
    write(out, results, machine)
    print(summary(results, machine))
    return 0 if results["scenes"] else 1


def write(out, results, machine):
    if out:
        (out / "gpu_bench.json").write_text(json.dumps(results, indent=1, default=str))
        (out / "machine.json").write_text(json.dumps(machine, indent=1, default=str))
        (out / "gpu_bench.md").write_text(report_md(results, machine))


def report_md(results, machine):
    cuda = machine.get("cuda", {})
    lines = [f"# GPU benchmark ({cuda.get('name') or machine.get('cpu')})", "",
             f"backend `{results['args']['backend']}`, {machine.get('date')}, commit "
             f"{machine.get('git_commit')}", "", "## Rays per second (pt)", "",
             "| scene | camera | shadow | incoherent bounce |", "|---|---|---|---|"]
    for name, e in results["scenes"].items():
        r = e["rays"]
        lines.append(f"| {name} | {fmt_rate(r['camera'])} | {fmt_rate(r['shadow'])} | "
                     f"{fmt_rate(r['bounce'])} |")
    lines += ["", "## Table 1: cumulative ms after each iteration", "",
              "| scene | eff. spp | lvc | cis no sort | cis | paper LVC-BDPTmk | paper CIS-LBDPT |"
              " sort share (cis) | GPU memory (cis: buffers / in use, GiB) |",
              "|---|---|---|---|---|---|---|---|---|"]
    for name, e in results["scenes"].items():
        t1, paper = e["table1"], e.get("paper")
        share = t1["cis"]["sort_share"]
        for i, ms in enumerate(t1["cis"]["ms"]):
            cells = [f"{t1[c]['ms'][i]:.0f}" if i < len(t1[c]["ms"]) else "-"
                     for c in ("lvc", "cis-nosort", "cis")]
            pl = f"{paper['lvc_ms'][i]}" if paper and i < 5 else "-"
            pc = f"{paper['cis_ms'][i]}" if paper and i < 5 else "-"
            mem = f"{gib(t1['cis'].get('device_memory_peak'))} / {gib(t1['cis'].get('device_memory_used'))}"
            lines.append(f"| {name} | {e['spi'] * (i + 1)} | {' | '.join(cells)} | {pl} | {pc} | "
                         f"{'' if share is None else f'{share:.1%}'} | {mem} |")
    lines += ["", "## Time per iteration per stage (ms)", ""]
    for name, e in results["scenes"].items():
        stages = sorted({k for v in e["stages_ms"].values() for k in v})
        lines += [f"### {name}", "", "| config | " + " | ".join(stages) + " |",
                  "|---|" + "---|" * len(stages)]
        for label, v in e["stages_ms"].items():
            lines.append(f"| {label} | " + " | ".join(f"{v.get(k, 0):.2f}" for k in stages) + " |")
        lines.append("")
    return "\n".join(lines) + "\n"


def gib(b):
    return f"{b / 2**30:.2f}" if b else "-"


def summary(results, machine):
    cuda = machine.get("cuda", {})
    lines = [f"== gpu_bench: backend {results['args']['backend']} on "
             f"{cuda.get('name') or machine.get('cpu')} =="]
    lines.append(f"{'scene':>10} {'camera':>12} {'shadow':>12} {'bounce':>12} "
                 f"{'lvc s':>8} {'cis-ns s':>8} {'cis s':>8} {'sort%':>6} {'paper cis s':>11} "
                 f"{'GiB':>5}")
    for name, e in results["scenes"].items():
        r, t1, paper = e["rays"], e["table1"], e.get("paper")

        def last(c):
            return f"{t1[c]['ms'][-1] / 1000:.2f}" if t1[c]["ms"] else "-"
        share = t1["cis"]["sort_share"]
        lines.append(f"{name:>10} {fmt_rate(r['camera']):>12} {fmt_rate(r['shadow']):>12} "
                     f"{fmt_rate(r['bounce']):>12} {last('lvc'):>8} {last('cis-nosort'):>8} "
                     f"{last('cis'):>8} {'' if share is None else f'{100 * share:.1f}':>6} "
                     f"{paper['cis_ms'][len(t1['cis']['ms']) - 1] / 1000 if paper else '-':>11} "
                     f"{gib(t1['cis'].get('device_memory_used')):>5}")
    for name, why in results["skipped"].items():
        lines.append(f"{name:>10} skipped: {why}")
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(main())
