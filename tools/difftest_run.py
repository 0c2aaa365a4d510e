"""tools/difftest.py with every integrator (auto and lt as well as pt, bdpt, lvc and cis) and
a choice of features (docs/difftest.md). The same options and log; --integrator's choices
are wider, and --want TAG (repeatable; "new" for every difftest_features3 tag, "new5" for every
difftest_features5 tag, "new6" for difftest_features6's) runs only the
seeds whose case has one of the tags (the others are skipped, not logged), one case at a time
through difftest.main (--resume: each seed once). A wrapper, not an edit of difftest.py,
whose digest keys the CI slice's stored Cycles side (tests/cycles/test_difftest.py): changing
it would make every stored reference stale. Its verdict adds "inconclusive" (verdict(): a case
that agrees only because the image mean's margin is over INCONCLUSIVE_MARGIN), and its Cycles
side renders without Cycles' Russian roulette (D51; --cycles-roulette keeps it).

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


difftest.parse = parse
difftest.compare = compare   # run_case, the confirmation and the shrinker read it from there
difftest.cycles_settings = cycles_settings   # render_cycles reads it from there


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
    global CYCLES_ROULETTE
    argv = list(sys.argv[1:] if argv is None else argv)
    if "--cycles-roulette" in argv:   # Cycles' default Min Light Bounces (0): D51 shows
        argv.remove("--cycles-roulette")
        CYCLES_ROULETTE = True
    want, argv = _take(argv, "--want")
    if not want:
        return difftest.main(argv)
    import difftest_features as df
    import difftest_features3 as f3
    import difftest_scene as ds
    import difftest_features5 as f5
    import difftest_features6 as f6
    groups = {"new": f3.FEATURES, "new5": f5.FEATURES,   # a batch's tags by one word
              "new6": f6.FEATURES}
    want = set().union(*(set(groups.get(w, {w})) for w in want))
    args = parse(argv)
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
        if not df.features(ds.generate(seed, args.profile, args.size, avoid)) & want:
            continue
        logged = {e["seed"] for e in difftest.read_log(args.out)
                  if e.get("settings", {}).get("integrator") == args.integrator}
        ran += 1
        if seed in logged:
            continue
        if args.until and _now() > until_time(args.until):
            print(f"deadline {args.until} UTC: stopped")
            break
        difftest.main(_until_today(argv) + ["--resume", "--seed", str(seed),
                                            "--cases", str(len(difftest.read_log(args.out)) + 1)])
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
