"""Speed against error (DESIGN.md): render each benchmark scene with each integrator until a time
or sample budget is spent, scoring RMSE against a converged reference at log-spaced sample
counts; write results.csv, one RMSE-vs-spp/time plot per scene, table.md and the machine.

Run: .venv/bin/python bench/rmse.py --scenes cornell --integrators pt --res 128x128 --time 20
     .venv/bin/python bench/rmse.py --quick          (64x64, 2 s per run: a smoke test)
See bench/README.md for what the numbers mean."""

import argparse
import math
import os
import shlex
import sys
import time
from datetime import date
from pathlib import Path

import numpy as np

BENCH = Path(__file__).resolve().parent
ROOT = BENCH.parent
sys.path.insert(0, str(BENCH))

import bench_scenes  # noqa: E402
import rmse_cycles  # noqa: E402
import rmse_reference  # noqa: E402
import rmse_report  # noqa: E402


def import_lantern():
    """lantern from this checkout (python/lantern: the newest scenes), borrowing the installed
    native module when the checkout has none (as tests/python/conftest.py does)."""
    import importlib.util
    src = ROOT / "python"
    spec = importlib.util.find_spec("lantern")
    installed = Path(list(spec.submodule_search_locations)[0]) if spec else None
    if str(src) not in sys.path:
        sys.path.insert(0, str(src))
    import lantern
    import lantern.metrics
    import lantern.scenes
    import lantern.session
    here = src / "lantern"
    has_core = bool(list(here.glob("_core*")))
    if installed and installed.resolve() != here.resolve() and not has_core:
        lantern.__path__.append(str(installed))
    return lantern


# ---- progress ----

class Progress:
    """One line on stderr, redrawn in place on a terminal; elsewhere a line per 10 %."""

    def __init__(self, label, enabled=True, stream=sys.stderr):
        self.label, self.enabled, self.stream = label, enabled, stream
        self.tty = stream.isatty()
        self.last_draw, self.last_decile = 0.0, -1

    def update(self, frac, text=""):
        if not self.enabled:
            return
        frac = min(max(frac, 0.0), 1.0)
        now = time.monotonic()
        if self.tty:
            if now - self.last_draw < 0.1 and frac < 1.0:
                return
            n = int(frac * 30)
            self.stream.write(f"\r{self.label:<16} [{'#' * n}{'.' * (30 - n)}] "
                              f"{100 * frac:3.0f}% {text}\033[K")
        else:
            decile = int(frac * 10)
            if decile == self.last_decile:
                return
            self.last_decile = decile
            self.stream.write(f"{self.label:<16} {100 * frac:3.0f}% {text}\n")
        self.last_draw = now
        self.stream.flush()

    def close(self):
        if self.enabled and self.tty:
            self.stream.write("\n")
            self.stream.flush()


# ---- one run ----

def next_checkpoint(spp, per_octave):
    """The smallest integer sample count above `spp` on the grid 2^(k / per_octave)."""
    k = math.floor(math.log2(max(spp, 1)) * per_octave + 1e-9) + 1
    while (c := int(round(2 ** (k / per_octave)))) <= spp:
        k += 1
    return c


VARIANTS = {"sort": {"sort": True}, "nosort": {"sort": False}, "bsdf": {"cis_target": "bsdf"}}


def integrator_variant(label):
    """'cis' -> ('cis', {}); 'cis-nosort' -> ('cis', {'sort': False}); suffixes: -sort,
    -nosort, -bsdf (the paper's BSDF-product target), -nN (N connections), -mM (M candidates)."""
    name, *suffixes = label.split("-")
    settings = {}
    for suffix in suffixes:
        if suffix in VARIANTS:
            settings.update(VARIANTS[suffix])
        elif suffix[:1] == "n" and suffix[1:].isdigit():
            settings["connections"] = int(suffix[1:])
        elif suffix[:1] == "m" and suffix[1:].isdigit():
            settings["candidates"] = int(suffix[1:])
        else:
            raise ValueError(f"integrator variant {label!r}: unknown suffix {suffix!r} "
                             f"(sort, nosort, bsdf, nN, mM)")
    return name, settings


def run_one(lantern, session, setup_s, scene_name, integrator, ref, args):
    """Step `session` until the budget is spent, scoring RMSE at log-spaced spp.
    Returns (the run dict, the final image)."""
    ref_img, floor, rel_floor = ref["image"], ref["rmse_floor"], ref["rel_rmse_floor"]
    progress = Progress(f"{scene_name}/{integrator}", args.progress)
    checkpoints, seconds, cpu_s, target_cp = [], 0.0, 0.0, 1
    load_before = os.getloadavg()[0]

    def score():
        img = np.asarray(session.image())
        e = lantern.metrics.rmse(img, ref_img)
        rel = lantern.metrics.relative_rmse(img, ref_img)
        checkpoints.append({
            "spp": session.spp, "seconds": seconds, "rmse": e, "rel_rmse": rel,
            "rmse_debiased": math.sqrt(max(e * e - floor * floor, 0.0)),
            "rel_rmse_debiased": math.sqrt(max(rel * rel - rel_floor * rel_floor, 0.0))})
        return img

    while True:
        before = session.spp
        t, c = time.perf_counter(), time.process_time()
        spp = session.step()
        seconds += time.perf_counter() - t
        cpu_s += time.process_time() - c
        stalled = spp <= before
        done = (stalled or (args.time is not None and seconds >= args.time)
                or (args.spp is not None and spp >= args.spp))
        if spp >= target_cp or done:
            img = score()
            while target_cp <= spp:
                target_cp = next_checkpoint(target_cp, args.checkpoints_per_octave)
        fracs = [seconds / args.time if args.time else 0.0, spp / args.spp if args.spp else 0.0]
        last = checkpoints[-1] if checkpoints else None
        progress.update(max(fracs), f"{seconds:6.1f} s  {spp:6d} spp"
                        + (f"  rmse {last['rmse']:.4g}" if last else ""))
        if done:
            break
    progress.close()
    if stalled:
        print(f"warning: {scene_name}/{integrator}: step() made no progress; stopped")
    return {"scene": scene_name, "integrator": integrator, "setup_s": setup_s,
            "checkpoints": checkpoints, "stats": session.stats, "warnings": session.warnings,
            "settings": session.settings,
            "load_avg_1m": [load_before, os.getloadavg()[0]],
            # process CPU seconds per step second: ~ the cores used (less when others compete)
            "cpu_per_wall": cpu_s / seconds if seconds > 0 else None}, img


# ---- command line ----

def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scenes", default="cornell",
                   help=f"comma list (registered: {', '.join(bench_scenes.SCENES)})")
    p.add_argument("--integrators", default="pt",
                   help="comma list, e.g. pt,lvc,cis,bdpt; variants: cis-nosort, lvc-sort, "
                        "cis-bsdf, cis-n8-m16")
    p.add_argument("--time", type=float, help="step seconds per run (default 10, or none "
                   "when --spp is given)")
    p.add_argument("--spp", type=int, help="samples per pixel per run (with --time: "
                   "whichever comes first)")
    p.add_argument("--res", help="WxH (default 128x128; 64x64 with --quick)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--threads", type=int, default=0, help="0: all cores")
    p.add_argument("--spp-per-iteration", type=int, default=1)
    p.add_argument("--quick", action="store_true", help="tiny: 64x64, 2 s per run, "
                   "1024-spp reference (each overridable)")
    p.add_argument("--out", help="output folder (default bench/results/<date>-<scenes>)")
    p.add_argument("--ref-integrator", default="pt")
    p.add_argument("--ref-spp", type=int, help="total reference spp (default 16384; "
                   "1024 with --quick)")
    p.add_argument("--ref-seeds", type=int, default=8,
                   help=f"independent reference renders (>= {rmse_reference.MIN_SEEDS})")
    p.add_argument("--refs", default=str(BENCH / "refs"), help="reference cache folder")
    p.add_argument("--rebuild-ref", action="store_true", help="ignore cached references")
    p.add_argument("--target-rmse", type=float, help="common RMSE for time-to-target "
                   "(default: the worst final RMSE of the scene's runs)")
    p.add_argument("--checkpoints-per-octave", type=int, default=4)
    p.add_argument("--no-progress", dest="progress", action="store_false")
    args = p.parse_args(argv)

    res = args.res or ("64x64" if args.quick else "128x128")
    try:
        args.width, args.height = (int(v) for v in res.lower().split("x"))
    except ValueError:
        p.error(f"--res must be WxH, got {res!r}")
    if args.time is None and args.spp is None:
        args.time = 2.0 if args.quick else 10.0
    if args.ref_spp is None:
        args.ref_spp = 1024 if args.quick else 16384
    if args.ref_seeds < rmse_reference.MIN_SEEDS:
        p.error(f"--ref-seeds must be >= {rmse_reference.MIN_SEEDS}")
    if (args.time is not None and args.time <= 0) or (args.spp is not None and args.spp < 1):
        p.error("--time must be > 0 and --spp >= 1")
    args.scene_list = [s.strip() for s in args.scenes.split(",") if s.strip()]
    args.integrator_list = [s.strip() for s in args.integrators.split(",") if s.strip()]
    if not args.scene_list or not args.integrator_list:
        p.error("--scenes and --integrators must name at least one each")
    args.out = Path(args.out) if args.out else (
        BENCH / "results" / f"{date.today().isoformat()}-{'+'.join(args.scene_list)}")
    return args


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    args_line = "bench/rmse.py " + shlex.join(sys.argv[1:] if argv is None else argv)
    lantern = import_lantern()
    lantern.session.require_core()
    import lantern.imageio
    args.out.mkdir(parents=True, exist_ok=True)
    machine = rmse_report.machine_info(lantern, args.threads)
    print(f"{machine['cpu']}, {machine['cpus_usable']} cpus, lantern {machine['build_info']}")
    if machine["load_avg_1m"] > 0.5:
        print(f"warning: load average {machine['load_avg_1m']:.2f} before starting: other "
              f"work on this machine slows the runs and skews the times")

    runs, refs = [], {}
    for scene_name in args.scene_list:
        try:
            if scene_name.startswith("blend:"):
                scene = rmse_cycles.build_blend(scene_name[6:], args.width, args.height)
            else:
                scene = bench_scenes.build(scene_name, args.width, args.height)
        except (bench_scenes.SceneUnavailable, KeyError) as e:
            print(f"skipped: {e}")
            runs.append({"scene": scene_name, "integrator": None, "skipped": str(e)})
            continue
        ref_progress = Progress(f"{scene_name}/ref", args.progress)
        ref = rmse_reference.get(
            lantern, scene, scene_name,
            {"integrator": args.ref_integrator, "spp": args.ref_spp, "n_seeds": args.ref_seeds,
             "threads": args.threads, "max_depth": lantern.session.DEFAULT_SETTINGS["max_depth"],
             "avoid_seeds": [args.seed]},
            args.refs, args.rebuild_ref,
            lambda done, total: ref_progress.update(done / total, f"{done}/{total} spp"))
        ref_progress.close()
        refs[scene_name] = ref
        how = f"cached {ref['path']}" if ref["cached"] else f"{ref['wall_s']:.1f} s"
        print(f"reference {scene_name}: {ref['spp']} spp, noise floor RMSE "
              f"{ref['rmse_floor']:.4g} (relative {ref['rel_rmse_floor']:.4g}), {how}")
        scene_runs = []
        for integrator in args.integrator_list:
            if integrator == "cycles":
                if not scene_name.startswith("blend:"):
                    print(f"skipped {scene_name}/cycles: Cycles renders blend:<name> scenes only")
                    runs.append({"scene": scene_name, "integrator": "cycles",
                                 "skipped": "not a blend scene"})
                    continue
                cref = rmse_cycles.reference(scene_name, args.width, args.height, args.ref_spp,
                                             args.ref_seeds, args.refs,
                                             rmse_reference.noise_floor, args.rebuild_ref)
                refs[scene_name + " (Cycles)"] = dict(cref, spp_per_seed=cref["spp"] // cref[
                    "n_seeds"])
                run, img = rmse_cycles.run(lantern, scene_name, cref, args)
                runs.append(run)
                scene_runs.append(run)
                cp = run["checkpoints"][-1]
                print(f"{scene_name}/cycles: {cp['spp']} spp in {cp['seconds']:.2f} s, RMSE "
                      f"{cp['rmse']:.4g} against its own reference")
                lantern.imageio.write_image(args.out / f"image_{scene_name[6:]}_cycles.png", img)
                continue
            start = time.perf_counter()
            try:
                name, variant = integrator_variant(integrator)
                session = lantern.Session(scene, integrator=name, seed=args.seed,
                                          spp_per_iteration=args.spp_per_iteration,
                                          threads=args.threads, **variant)
            except (NotImplementedError, ValueError) as e:  # not implemented / unknown
                print(f"skipped {scene_name}/{integrator}: {type(e).__name__}: {e}")
                runs.append({"scene": scene_name, "integrator": integrator,
                             "skipped": f"{type(e).__name__}: {e}"})
                continue
            run, img = run_one(lantern, session, time.perf_counter() - start, scene_name,
                               integrator, ref, args)
            runs.append(run)
            scene_runs.append(run)
            cp = run["checkpoints"][-1]
            print(f"{scene_name}/{integrator}: {cp['spp']} spp in {cp['seconds']:.2f} s, "
                  f"RMSE {cp['rmse']:.4g}, rel RMSE {cp['rel_rmse']:.4g}")
            print("  stats: " + ", ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}"
                                          for k, v in run["stats"].items()))
            stem = args.out / f"image_{scene_name.replace('blend:', '')}_{integrator}"
            lantern.imageio.write_image(stem.with_suffix(".exr"), img)
            lantern.imageio.write_image(stem.with_suffix(".png"), img)
        lantern.imageio.write_image(
            args.out / f"image_{scene_name.replace('blend:', '')}_ref.png", ref["image"])
        if scene_runs:
            rmse_report.plot_scene(
                args.out / f"rmse_{scene_name.replace('blend:', '')}.png", scene_name, scene_runs, ref,
                f"{scene_name} {args.width}x{args.height}, {machine['cpu']} "
                f"({machine['cpus_usable']} cpus, threads={args.threads})")

    rmse_report.write_csv(args.out / "results.csv", runs)
    rmse_report.write_json(args.out / "machine.json", machine)
    ref_meta = {k: {kk: vv for kk, vv in r.items() if kk not in ("image", "se")}
                for k, r in refs.items()}
    rmse_report.write_json(args.out / "runs.json", {"command": args_line, "runs": runs,
                                                    "references": ref_meta})
    table = rmse_report.table_md(runs, refs, machine, args_line, args.target_rmse)
    (args.out / "table.md").write_text(table)
    print(f"\nwrote {args.out}/: results.csv, table.md, rmse_<scene>.png, machine.json, "
          f"runs.json, image_*.exr/png")
    return 0 if any(r.get("checkpoints") for r in runs) else 1


if __name__ == "__main__":
    sys.exit(main())
