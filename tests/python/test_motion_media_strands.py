"""Moving strands beside volumes (docs/motion_blur.md, "Strands" and "Volumes"; issue 32): a fur
ball's fur sliding over the shutter (its points at 3 steps, curves["deform"]; the ball still)
in world fog. Before, a scene with volumes kept moving strands still with a
warning; now every medium ray (pt's bounces through the fog, its next-event shadow rays
through it, pt_shadow_transmittance; the bidirectional sub-paths' rays, connections and shadow
segments through media, bdpt_connect_medium / bdpt_medium_shadow) carries the path's time, so
the curve queries find the fur where it is then. pt against an independent estimate of the
shutter integral (per seed, J still renders with the fur placed here at the times
(j + u) / J, u uniform per seed; the core's motion code not involved), by
lantern.metrics.assert_agreement; negative control: the fur kept still (the behaviour before)
must not agree. bdpt and cis (SPP passes of one sample: one time per pass) against pt; their
control: the medium rays at time 0 (LANTERN_TEST_UNTIMED_MEDIA=1, MotionView::media_untimed)
must not agree."""
import numpy as np
import pytest

import lantern
from lantern import metrics, session
from lantern.scenes_hair import fur_ball

from shutter_ref import shutter_average

pytestmark = pytest.mark.skipif(not session.native_available(),
                                reason=f"lantern._core not built ({session.native_error()})")

K, SPP, J, SIZE, STRANDS, FOG = 8, 32, 4, 24, 300, 0.1


def _slide(t):
    """Where the fur is at shutter time t: from 0.6 m left and 0.2 m up to the frame's place at
    the shutter's middle and back (its corner at a step: 3 steps lerp it exactly)."""
    a = abs(2.0 * t - 1.0)
    return np.array([-0.6 * a, 0.0, 0.2 * a], np.float32)


def _scene(t=0.5, steps=0):
    """The fur ball in world fog, its fur placed at time t (steps 0), or exported at the frame
    (t 0.5) with 3 motion steps of the fur's points. The ball itself stays still: the scene's
    only motion is the strands' (MotionView::curves, no moving mesh), so every timed medium ray
    here is timed for the strands alone."""
    sc = fur_ball(SIZE, SIZE, num_strands=STRANDS, world=0.3)
    sc.world["volume"] = {"sigma_s": [FOG] * 3, "sigma_a": [0.2 * FOG] * 3}
    fur = sc.curves[0]
    p0 = fur["points"].copy()
    if not steps:
        fur["points"] = (p0 + _slide(t)).astype(np.float32)
        return sc
    ts = np.linspace(0.0, 1.0, steps)
    fur["deform"] = np.stack([p0 + _slide(u) for u in ts]).astype(np.float32)
    return sc


def _render(scene, seed, spp, integrator="pt"):
    """spp samples a pixel: one step (pt, bdpt), spp passes of one sample (cis)."""
    per_pass = integrator in ("lvc", "cis")
    s = lantern.Session(scene, integrator=integrator, seed=seed,
                        spp_per_iteration=1 if per_pass else spp, threads=1, max_depth=3)
    for _ in range(spp if per_pass else 1):
        s.step()
    return np.asarray(s.image(), np.float64), list(s.warnings)


def _reference(seed):
    return shutter_average(_scene, lambda *a: _render(*a)[0], seed, 5000, SPP, J)


_PT = {}


def _pt():
    if "pt" not in _PT:
        lan = []
        for k in range(K):
            img, warnings = _render(_scene(steps=3), 1 + k, SPP)
            assert not warnings, warnings
            lan.append(img)
        _PT["pt"] = np.stack(lan)
        assert np.isfinite(_PT["pt"]).all()
    return _PT["pt"]


def _still_fur():
    sc = _scene(steps=3)
    sc.curves[0].pop("deform")  # the fur where it was exported
    return sc


def test_moving_fur_in_fog_matches_static_average():
    lan = _pt()
    ref = np.stack([_reference(k) for k in range(K)])
    metrics.assert_agreement("strands in fog", lan, ref, block=8, se_floor=1e-6,
                             image_bias=0.03, block_bias=0.10)
    sharp = np.stack([_render(_still_fur(), 1 + k, SPP)[0] for k in range(K)])
    res = metrics.compare_renders(sharp, ref, block=8, se_floor=1e-6)
    print("control, still fur:", res)
    assert not res.passed, f"the still fur agrees with the sliding fur's reference: {res}"


@pytest.mark.parametrize("integrator", ["bdpt", "cis"])
def test_moving_fur_in_fog_light_paths_match_pt(integrator, monkeypatch):
    pt = _pt()

    def renders():
        out = []
        for k in range(K):
            img, warnings = _render(_scene(steps=3), 500 + k, SPP, integrator)
            assert not warnings, warnings
            out.append(img)
        out = np.stack(out)
        assert np.isfinite(out).all()
        return out

    metrics.assert_agreement(f"strands in fog {integrator} vs pt", renders(), pt, block=8,
                             se_floor=1e-6, image_bias=0.03, block_bias=0.10)
    # the change's control: their medium rays at time 0 (the test hook) meet the fur where it
    # is then, not at the path's time
    monkeypatch.setenv("LANTERN_TEST_UNTIMED_MEDIA", "1")
    res = metrics.compare_renders(renders(), pt, block=8, se_floor=1e-6)
    print(f"control, untimed medium rays ({integrator}):", res)
    assert not res.passed, f"{integrator}: medium rays at time 0 agree with pt: {res}"
