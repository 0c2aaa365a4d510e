"""What `bench/rmse.py` writes: results.csv, runs.json, machine.json, rmse_<scene>.png (RMSE
against samples and against time, log-log, one line per integrator) and table.md.

A run is a dict: scene, integrator, checkpoints [{spp, seconds, rmse, rel_rmse, ...}], stats,
setup_s; or scene, integrator, skipped (the reason)."""

import csv
import json
import math
import os
import platform
import subprocess
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

CSV_FIELDS = ("scene", "integrator", "spp", "seconds", "rmse", "rel_rmse",
              "rmse_debiased", "rel_rmse_debiased")


# ---- machine ----

def _cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def _git(*args, strip=True):
    root = Path(__file__).resolve().parents[1]
    try:
        out = subprocess.run(["git", *args], cwd=root, capture_output=True, text=True,
                             timeout=10)
        if out.returncode != 0:
            return None
        return out.stdout.strip() if strip else out.stdout
    except (OSError, subprocess.SubprocessError):
        return None


def _version(module):
    try:
        return __import__(module).__version__
    except Exception:  # absent or broken: record that, do not fail the benchmark
        return None


def machine_info(lantern, threads):
    core = lantern.session.require_core()
    build = core.build_info() if callable(core.build_info) else core.build_info
    try:
        affinity = len(os.sched_getaffinity(0))
    except AttributeError:
        affinity = os.cpu_count()
    dirty = _git("status", "--porcelain", "--untracked-files=no", strip=False)
    return {
        "date": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "cpu": _cpu_model(),
        "cpu_count": os.cpu_count(),
        "cpus_usable": affinity,
        "threads_setting": threads,
        "os": platform.platform(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "matplotlib": _version("matplotlib"),
        "lantern": getattr(lantern, "__version__", None),
        "lantern_path": str(Path(lantern.__file__).parent),
        "lantern_core": getattr(core, "__file__", None),
        "lantern_core_mtime": (datetime.fromtimestamp(os.path.getmtime(core.__file__),
                                                      timezone.utc).isoformat(timespec="seconds")
                               if getattr(core, "__file__", None) else None),
        "build_info": build,
        "embree": core.embree_version() if hasattr(core, "embree_version") else None,
        "git_commit": _git("rev-parse", "HEAD"),
        "git_dirty": sorted(line[3:] for line in dirty.splitlines() if line) if dirty else [],
        "load_avg_1m": os.getloadavg()[0],
    }


# ---- numbers ----

def time_to_target(checkpoints, target):
    """Step seconds at which the run's RMSE first reaches `target` (log-log interpolated
    between checkpoints), or None when it never does."""
    prev = None
    for cp in checkpoints:
        if cp["rmse"] <= target:
            if prev is None or prev["rmse"] <= 0 or cp["rmse"] <= 0 or cp["seconds"] <= 0:
                return cp["seconds"]
            la, lb = math.log(prev["rmse"]), math.log(cp["rmse"])
            f = (la - math.log(target)) / (la - lb) if la != lb else 1.0
            return math.exp(math.log(prev["seconds"]) + f * (math.log(cp["seconds"])
                                                            - math.log(prev["seconds"])))
        if cp["seconds"] > 0:
            prev = cp
    return None


def _fmt(x, digits=4):
    if x is None:
        return "–"
    if isinstance(x, float):
        return f"{x:.{digits}g}"
    return str(x)


# ---- files ----

def write_csv(path, runs):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=CSV_FIELDS, extrasaction="ignore")
        w.writeheader()
        for run in runs:
            for cp in run.get("checkpoints", []):
                w.writerow({"scene": run["scene"], "integrator": run["integrator"],
                            **{k: (f"{v:.6g}" if isinstance(v, float) else v)
                               for k, v in cp.items()}})


def write_json(path, data):
    with open(path, "w") as f:
        json.dump(data, f, indent=2, default=lambda o: o.tolist() if hasattr(o, "tolist")
                  else str(o))
        f.write("\n")


def plot_scene(path, scene, runs, ref, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    for ax, key, label in ((axes[0], "spp", "samples per pixel"),
                           (axes[1], "seconds", "render time (s)")):
        for run in runs:
            pts = [cp for cp in run["checkpoints"] if cp[key] > 0 and cp["rmse"] > 0]
            if not pts:
                continue
            ax.loglog([cp[key] for cp in pts], [cp["rmse"] for cp in pts], "o-",
                      ms=3, lw=1.4, label=run["integrator"])
            if run is runs[0] and len(pts) > 1:  # a 1/sqrt(N) guide through the first point
                x0, y0, x1 = pts[0][key], pts[0]["rmse"], pts[-1][key]
                ax.loglog([x0, x1], [y0, y0 * math.sqrt(x0 / x1)], ":", color="0.6", lw=1,
                          label=r"$\propto N^{-1/2}$")
        if ref is not None and ref["rmse_floor"] > 0:
            ax.axhline(ref["rmse_floor"], ls="--", color="0.4", lw=1,
                       label=f"reference noise ({ref['spp']} spp)")
        ax.set_xlabel(label)
        ax.set_ylabel("RMSE")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    axes[0].set_title("RMSE vs samples")
    axes[1].set_title("RMSE vs time")
    fig.suptitle(title, fontsize=10)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _stats_lines(stats, seconds):
    # zero counters (stages another integrator uses) are left out; runs.json has them all
    rays = {k[5:]: v for k, v in stats.items() if k.startswith("rays_") and v}
    times = {k[5:]: v for k, v in stats.items() if k.startswith("time_") and v}
    other = {k: v for k, v in stats.items() if not k.startswith(("rays_", "time_"))}
    lines = []
    if rays:
        total = rays.get("total", sum(v for k, v in rays.items() if k != "total"))
        rate = f", {total / seconds / 1e6:.2f} Mrays/s" if seconds > 0 else ""
        lines.append("rays: " + ", ".join(f"{k} {v / 1e6:.2f} M" for k, v in rays.items())
                     + rate)
    if times:
        total = times.get("total") or sum(times.values())
        lines.append("time: " + ", ".join(
            f"{k} {v:.3g} s" + (f" ({100 * v / total:.0f} %)" if total and k != "total" else "")
            for k, v in times.items()))
    if other:
        lines.append("other: " + ", ".join(f"{k} {v}" for k, v in other.items()))
    return lines


def table_md(runs, refs, machine, args_line, target_rmse=None):
    """The Markdown summary: per scene, a table of integrators and the reference used."""
    out = ["# Speed against error", "", f"Command: `{args_line}`", ""]
    for scene in dict.fromkeys(r["scene"] for r in runs):
        done = [r for r in runs if r["scene"] == scene and r.get("checkpoints")]
        skipped = [r for r in runs if r["scene"] == scene and r.get("skipped")]
        out += [f"## {scene}", ""]
        ref = refs.get(scene)
        if ref is not None:
            out += [f"Reference: {ref['integrator']}, {ref['spp']} spp as {ref['n_seeds']} "
                    f"seeds of {ref['spp_per_seed']} spp, {ref['wall_s']:.1f} s to render"
                    f"{' (cached)' if ref.get('cached') else ''}; its own expected RMSE "
                    f"(noise floor) {ref['rmse_floor']:.4g}, relative {ref['rel_rmse_floor']:.4g}. "
                    f"`{Path(ref['path']).name}`", ""]
        if done:
            finals = [r["checkpoints"][-1]["rmse"] for r in done]
            target = target_rmse if target_rmse is not None else max(finals)
            ttt = {r["integrator"]: time_to_target(r["checkpoints"], target) for r in done}
            all_reached = all(t is not None for t in ttt.values())
            base = ttt.get("pt")
            out += [f"Common RMSE target: {target:.4g} "
                    f"({'given' if target_rmse is not None else 'worst final RMSE'}"
                    f"{'' if all_reached else '; not reached by every integrator'}).", "",
                    "| integrator | spp | time (s) | setup (s) | RMSE | rel RMSE | RMSE − floor "
                    "| time to target (s) | speedup vs pt |",
                    "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
            for r in done:
                cp = r["checkpoints"][-1]
                t = ttt[r["integrator"]]
                speed = (f"{base / t:.2f}×" if all_reached and base and t else "–")
                out.append(f"| {r['integrator']} | {cp['spp']} | {cp['seconds']:.2f} | "
                           f"{r['setup_s']:.2f} | {cp['rmse']:.4g} | {cp['rel_rmse']:.4g} | "
                           f"{cp['rmse_debiased']:.4g} | {_fmt(t, 3)} | {speed} |")
            out.append("")
            for r in done:
                lines = _stats_lines(r["stats"], r["checkpoints"][-1]["seconds"])
                load, cpu = r.get("load_avg_1m"), r.get("cpu_per_wall")
                cpus = machine.get("cpus_usable") or 1
                threads = r.get("settings", {}).get("threads") or cpus
                if load:
                    lines.append(f"load average (1 min) before/after: {load[0]:.2f} / "
                                 f"{load[1]:.2f}")
                if cpu is not None:
                    starved = cpu < 0.8 * min(threads, cpus)
                    lines.append(f"CPU seconds per step second: {cpu:.2f} of {min(threads, cpus)}"
                                 + (" — **the run got less CPU than it asked for (other work "
                                    "on the machine?): times are skewed**" if starved else ""))
                if lines:
                    out += [f"Session.stats, {r['integrator']}:", ""]
                    out += [f"- {line}" for line in lines] + [""]
        for r in skipped:
            out += [f"- skipped {r['integrator'] or 'scene'}: {r['skipped']}"]
        if skipped:
            out.append("")
    out += ["## Machine", ""]
    for key in ("date", "cpu", "cpu_count", "cpus_usable", "threads_setting", "os", "python",
                "numpy", "lantern", "build_info", "embree", "git_commit", "git_dirty",
                "load_avg_1m"):
        out.append(f"- {key}: {machine.get(key)}")
    out += ["", "Times are `Session.step()` wall seconds only (no RMSE, no image read-back); "
            "setup is Session construction (scene conversion, BVH). RMSE − floor is "
            "sqrt(max(RMSE² − floor², 0)): the error left after removing the reference's own "
            "noise (independent of the run's).", ""]
    return "\n".join(out)
