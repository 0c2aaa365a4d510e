"""The differential tester's verdict (tools/difftest_run.py, difftest4): a case whose image
mean passes only within a heavy-tailed margin is "inconclusive", not "agree" (difftest3's seed
5006 passed at -62 % with 217 % allowed), while an ordinary agreeing case stays "agree" and a
plain disagreement stays "differ". Synthetic renders, no bpy scene; well under a second. And
its Cycles side's roulette setting (D51), on an empty bpy scene."""

import os
import sys

import numpy as np

TOOLS = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))), "tools")
sys.path.insert(0, TOOLS)
import difftest  # noqa: E402
import difftest_run  # noqa: E402


def _renders(rng, k=16, level=1.0, noise=0.05):
    return [level * (1.0 + noise * rng.standard_normal((32, 32, 3))) for _ in range(k)]


def test_ordinary_case_agrees():
    rng = np.random.default_rng(1)
    lan, cyc = _renders(rng), _renders(rng)
    assert difftest_run.compare(lan, cyc, controls=False).status == "agree"


def test_heavy_tailed_case_is_inconclusive():
    """One Cycles seed catches a firefly of 3e5 in one pixel (a caustic): every block test
    and the block-weighted mean pass, the image mean reads about -50 % and passes within a
    margin of hundreds of per cent. The plain tester calls it "agree" (the control of this
    test); the wrapper's verdict calls it "inconclusive"."""
    rng = np.random.default_rng(2)
    lan, cyc = _renders(rng), _renders(rng)
    cyc[0] = cyc[0].copy()
    cyc[0][27, 11] = 3.0e5
    plain = difftest_run._compare(lan, cyc, controls=False)   # difftest.py's own
    assert plain.status == "agree" and plain.mean_rel[0] < -0.3   # passed silently before
    res = difftest_run.compare(lan, cyc, controls=False)
    assert res.status == "inconclusive", res.text
    assert "inconclusive" in res.text
    assert difftest.classify({"result": {"status": res.status}}) == "inconclusive"


def test_difference_still_differs():
    rng = np.random.default_rng(3)
    lan, cyc = _renders(rng, level=1.1), _renders(rng)
    assert difftest_run.compare(lan, cyc, controls=False).status == "differ"


def test_cycles_side_renders_without_roulette():
    """D51 (docs/difftest.md): the wrapper's Cycles side sets Min Light / Transparent Bounces to
    the bounce counts (Cycles' roulette in a volume drops lamp hits), and --cycles-roulette
    keeps Cycles' default; the control is difftest.py's own settings (roulette at 0)."""
    import pytest
    bpy = pytest.importorskip("bpy")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    difftest_run._cycles_settings(sc, 1, 4, 3, 1)   # difftest.py's own
    assert (sc.cycles.min_light_bounces, sc.cycles.min_transparent_bounces) == (0, 0)
    difftest.cycles_settings(sc, 1, 4, 3, 1)   # what render_cycles calls: the wrapper's
    assert (sc.cycles.min_light_bounces, sc.cycles.min_transparent_bounces) == (3, 64)
    old = difftest_run.CYCLES_ROULETTE
    try:
        difftest_run.CYCLES_ROULETTE = True
        sc.cycles.min_light_bounces = sc.cycles.min_transparent_bounces = 0
        difftest.cycles_settings(sc, 1, 4, 3, 1)
        assert (sc.cycles.min_light_bounces, sc.cycles.min_transparent_bounces) == (0, 0)
    finally:
        difftest_run.CYCLES_ROULETTE = old


def test_until_past_midnight():
    """--until HH:MM is the next such time (difftest6: a run started at 23:43 with --until
    00:40 stopped at once, the time read as today's); today's where it is ahead, or passed
    less than 12 hours ago (a stop that is due)."""
    import datetime
    utc = datetime.timezone.utc
    now = datetime.datetime(2026, 12, 6, 23, 43, tzinfo=utc)
    assert difftest_run.until_time("00:40", now) == datetime.datetime(2026, 12, 7, 0, 40,
                                                                      tzinfo=utc)
    assert difftest_run.until_time("23:50", now) == now.replace(minute=50)
    assert difftest_run.until_time("20:00", now) == now.replace(hour=20, minute=0)
    early = now.replace(hour=2, minute=0)
    assert difftest_run.until_time("07:38", early) == early.replace(hour=7, minute=38)


def test_cycles_cache_renders_a_case_once(tmp_path, monkeypatch):
    """--cycles-cache (difftest7): Cycles' renders of a case are kept and read back, so the
    integrators of --integrators share one Cycles side; another case (or other seeds) renders
    again. The control: without the cache every call renders."""
    import pytest
    pytest.importorskip("bpy")
    calls = []

    def fake(bounces, seeds, spp, threads):
        calls.append(tuple(seeds))
        return [np.full((2, 2, 3), float(s) + 0.25) for s in seeds]
    monkeypatch.setattr(difftest_run, "_render_cycles", fake)
    monkeypatch.setattr(difftest_run, "CYCLES_CACHE", None)
    case = {"seed": 1, "bounces": 2, "objects": [], "lights": [], "materials": {}}
    monkeypatch.setattr(difftest_run, "_CASE", case)
    difftest.render_cycles(2, [1, 2], 4, 1)
    difftest.render_cycles(2, [1, 2], 4, 1)
    assert len(calls) == 2   # the control: no cache, two renders
    monkeypatch.setattr(difftest_run, "CYCLES_CACHE", str(tmp_path))
    a = difftest.render_cycles(2, [1, 2], 4, 1)
    b = difftest.render_cycles(2, [1, 2], 4, 1)
    assert len(calls) == 3 and all(np.array_equal(x, y) for x, y in zip(a, b))
    difftest.render_cycles(2, [3, 4], 4, 1)   # other seeds
    monkeypatch.setattr(difftest_run, "_CASE", dict(case, seed=2))   # another case
    difftest.render_cycles(2, [1, 2], 4, 1)
    assert calls[3:] == [(3, 4), (1, 2)]


def test_view_dependent_tag_for_bidirectional_runs(monkeypatch):
    """The wrapper's VIEW_TAG (difftest7's 41028): a surface graph reading Geometry Incoming is
    tagged in a run of a bidirectional integrator, not in pt's, and a graph without a
    view-dependent source is not."""
    graph = {"nodes": {"n0": {"type": "ShaderNodeBsdfDiffuse", "props": {}, "inputs": {}},
                       "n1": {"type": "ShaderNodeNewGeometry", "props": {}, "inputs": {}}},
             "links": [["n1", "Incoming", "n0", "Color"]], "out": ["n0", "BSDF"]}
    case = {"objects": [], "lights": [], "materials": {"m": graph}}
    plain = dict(case, materials={"m": dict(graph, links=[["n1", "Position", "n0", "Color"]])})
    assert difftest_run.view_dependent(case) and not difftest_run.view_dependent(plain)
    monkeypatch.setattr(difftest_run, "_dk_tags", lambda c: set())
    monkeypatch.setattr(difftest_run, "BIDIR", False)
    assert difftest.dk.tags(case) == set()
    monkeypatch.setattr(difftest_run, "BIDIR", True)
    assert difftest.dk.tags(case) == {difftest_run.VIEW_TAG}
    assert difftest.dk.tags(plain) == set()
