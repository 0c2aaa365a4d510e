"""tools/difftest.py with every integrator (auto and lt as well as pt, bdpt, lvc and cis) and
a choice of features (docs/difftest.md). The same options and log; --integrator's choices
are wider, and --want TAG (repeatable; "new" for every difftest_features3 tag, "new5" for every
difftest_features5 tag, "new6" / "new7" for difftest_features6's / 7's) runs only the
seeds whose case has one of the tags (the others are skipped, not logged), one case at a time
through difftest.main (--resume: each seed once); --and TAG (repeatable): and one of these
too; --integrators a,b,...: each such seed with each integrator in turn, logged in
OUT/<integrator>; --cycles-cache DIR: Cycles' renders of a case kept there and reused (one
Cycles side for all the integrators of a case). A wrapper, not an edit of difftest.py,
whose digest keys the CI slice's stored Cycles side (tests/cycles/test_difftest.py): changing
it would make every stored reference stale. Its verdict adds "inconclusive" (verdict(): a case
that agrees only because the image mean's margin is over INCONCLUSIVE_MARGIN), and its Cycles
side renders without Cycles' Russian roulette (D51; --cycles-roulette keeps it), and a case
flagged as a glossy caustic (glossy_caustic, D59) is confirmed with 8x Cycles' samples
(--no-caustic-guard: as any other).

    nice .venv/bin/python tools/difftest_run.py --integrator lt --profile full --seed 5000 \
        --cases 20 --out bench/results/DATE-difftest3/lt
"""

import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import difftest  # noqa: E402

INTEGRATORS = ("pt", "bdpt", "lvc", "cis", "lt", "auto")
_parse = difftest.parse
_compare = difftest.compare

# A case whose image-mean test passes only because that test allows more than this relative
# difference (heavy-tailed noise: a caustic or a firefly that a few seeds catch; seed 5006 of
# difftest3 passed at -62 % with 217 % allowed) is "inconclusive", not "agree": the summary
# counts it apart and the run says so. The block-weighted test may still be tight there, but
# it weights such blocks down, so the part of the image that is off is the part it cannot see.
INCONCLUSIVE_MARGIN = 0.25


def verdict(res, lan, cyc, alpha=difftest.ALPHA):
    """`res` (difftest.compare's Result) as "inconclusive" where it agrees only within a margin
    over INCONCLUSIVE_MARGIN; the Result, changed in place."""
    if res.status != "agree":
        return res
    from lantern import metrics as agreement
    a = agreement.compare_renders(lan, cyc, block=difftest.BLOCK, alpha=alpha)
    allowed = float(np.max(a.mean_allowed[0]))
    if allowed > INCONCLUSIVE_MARGIN:
        res.status = "inconclusive"
        res.text = (f"inconclusive: the image mean's margin is {allowed:.0%} (over "
                    f"{INCONCLUSIVE_MARGIN:.0%}: heavy-tailed noise); " + res.text)
    return res


def compare(lan, cyc, alpha=difftest.ALPHA, controls=True):
    """difftest.compare, then verdict()."""
    return verdict(_compare(lan, cyc, alpha, controls), lan, cyc, alpha)


def parse(argv):
    """difftest.parse, --integrator taking any of INTEGRATORS."""
    argv = list(sys.argv[1:] if argv is None else argv)
    chosen = None
    for i, a in enumerate(argv):
        if a == "--integrator" and i + 1 < len(argv):
            chosen, argv[i + 1] = argv[i + 1], "pt"
        elif a.startswith("--integrator="):
            chosen, argv[i] = a.split("=", 1)[1], "--integrator=pt"
    if chosen is not None and chosen not in INTEGRATORS:
        sys.exit(f"--integrator {chosen}: one of {', '.join(INTEGRATORS)}")
    args = _parse(argv)
    if chosen is not None:
        args.integrator = chosen
    return args


# Cycles' own Russian roulette drops the light of a lamp or of the world that a bounce ray
# reaches inside a volume (D51, docs/difftest.md; tests/cycles/test_fog_lamp_roulette.py): in a
# volume a lamp hit or a miss is tested for roulette before the volume is shaded, a path ended
# there adds nothing and one that goes on is not divided by its survival probability. Min Light
# (and Transparent) Bounces at the bounce counts turn that roulette off, which changes nothing
# else in expectation: the tester's Cycles side renders so unless --cycles-roulette. Live
# renders only: difftest.stored_cycles' key (the CI slice) does not see it.
CYCLES_ROULETTE = False
_cycles_settings = difftest.cycles_settings


def cycles_settings(sc, seed, spp, bounces, threads):
    """difftest.cycles_settings, then (unless CYCLES_ROULETTE) Cycles' roulette off."""
    _cycles_settings(sc, seed, spp, bounces, threads)
    if not CYCLES_ROULETTE:
        sc.cycles.min_light_bounces = bounces
        sc.cycles.min_transparent_bounces = sc.cycles.transparent_max_bounces


# Cycles' side of a case kept on disk (--cycles-cache DIR): one case rendered with several
# integrators (--integrators) or confirmed for two of them renders Cycles once. Cycles with a
# fixed seed is deterministic, and its scene is built from the case alone
# (difftest_build.build), so the key is the case, what render_cycles is given, the roulette
# setting and the files that build the scene and set Cycles up. Live renders only, as above.
CYCLES_CACHE = None
_CASE = None
_run_case = difftest.run_case
_render_cycles = difftest.render_cycles
_SOURCES = ("difftest.py", "difftest_build.py", "difftest_scene.py", "difftest_graph.py",
            "difftest_features.py", "difftest_features2.py", "difftest_features3.py",
            "difftest_features4.py", "difftest_features5.py", "difftest_features6.py",
            "difftest_features7.py",
            "render_compare.py")


def run_case(case, st, *args, **kwargs):
    """difftest.run_case, the case kept for render_cycles' cache key."""
    global _CASE
    _CASE = case
    try:
        return _run_case(case, st, *args, **kwargs)
    finally:
        _CASE = None


def cycles_key(case, bounces, seeds, spp, threads):
    """The cache's key (hex) of Cycles' renders of `case`."""
    import hashlib
    import json
    import bpy
    h = hashlib.sha256()
    for f in _SOURCES:
        with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), f), "rb") as fh:
            h.update(hashlib.sha256(fh.read()).digest())
    h.update(json.dumps(dict(case=case, bounces=bounces, seeds=list(seeds), spp=spp,
                             threads=threads, roulette=CYCLES_ROULETTE,
                             bpy=bpy.app.version_string), sort_keys=True).encode())
    return h.hexdigest()


def render_cycles(bounces, seeds, spp, threads):
    """difftest.render_cycles, read from CYCLES_CACHE where it holds the case's renders."""
    if CYCLES_CACHE is None or _CASE is None:
        return _render_cycles(bounces, seeds, spp, threads)
    path = os.path.join(CYCLES_CACHE, cycles_key(_CASE, bounces, seeds, spp, threads) + ".npz")
    if os.path.exists(path):
        with np.load(path) as z:
            print(f"  (Cycles' side from the cache: {os.path.basename(path)[:12]})", flush=True)
            return [np.asarray(x, np.float64) for x in z["images"]]
    out = _render_cycles(bounces, seeds, spp, threads)
    os.makedirs(CYCLES_CACHE, exist_ok=True)
    tmp = path + f".{os.getpid()}.tmp.npz"
    np.savez_compressed(tmp, images=np.stack(out))
    os.replace(tmp, path)
    return out


# A view-dependent graph (Incoming, Reflection, Fresnel, Layer Weight, Camera, ...: the
# generator's difftest_graph.VIEW_DEPENDENT sources and nodes) on a surface: at a light
# sub-path's vertex the view is where the light came from, so bdpt, lvc, cis, lt (and auto's
# cis) differ from pt and Cycles there by design (docs/nodes.md). A tag of this wrapper's, for
# runs of those integrators only (difftest7's 41028: a floor's Base Color = Geometry Incoming,
# bdpt +6 %, pt agrees), and not in difftest_known.KNOWN (the ci profile draws such graphs:
# a KNOWN tag would redraw the CI slice's scenes). --avoid it to leave such cases out.
VIEW_TAG = "view-dependent graph (bidirectional)"
_dk_tags = difftest.dk.tags


def view_dependent(case):
    """Whether a surface material's graph reads a view-dependent source or node."""
    import difftest_graph as dg
    for g in case["materials"].values():
        nodes = g.get("nodes", {})
        if any(n["type"] in dg.VIEW_DEPENDENT_NODES for n in nodes.values()):
            return True
        for link in g.get("links", []):
            if link[0] in nodes and (nodes[link[0]]["type"], link[1]) in dg.VIEW_DEPENDENT:
                return True
    return False


def tags(case):
    """difftest_known.tags, and VIEW_TAG where a run's integrator is not pt (BIDIR)."""
    found = _dk_tags(case)
    if BIDIR and view_dependent(case):
        found.add(VIEW_TAG)
    return found


BIDIR = False
_investigate = difftest.investigate


def investigate(case, st, out_dir, max_evals, shrink=True, mutate=None, say=print, **kwargs):
    """difftest.investigate; with --no-shrink only its confirmation, and the case saved as
    drawn (difftest.investigate renders the unshrunk case a third time, at seeds 3001..)."""
    from dataclasses import asdict
    caustic = caustic_confirm(case, st, mutate, say)
    if caustic is not None and caustic.status not in ("differ", "nonfinite"):
        return {"first": None, "confirm": asdict(caustic), "tags": difftest.known_tags(case),
                "describe": difftest.ds.describe(case),
                "verdict": "not confirmed", "glossy_caustic": True}
    if shrink:
        return _investigate(case, st, out_dir, max_evals, shrink, mutate, say, **kwargs)
    conf = caustic or run_case(case, st, base=1000, spp_factor=2, mutate=mutate,
                               controls=False)
    if caustic is None:
        say(f"  confirm (seeds 1001.., 2x spp): {conf.line()}")
    info = {"first": None, "confirm": asdict(conf), "tags": difftest.known_tags(case),
            "describe": difftest.ds.describe(case)}
    if conf.status not in ("differ", "nonfinite"):
        info["verdict"] = "not confirmed"
        return info
    info["class"] = "known" if difftest.explaining_tags(case) else "new"
    info["verdict"] = ("confirmed (known tag)" if info["class"] == "known" else
                       "confirmed (not shrunk)")
    info["command"] = difftest.save_case(case, st, out_dir, f"case-{case['profile']}-"
                                         f"{case['seed']}-original", info)
    say(f"  {info['verdict']}; reproduce: {info['command']}")
    return info


# A glossy caustic (D59, docs/difftest.md): a small lamp seen through a rough-glossy bounce off
# a surface, which a path tracer finds only where a bounce happens to land in the lobe's peak
# towards the lamp. At 16 x 16 spp Cycles' (and pt's) image of it is heavy-tailed: the few
# seeds that catch it read under the mean, and their spread under the spread, so bdpt / lvc /
# cis / lt, which carry such light well, were called brighter (difftest7's 40085: +8.8 % on a
# block, z 12-25; Cycles 0.00230 at 16 spp, 0.00246 at 2,048, bdpt 0.00254). The guard: a case
# with such a pair (glossy_caustic) is confirmed with Cycles at CAUSTIC_CYCLES_FACTOR times the
# confirmation's samples (Lantern's as usual); agreeing there, it is "not confirmed (glossy
# caustic)" (the log's verdict "not confirmed", glossy_caustic true). A bias still shows: the check is tighter on Cycles' side, not looser.
# --no-caustic-guard confirms such cases as any other.
CAUSTIC_GUARD = True
CAUSTIC_CYCLES_FACTOR = 8
CAUSTIC_ROUGHNESS = 0.4     # a glossy lobe this rough or less (or a graph on Roughness)
CAUSTIC_RADIUS = 0.05       # a point or spot lamp this small or less (Blender's default: 0.25)
_GLOSSY = ("ShaderNodeBsdfGlossy", "ShaderNodeBsdfAnisotropic", "ShaderNodeBsdfMetallic",
           "ShaderNodeBsdfGlass", "ShaderNodeBsdfRefraction")


def _glossy_lobe(graph):
    """Whether a surface graph holds a glossy lobe of Roughness <= CAUSTIC_ROUGHNESS (or one
    a graph drives): a Glossy, Anisotropic, Metallic, Glass or Refraction BSDF, or a Principled
    with Metallic or Transmission Weight over 0 (or linked)."""
    nodes = (graph or {}).get("nodes", {})
    linked = {(link[2], link[3]) for link in (graph or {}).get("links", [])}
    for name, n in nodes.items():
        ins = n.get("inputs", {})
        if n["type"] == "ShaderNodeBsdfPrincipled":
            if not any(ins.get(k, 0.0) > 0.0 or (name, k) in linked
                       for k in ("Metallic", "Transmission Weight")):
                continue
            rough = ins.get("Roughness", 0.5)
        elif n["type"] in _GLOSSY:
            rough = ins.get("Roughness", 0.5)
        else:
            continue
        if (name, "Roughness") in linked or rough <= CAUSTIC_ROUGHNESS:
            return True
    return False


def glossy_caustic(case):
    """Whether `case` has a point or spot lamp of Radius <= CAUSTIC_RADIUS and an object whose
    material has a glossy lobe of low roughness (_glossy_lobe): the guard's flag."""
    small = any(lt["type"] in ("POINT", "SPOT") and lt.get("radius", 0.25) <= CAUSTIC_RADIUS
                for lt in case["lights"])
    used = {o.get("material") for o in case["objects"]}
    return small and any(_glossy_lobe(case["materials"].get(m)) for m in used if m)


def caustic_confirm(case, st, mutate=None, say=print):
    """The guard's confirmation of a flagged case (seeds 1001.., 2x spp, Cycles at
    CAUSTIC_CYCLES_FACTOR x that), or None where the guard is off or the case not flagged."""
    if not (CAUSTIC_GUARD and glossy_caustic(case)):
        return None
    from dataclasses import replace
    wide = replace(st, cycles_spp=st.cycles_spp * CAUSTIC_CYCLES_FACTOR)
    conf = run_case(case, wide, base=1000, spp_factor=2, mutate=mutate, controls=False)
    say(f"  glossy caustic: confirm with Cycles at {CAUSTIC_CYCLES_FACTOR}x (seeds 1001.., "
        f"2x spp): {conf.line()}")
    return conf


difftest.parse = parse
difftest.compare = compare   # run_case, the confirmation and the shrinker read it from there
difftest.cycles_settings = cycles_settings   # render_cycles reads it from there
difftest.run_case = run_case   # main and investigate read these from there
difftest.investigate = investigate
difftest.dk.tags = tags   # difftest_scene.generate and the log's known tags read it there
difftest.render_cycles = render_cycles


def _take(argv, flag):
    """(values of every `flag VALUE` in argv, argv without them)."""
    vals, rest, i = [], [], 0
    while i < len(argv):
        if argv[i] == flag and i + 1 < len(argv):
            vals.append(argv[i + 1])
            i += 2
        else:
            rest.append(argv[i])
            i += 1
    return vals, rest


def main(argv=None):
    global CYCLES_ROULETTE, CYCLES_CACHE, BIDIR, CAUSTIC_GUARD
    argv = list(sys.argv[1:] if argv is None else argv)
    if "--no-caustic-guard" in argv:   # D59's flagged cases confirmed as any other
        argv.remove("--no-caustic-guard")
        CAUSTIC_GUARD = False
    if "--cycles-roulette" in argv:   # Cycles' default Min Light Bounces (0): D51 shows
        argv.remove("--cycles-roulette")
        CYCLES_ROULETTE = True
    cache, argv = _take(argv, "--cycles-cache")
    if cache:
        CYCLES_CACHE = cache[-1]
    want, argv = _take(argv, "--want")
    also, argv = _take(argv, "--and")
    several, argv = _take(argv, "--integrators")
    if not want:
        BIDIR = parse(argv).integrator != "pt"
        return difftest.main(argv)
    import difftest_features as df
    import difftest_features3 as f3
    import difftest_scene as ds
    import difftest_features5 as f5
    import difftest_features6 as f6
    import difftest_features7 as f7
    groups = {"new": f3.FEATURES, "new5": f5.FEATURES,   # a batch's tags by one word
              "new6": f6.FEATURES, "new7": f7.FEATURES}
    want = set().union(*(set(groups.get(w, {w})) for w in want))
    also = set().union(*(set(groups.get(w, {w})) for w in also))
    integrators = [i for w in several for i in w.split(",") if i]
    for i in integrators:
        if i not in INTEGRATORS:
            sys.exit(f"--integrators {i}: one of {', '.join(INTEGRATORS)}")
    args = parse(argv)
    BIDIR = any(i != "pt" for i in integrators or [args.integrator])
    if integrators:   # each wanted seed with each in turn, logged in OUT/<integrator>
        _, argv = _take(argv, "--out")
        _, argv = _take(argv, "--integrator")
    runs = ([(i, os.path.join(args.out, i)) for i in integrators] or
            [(args.integrator, args.out)])
    avoid = set(args.avoid) | (set(difftest.dk.KNOWN) - set(args.allow)
                               if args.avoid_known else set())
    base, _ = _take(argv, "--seed")
    _, argv = _take(argv, "--seed")
    _, argv = _take(argv, "--cases")
    first = int(base[-1]) if base else 0
    seed, ran = first - 1, 0
    while ran < args.cases:
        seed += 1
        if seed > first + 20 * args.cases:
            break
        tags = df.features(ds.generate(seed, args.profile, args.size, avoid))
        if not tags & want or (also and not tags & also):
            continue
        ran += 1
        for integrator, out in runs:
            logged = {e["seed"] for e in difftest.read_log(out)
                      if e.get("settings", {}).get("integrator") == integrator}
            if seed in logged:
                continue
            if args.until and _now() > until_time(args.until):
                print(f"deadline {args.until} UTC: stopped")
                return 0
            extra = ["--integrator", integrator, "--out", out] if integrators else []
            if integrators:
                print(f"== {integrator}", flush=True)
            difftest.main(_until_today(argv) + extra + [
                "--resume", "--seed", str(seed), "--cases", str(len(difftest.read_log(out)) + 1)])
    return 0


def _now():
    import datetime
    return datetime.datetime.now(datetime.timezone.utc)


def until_time(until, now=None):
    """--until HH:MM (UTC) as the next such time: today's, or tomorrow's where today's was over
    12 hours ago (a run started at 23:40 with --until 00:40 stops after midnight, not at once)."""
    import datetime
    now = now or _now()
    hh, mm = (int(x) for x in until.split(":"))
    t = now.replace(hour=hh, minute=mm, second=0, microsecond=0)
    return t + datetime.timedelta(days=1) if (now - t).total_seconds() > 12 * 3600 else t


def _until_today(argv):
    """argv without --until where its time is tomorrow's (difftest.main reads HH:MM as today's
    and would start nothing; the wrapper checks the deadline before each case, and --max-evals
    bounds a shrink)."""
    vals, rest = _take(argv, "--until")
    if vals and until_time(vals[-1]).date() != _now().date():
        return rest
    return argv


if __name__ == "__main__":
    sys.exit(main())
