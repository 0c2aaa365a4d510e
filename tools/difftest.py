"""Differential tester: random Blender scenes (tools/difftest_scene.py) rendered by Lantern
(through the add-on's export, as tests/cycles does) and by Cycles at matched settings, each
with K independent seeds, compared by the project's agreement test
(lantern.metrics.compare_renders: 8x8 block means and the image mean, tolerance from both
sides' noise, Bonferroni at alpha). A case that differs is rendered again with other seeds and
twice the samples (a confirmation, so that one unlucky comparison in a long run is not
reported), then shrunk: lights, objects, materials, shader links, input values and properties
are dropped or reset to Blender's defaults one at a time while the disagreement persists
(tools/difftest_shrink.py). The minimal case is saved as DIR/<name>.blend and .json, and a
one-line command that reproduces it is printed. docs/difftest.md lists what it has found.

Matched settings: Cycles CPU, no denoising, no adaptive sampling, no clamping, light threshold
0, Filter Glossy 0, every bounce limit B; Lantern max_depth B + 2 (render_compare.
lantern_depth); Blackman-Harris 1.5 px on both; one thread per render on both sides.

    nice .venv/bin/python tools/difftest.py --seed 0 --cases 50 --out /tmp/difftest
        [--profile full|ci] [--seeds 16] [--spp 16] [--integrator pt] [--minutes M]
        [--no-shrink] [--size 32]
    .venv/bin/python tools/difftest.py --blend DIR/case.blend     # replay a saved case
    .venv/bin/python tools/difftest.py --case DIR/case.json       # rebuild and replay
        [--blend-out DIR2]                                         # ... and save its .blend
    nice .venv/bin/python tools/difftest.py --avoid-known --allow "two lights" --resume \
        --until 07:38 --cases 1000 --out bench/results/DATE-difftest   # the long run

A run appends one line per case to DIR/log.jsonl and rewrites DIR/summary.json after each;
--resume skips the seeds already in the log (same profile and settings), so a run stopped by
--until or --minutes continues where it stopped. docs/difftest.md: profiles, statistics and
what the tester has found."""

import argparse
import glob
import json
import os
import sys
import tempfile
import time
from dataclasses import asdict, dataclass

import numpy as np

TOOLS = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(TOOLS)
sys.path.insert(0, TOOLS)
_SRC = os.path.join(ROOT, "python")   # the checkout's lantern when it has its own native core
if glob.glob(os.path.join(_SRC, "lantern", "_core*")) and _SRC not in sys.path:
    sys.path.insert(0, _SRC)          # (as tests/cycles/conftest.py does)
import difftest_build as db  # noqa: E402
import difftest_features as df  # noqa: E402
import difftest_known as dk  # noqa: E402
import difftest_scene as ds  # noqa: E402
import difftest_shrink  # noqa: E402

ALPHA = 1e-3
# the shrinker's test: stricter, so that a step that loses the disagreement is not kept on a
# false alarm (one in 1e3 comparisons at ALPHA, over a hundred steps) and the case does not
# drift to noise (seen before: a case shrunk on ALPHA agreed at the end, z 9.9 of 10.0)
SHRINK_ALPHA = 1e-6
# ... which at the run's own samples kept no edit of a real disagreement of z 8-9 (ci seed 6:
# 0 of 30 kept): the shrinker renders with this many times the samples, so that a
# disagreement's z doubles while the false-alarm rate stays SHRINK_ALPHA
SHRINK_SPP_FACTOR = 4
BLOCK = 8
GAIN = 0.05          # the negative control: Lantern's image x (1 +- GAIN) must be flagged
BLACK = 1e-7         # image means under this on both sides: nothing to compare

@dataclass
class Settings:
    seeds: int = 16          # K independent renders a side
    spp: int = 16            # Lantern samples per seed
    cycles_spp: int = 16     # Cycles samples per seed
    integrator: str = "pt"
    threads: int = 1
    alpha: float = ALPHA


def known_tags(case):
    """The known disagreements (difftest_known.KNOWN) a case has."""
    return sorted(dk.tags(case))


# tags about noise, not about the image's expectation: they cannot explain a failed
# agreement test (whose tolerance is each side's own measured noise)
NOISE_ONLY = {"two lights"}


def explaining_tags(case):
    """The known tags of a case that could explain a disagreement (not NOISE_ONLY)."""
    return dk.tags(case) - NOISE_ONLY


# ---- rendering ----

def cycles_settings(sc, seed, spp, bounces, threads):
    """render_compare.cycles_settings with the tester's choices: Lantern has no transparency
    limit (alpha and Transparent BSDF passes are not bounces), so Cycles' own must not bind (at
    B = 0 a Transparent sphere rendered black in Cycles): 64; the film filter 1.5; fixed
    threads."""
    import render_compare as rc
    rc.cycles_settings(sc, seed, spp, bounces, transparent_bounces=64, threads=threads,
                       filter_size=1.5)


def render_cycles(bounces, seeds, spp, threads):
    """K Cycles renders of the current scene (seeds in `seeds`), float64 (H, W, 3) each."""
    import bpy
    import lantern_bpy
    sc = bpy.context.scene
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        for seed in seeds:
            cycles_settings(sc, seed, spp, bounces, threads)
            sc.render.filepath = os.path.join(tmp, f"c{seed}.exr")
            bpy.ops.render.render(write_still=True)
            out.append(lantern_bpy.read_image_bpy(sc.render.filepath).astype(np.float64))
    return out


def stored_cycles(path, case, scene, bounces, seeds, spp, threads):
    """Cycles' renders of the current scene as per-seed block means (lantern.blocks.SeedBlocks),
    stored at `path` (lantern.testing.refs; tests/README.md, "Stored references") and rendered
    again only when their key changes: the case, the scene as the add-on exports it (order-free,
    refs.order_free), the bounces, seeds and samples, the bpy version and the files that build
    the scene and set Cycles up (difftest_build.py, difftest_scene.py, this file,
    render_compare.py). The tests' CI slice renders only Lantern's side live."""
    import bpy
    from lantern.testing import refs
    key = dict(case=json.dumps(case, sort_keys=True), scene=refs.order_free(scene),
               bounces=bounces, seeds=list(seeds), spp=spp, threads=threads,
               bpy=bpy.app.version_string,
               sources=[refs.file_digest(os.path.join(TOOLS, f)) for f in (
                   "difftest_build.py", "difftest_scene.py", "difftest.py",
                   "render_compare.py")])
    return refs.reference_blocks(path, lambda: render_cycles(bounces, seeds, spp, threads), key,
                                 block=BLOCK)


def export_lantern():
    """(lantern.Scene, export warnings) of the current bpy scene, through the add-on."""
    import bpy
    import lantern_bpy
    lantern_bpy.load_addon()
    from lantern_blender.export import export_scene
    scene, report = export_scene(bpy.context.evaluated_depsgraph_get())
    return scene, list(report.messages)


def session_warnings(scene, bounces, integrator):
    """What a Lantern session of the scene warns of (the core's own unsupported features, e.g.
    a moving emitter left still: native/src/scene/motion_build.cpp), which the add-on's export
    does not see; a case with any is unsupported, as one the export warns of."""
    import lantern
    from render_compare import lantern_depth
    return list(lantern.Session(scene, integrator=integrator, backend="cpu",
                                max_depth=lantern_depth(bounces), seed=1, threads=1).warnings)


def render_lantern(scene, bounces, seeds, spp, integrator, threads):
    import lantern
    from render_compare import lantern_depth
    out = []
    for seed in seeds:
        s = lantern.Session(scene, integrator=integrator, backend="cpu",
                            max_depth=lantern_depth(bounces), seed=seed,
                            spp_per_iteration=spp, threads=threads)
        while s.spp < spp:
            s.step()
        out.append(np.asarray(s.image(), np.float64)[..., :3])
    return out


@dataclass
class Result:
    status: str             # agree, differ, black, nonfinite, unsupported
    mean_rel: list = None   # Lantern / Cycles - 1, image mean per channel
    worst_z: float = 0.0
    worst_excess: float = 0.0   # the worst block's z beyond the agreement test's bias cap
    threshold: float = 0.0
    worst_block: list = None
    worst_block_rel: float = 0.0
    detects: float = 0.0    # the smallest whole-image bias flagged with 99 % power
    gain_flagged: bool = None   # Lantern x (1 +- GAIN) flagged (the negative control)
    text: str = ""
    warnings: list = None
    seconds: float = 0.0

    def line(self):
        if self.status in ("black", "unsupported"):
            return self.status + (f" ({self.warnings[0]})" if self.warnings else "")
        if self.status == "nonfinite":
            return f"nonfinite: {self.text}, {self.seconds:.1f} s"
        mr = ", ".join(f"{x:+.2%}" for x in self.mean_rel or [])
        return (f"{self.status}: image mean [{mr}], worst block z {self.worst_z:.1f}, "
                f"{self.worst_excess:.1f} beyond the 0.2 % cap (threshold "
                f"{self.threshold:.1f}) at {self.worst_block} "
                f"({self.worst_block_rel:+.1%}), detects {self.detects:.1%}, "
                f"{self.seconds:.1f} s")


def compare(lan, cyc, alpha=ALPHA, controls=True):
    """Result of the agreement test on two sets of renders, with the +-GAIN controls."""
    from lantern import metrics as agreement   # compare_renders lives there (agreement.py)
    if not all(np.isfinite(x).all() for x in lan):
        return Result("nonfinite", text="non-finite pixels in Lantern's image")
    from lantern.blocks import SeedBlocks
    cyc_values = cyc.blocks if isinstance(cyc, SeedBlocks) else cyc  # stored: block means
    if not all(np.isfinite(x).all() for x in cyc_values):
        return Result("nonfinite", text="non-finite pixels in Cycles' image")
    ml, mc = float(np.mean(lan)), float(np.mean(cyc_values))
    if abs(ml) < BLACK and abs(mc) < BLACK:
        return Result("black")
    a = agreement.compare_renders(lan, cyc, block=BLOCK, alpha=alpha)
    cmp = a.blocks
    idx = tuple(int(i) for i in cmp.worst_index)
    with np.errstate(divide="ignore", invalid="ignore"):
        rel_block = float(cmp.mean_a[idx] / cmp.mean_b[idx] - 1.0) if cmp.mean_b[idx] else \
            float("inf")
        mean_rel = [float(x) for x in np.where(a.mean_b != 0, a.mean_a / a.mean_b - 1.0,
                                               np.inf)]
    res = Result("agree" if a.passed else "differ", mean_rel=mean_rel,
                 worst_z=float(cmp.worst),
                 worst_excess=float(np.max(np.abs(cmp.z_excess))), threshold=float(cmp.threshold(alpha)),
                 worst_block=list(idx), worst_block_rel=rel_block,
                 detects=float(a.detectable_bias()), text=str(a))
    if controls:
        res.gain_flagged = all(not agreement.compare_renders(
            [x * (1.0 + g) for x in lan], cyc, block=BLOCK, alpha=alpha).passed
            for g in (GAIN, -GAIN))
    return res


def run_case(case, st, base=0, spp_factor=1, mutate=None, controls=True, built=False,
             cycles_store=None):
    """Build (unless `built`), export and render `case` on both sides; a Result. Seeds
    base + 1 .. base + K; `mutate(lantern_scene)` changes Lantern's side (negative controls
    of the tester itself). `cycles_store`: a .npz path where Cycles' side is kept
    (stored_cycles), else Cycles renders live."""
    t0 = time.perf_counter()
    if not built:
        db.build(case)
    scene, warnings = export_lantern()
    warnings = warnings or session_warnings(scene, case["bounces"], st.integrator)
    if warnings:
        return Result("unsupported", warnings=warnings, seconds=time.perf_counter() - t0)
    seeds = [base + 1 + k for k in range(st.seeds)]
    cycles_spp = st.cycles_spp * spp_factor
    cyc = (stored_cycles(cycles_store, case, scene, case["bounces"], seeds, cycles_spp,
                         st.threads) if cycles_store
           else render_cycles(case["bounces"], seeds, cycles_spp, st.threads))
    if mutate is not None:
        mutate(scene)
    lan = render_lantern(scene, case["bounces"], seeds, st.spp * spp_factor, st.integrator,
                         st.threads)
    res = compare(lan, cyc, st.alpha, controls)
    res.warnings = warnings
    res.seconds = time.perf_counter() - t0
    return res


# ---- saving and replaying ----

def save_case(case, st, out_dir, name, info=None):
    """DIR/name.json (the case, settings, what was found) and DIR/name.blend (the scene,
    settings in its scene["difftest"]); returns the command line that replays it."""
    import bpy
    os.makedirs(out_dir, exist_ok=True)
    jpath = os.path.join(out_dir, name + ".json")
    bpath = os.path.join(out_dir, name + ".blend")
    with open(jpath, "w") as f:
        json.dump({"case": case, "settings": asdict(st), "info": info or {}}, f, indent=1)
        f.write("\n")
    sc = db.build(case)
    sc["difftest"] = json.dumps({"settings": asdict(st), "bounces": case["bounces"]})
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(bpath), copy=True, compress=True)
    return (f"nice {sys.executable} {os.path.relpath(os.path.join(TOOLS, 'difftest.py'))} "
            f"--blend {bpath}")


def replay_blend(path, base=0, spp_factor=1):
    import bpy
    bpy.ops.wm.open_mainfile(filepath=os.path.abspath(path))
    meta = json.loads(bpy.context.scene["difftest"])
    st = Settings(**meta["settings"])
    case = {"bounces": meta["bounces"]}
    return run_case(case, st, base=base, spp_factor=spp_factor, built=True), st


# ---- the run ----

def parse(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seed", type=int, default=0, help="first case seed")
    ap.add_argument("--cases", type=int, default=10)
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "difftest"))
    ap.add_argument("--profile", default="full", choices=("full", "ci"))
    ap.add_argument("--size", type=int, default=None, help="pixels a side (full 32, ci 24)")
    ap.add_argument("--seeds", type=int, default=16)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--cycles-spp", type=int, default=None)
    ap.add_argument("--integrator", default="pt", choices=("pt", "bdpt", "lvc", "cis"))
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--minutes", type=float, default=None, help="stop starting cases after")
    ap.add_argument("--until", metavar="HH:MM", default=None,
                    help="a deadline (UTC, today): no case starts and no shrink step runs "
                    "after it")
    ap.add_argument("--resume", action="store_true",
                    help="continue the run logged in --out: seeds already in its log.jsonl "
                    "are skipped (so --seed S --cases N, run again, reaches N cases in all)")
    ap.add_argument("--no-shrink", action="store_true")
    ap.add_argument("--recheck-blind", action="store_true",
                    help="render a case that agrees but whose noise hides a 5 %% gain again "
                    "at 4x the samples (seeds 101..), and judge it by that")
    ap.add_argument("--max-evals", type=int, default=150, help="shrink budget (renders of "
                    "the case on both sides)")
    ap.add_argument("--shrink-spp-factor", type=int, default=SHRINK_SPP_FACTOR,
                    help="samples of a shrink step, times --spp (default %(default)s)")
    ap.add_argument("--avoid", action="append", default=[], metavar="TAG",
                    help="draw no case with this known tag (difftest_known.KNOWN) or feature "
                         "(difftest_features.FEATURES)")
    ap.add_argument("--avoid-known", action="store_true", help="avoid every known tag")
    ap.add_argument("--allow", action="append", default=[], metavar="TAG",
                    help="with --avoid-known: draw cases with this tag all the same")
    ap.add_argument("--blend", help="replay a saved .blend (its settings inside)")
    ap.add_argument("--case", nargs="+", help="rebuild and replay saved .json cases")
    ap.add_argument("--blend-out", metavar="DIR", help="with --case: also save each case as "
                    "DIR/<name>.blend (replay it with --blend)")
    return ap.parse_args(argv)


def _log(out_dir, entry):
    os.makedirs(out_dir, exist_ok=True)
    with open(os.path.join(out_dir, "log.jsonl"), "a") as f:
        f.write(json.dumps(entry) + "\n")


def investigate(case, st, out_dir, max_evals, shrink=True, mutate=None, say=print,
                deadline=None, shrink_spp_factor=SHRINK_SPP_FACTOR):
    """A case that differed: confirm with other seeds and twice the samples, shrink (a case
    with a known tag is not shrunk: it is counted as known), save. Returns the info dict
    (also in the saved .json)."""
    name = f"case-{case['profile']}-{case['seed']}"
    conf = run_case(case, st, base=1000, spp_factor=2, mutate=mutate, controls=False)
    say(f"  confirm (seeds 1001.., 2x spp): {conf.line()}")
    info = {"first": None, "confirm": asdict(conf), "tags": known_tags(case),
            "describe": ds.describe(case)}
    if conf.status not in ("differ", "nonfinite"):
        info["verdict"] = "not confirmed"
        return info
    info["class"] = "known" if explaining_tags(case) else "new"
    if info["class"] == "known":
        say(f"  confirmed; known tags {sorted(explaining_tags(case))}: not shrunk")
        info["verdict"] = "confirmed (known tag)"
        return info
    small = case
    if shrink and deadline is not None and time.time() > deadline:
        say("  past the deadline: not shrunk")
        shrink = False
    if shrink:
        strict = Settings(**dict(asdict(st), alpha=SHRINK_ALPHA))
        own = dk.tags(case)

        def fails(c):   # an edit that adds a known disagreement would drift into it
            return not (dk.tags(c) - own) and run_case(
                c, strict, base=2000, spp_factor=shrink_spp_factor, mutate=mutate,
                controls=False).status in (
                    "differ", "nonfinite")
        small, trail = difftest_shrink.shrink(
            case, fails,
            max_evals=max_evals, say=say, deadline=deadline)
        info["shrink_steps"] = trail
    final = run_case(small, st, base=3000, spp_factor=2, mutate=mutate, controls=False)
    say(f"  shrunk: {ds.describe(small)}")
    say(f"  shrunk, fresh seeds 3001.., 2x spp: {final.line()}")
    info.update(verdict="confirmed" if final.status in ("differ", "nonfinite") else
                "shrunk case not confirmed", shrunk=asdict(final),
                shrunk_tags=known_tags(small), shrunk_describe=ds.describe(small))
    cmd = save_case(small, st, out_dir, name, info)
    save_case(case, st, out_dir, name + "-original", info)
    info["command"] = cmd
    say(f"  reproduce: {cmd}")
    return info


def main(argv=None):
    args = parse(argv)
    import lantern
    if not lantern.native_available():
        sys.exit(f"lantern native core unavailable: {lantern.native_error()}")
    if args.blend:
        res, st = replay_blend(args.blend)
        print(res.line())
        print(res.text)
        return 0 if res.status == "agree" else 1
    if args.case:
        worst = 0
        for path in args.case:
            with open(path) as f:
                doc = json.load(f)
            st = Settings(**doc["settings"])
            if args.blend_out:
                name = os.path.splitext(os.path.basename(path))[0]
                print(save_case(doc["case"], st, args.blend_out, name, doc.get("info") or
                                {k: doc[k] for k in ("why", "found") if k in doc}))
            res = run_case(doc["case"], st, controls=False)
            print(f"{path}: {ds.describe(doc['case'])}\n  {res.line()}", flush=True)
            if len(args.case) == 1:
                print(res.text)
            worst = max(worst, res.status != "agree")
        return worst
    st = Settings(seeds=args.seeds, spp=args.spp, cycles_spp=args.cycles_spp or args.spp,
                  integrator=args.integrator, threads=args.threads)
    deadline = None
    if args.until:
        import datetime
        hh, mm = (int(x) for x in args.until.split(":"))
        now = datetime.datetime.now(datetime.timezone.utc)
        deadline = now.replace(hour=hh, minute=mm, second=0, microsecond=0).timestamp()
    avoid = set(args.avoid) | (set(dk.KNOWN) - set(args.allow) if args.avoid_known else set())
    run = {"profile": args.profile, "size": args.size, "settings": asdict(st),
           "avoid": sorted(avoid), "command": " ".join([os.path.relpath(__file__)] +
                                                       (argv or sys.argv[1:]))}
    done = set()
    if args.resume:
        for e in read_log(args.out):
            if e.get("profile") == args.profile and e.get("settings", asdict(st)) == asdict(st):
                done.add(e["seed"])
    t_start = time.perf_counter()
    counts = {}
    print(f"lantern {lantern.__file__}; settings {asdict(st)}; avoid {sorted(avoid)}"
          + (f"; resuming, {len(done)} cases in the log" if done else ""), flush=True)
    # --cases counts the run's cases, the log's included: a resumed run stops at N in all
    seed, ran = args.seed - 1, len(done)
    if ran >= args.cases:
        print(f"the log holds {ran} cases, --cases {args.cases}: nothing to run")
    while ran < args.cases:
        seed += 1
        if seed in done:
            continue
        if args.minutes and time.perf_counter() - t_start > 60 * args.minutes:
            print(f"time limit: stopped at {ran} cases")
            break
        if deadline is not None and time.time() > deadline:
            print(f"deadline {args.until} UTC: stopped at {ran} cases")
            break
        ran += 1
        case = ds.generate(seed, args.profile, args.size, avoid)
        res = run_case(case, st)
        counts[res.status] = counts.get(res.status, 0) + 1
        print(f"[{seed}] {ds.describe(case)}\n  {res.line()}", flush=True)
        entry = {"seed": seed, "profile": args.profile, "settings": asdict(st),
                 "avoid": sorted(avoid), "describe": ds.describe(case),
                 "result": asdict(res), "tags": known_tags(case),
                 "features": sorted(df.features(case))}
        if args.recheck_blind and res.status == "agree" and res.gain_flagged is False:
            # too noisy to see a 5 % gain: once more at 4x the samples (as the CI slice does)
            res = run_case(case, st, base=100, spp_factor=4)
            print(f"  at 4x spp (the first could not see 5 %): {res.line()}", flush=True)
            entry["recheck"] = asdict(res)
        if res.status in ("differ", "nonfinite"):
            entry["investigation"] = investigate(case, st, args.out, args.max_evals,
                                                 shrink=not args.no_shrink, deadline=deadline,
                                                 shrink_spp_factor=args.shrink_spp_factor)
        _log(args.out, entry)
        write_summary(args.out, run)
    wall = time.perf_counter() - t_start
    print(f"done in {wall / 60:.1f} min: " + ", ".join(f"{k} {v}" for k, v in
                                                     sorted(counts.items())))
    return 0


def read_log(out_dir):
    path = os.path.join(out_dir, "log.jsonl")
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return [json.loads(line) for line in f if line.strip()]


def classify(entry):
    """agree | black | unsupported | not confirmed | known | new (a confirmed disagreement
    with no known tag that explains it)."""
    status = entry.get("recheck", entry["result"])["status"]
    if status not in ("differ", "nonfinite"):
        return status
    inv = entry.get("investigation", {})
    if inv.get("verdict") == "not confirmed":
        return "not confirmed"
    return inv.get("class", "new")


def _quantiles(xs):
    """Median, 90th percentile and maximum (or None) of a list of numbers; the infinite ones
    (a comparison with no resolution at all) are counted, and ranked above the rest."""
    if not xs:
        return None
    xs = np.asarray(xs, float)
    fin = np.isfinite(xs)
    big = np.where(fin, xs, np.finfo(float).max)
    out = {"median": float(np.percentile(big, 50, method="higher")),
           "p90": float(np.percentile(big, 90, method="higher")),
           "max_finite": float(xs[fin].max()) if fin.any() else None,
           "infinite": int((~fin).sum())}
    return {k: (None if isinstance(v, float) and v >= np.finfo(float).max else v)
            for k, v in out.items()}


def write_summary(out_dir, run):
    """DIR/summary.json from the whole log (every session that appended to it)."""
    log = read_log(out_dir)
    counts, new, known, secs = {}, [], [], []
    for e in log:
        k = classify(e)
        counts[k] = counts.get(k, 0) + 1
        secs.append(e["result"]["seconds"])
        inv = e.get("investigation", {})
        item = {"seed": e["seed"], "profile": e["profile"], "describe": e["describe"],
                "first": e["result"]["status"], "tags": e["tags"]}
        if k == "new":
            name = f"case-{e['profile']}-{e['seed']}"
            item.update(verdict=inv.get("verdict"), shrunk=inv.get("shrunk_describe"),
                        command=inv.get("command"),
                        files=[name + ".json", name + ".blend"] if inv.get("command") else [])
            # a tag added to KNOWN since (the finding, recorded): today's tags of the case
            orig = os.path.join(out_dir, name + "-original.json")
            if os.path.exists(orig):
                with open(orig) as f:
                    item["known_now"] = sorted(explaining_tags(json.load(f)["case"]))
            new.append(item)
        elif k == "known":
            known.append(item)
    # agreeing cases whose noise would not show Lantern's image x 1.05 / x 0.95 (weak)
    blind = [e["seed"] for e in log if e.get("recheck", e["result"])["status"] == "agree" and
             e.get("recheck", e["result"]).get("gain_flagged") is False]
    by_feature = {}   # difftest_features.FEATURES: cases drawn with each, by class
    for e in log:
        for t in e.get("features", []):
            d = by_feature.setdefault(t, {})
            d[classify(e)] = d.get(classify(e), 0) + 1
    summary = {"run": run, "cases": len(log), "counts": counts, "features": by_feature,
               "agree_but_blind_to_5_percent": {"count": len(blind), "seeds": blind},
               "seeds": [min((e["seed"] for e in log), default=None),
                         max((e["seed"] for e in log), default=None)],
               "detects_whole_image_bias": _quantiles(
                   [e.get("recheck", e["result"])["detects"] for e in log
                    if e.get("recheck", e["result"])["status"] == "agree"]),
               "seconds_per_case_first_render": {
                   "mean": float(np.mean(secs)) if secs else None,
                   "median": float(np.median(secs)) if secs else None},
               "new": new, "known": known,
               "updated": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}
    with open(os.path.join(out_dir, "summary.json"), "w") as f:
        json.dump(summary, f, indent=1)
        f.write("\n")
    return summary


if __name__ == "__main__":
    sys.exit(main())
