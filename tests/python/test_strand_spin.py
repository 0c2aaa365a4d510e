"""Strands of a turning object (docs/motion_blur.md "Strands of a turning object"): a fur ball
whose fur turns half a turn about the view axis over the shutter, exported at the frame with its
object's matrices at 3 steps (curves["motion"], ["motion_base"]: the core slerps them), rendered
by pt against an independent estimate of the same shutter integral: each seed's reference
averages J still renders with the fur turned here by the exact angle at the times (j + u) / J
(u uniform per seed), the core's motion code not involved; by lantern.metrics with negative
controls: the fur left still, and the same turn exported as world points at the steps
(curves["deform"], lerped: its strands cut the chords, 0.29 x their reach inside the arc between
two steps) must both differ. Embree's instance against the built-in BVH's (the same seeds); the
bidirectional integrators render it themselves; the scene file keeps the steps."""
import numpy as np
import pytest

import lantern
from lantern import metrics, session
from lantern.scenes_hair import fur_ball

from shutter_ref import shutter_average

pytestmark = pytest.mark.skipif(not session.native_available(),
                                reason=f"lantern._core not built ({session.native_error()})")

K, SPP, J, SIZE, STRANDS = 8, 16, 4, 20, 120


def _turn(t):
    """The fur's object-to-world at shutter time t: a turn by pi (t - 1/2) about y (the view
    axis), the frame's at t = 1/2."""
    a = np.pi * (t - 0.5)
    c, s = np.cos(a), np.sin(a)
    m = np.eye(4)
    m[0, 0], m[0, 2], m[2, 0], m[2, 2] = c, s, -s, c
    return m


def _scene(t=0.5, export=None):
    """The fur turned to time t (export None), or exported at the frame with 3 steps as the
    object's matrices (export "motion") or as world points at the steps ("deform")."""
    sc = fur_ball(SIZE, SIZE, num_strands=STRANDS, world=0.3)
    fur = sc.curves[0]
    p0 = fur["points"].astype(np.float64)
    if export is None:
        m = _turn(t)
        fur["points"] = (p0 @ m[:3, :3].T + m[:3, 3]).astype(np.float32)
    elif export == "motion":
        fur["motion"] = [_turn(u) for u in (0.0, 0.5, 1.0)]
        fur["motion_base"] = _turn(0.5)
    else:
        fur["deform"] = np.stack([p0 @ _turn(u)[:3, :3].T for u in (0.0, 0.5, 1.0)]
                                 ).astype(np.float32)
    return sc


def _render(scene, seed=3, spp=4, integrator="pt"):
    s = lantern.Session(scene, integrator=integrator, seed=seed, spp_per_iteration=spp,
                        threads=1, max_depth=3)
    s.step()
    return np.asarray(s.image(), np.float64), list(s.warnings)


def _set(scene, k=K, spp=SPP):
    out = []
    for s in range(k):
        img, warnings = _render(scene, 1 + s, spp)
        assert not warnings, warnings
        out.append(img)
    return np.stack(out)


def _reference(seed, spp=SPP, j_times=J):
    return shutter_average(_scene, lambda *a: _render(*a)[0], seed, 4000, spp, j_times)


def test_turning_fur_matches_static_average():
    """8 seeds x 16 spp; controls: the still fur and the lerped (chord) export must fail."""
    lan = _set(_scene(export="motion"))
    assert np.isfinite(lan).all()
    ref = np.stack([_reference(s) for s in range(K)])
    metrics.assert_agreement("turning fur", lan, ref, block=10, se_floor=1e-6,
                             image_bias=0.03, block_bias=0.10)
    for name, scene in (("still fur", _scene()), ("lerped points", _scene(export="deform"))):
        res = metrics.compare_renders(_set(scene), ref, block=10, se_floor=1e-6)
        print(f"control, {name}:", res)
        assert not res.passed, f"the {name} agree with the turning fur's reference: {res}"


def test_embree_and_builtin_bvh_agree_on_turning_fur(monkeypatch):
    if not session.require_core().embree_available():
        pytest.skip("Embree is not available")
    scene = _scene(export="motion")
    out = {}
    for accel in ("embree", "bvh"):
        monkeypatch.setenv("LANTERN_ACCEL", accel)
        out[accel] = np.stack([_render(scene, 1 + k, SPP)[0] for k in range(4)])
    metrics.assert_agreement("turning fur embree/bvh",
                             *metrics.paired_sets(out["bvh"], out["embree"]), block=5)
    # the same seed: the two structures find the same strands at the same times
    assert np.abs(out["bvh"].mean() - out["embree"].mean()) < 0.01 * out["bvh"].mean()


@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis", "lt"])
def test_bidirectional_renders_turning_strands_itself(integrator):
    img, warnings = _render(_scene(export="motion"), integrator=integrator)
    assert not any("motion blur" in w for w in warnings), warnings
    assert np.isfinite(img).all()
    assert not np.array_equal(img, _render(_scene(), integrator=integrator)[0])


def test_turning_steps_survive_the_scene_file(tmp_path):
    sc = _scene(export="motion")
    path = tmp_path / "spin.lantern"
    sc.save(path)
    back = lantern.load_scene(path)
    np.testing.assert_array_equal(np.asarray(back.curves[0]["motion"]),
                                  np.asarray(sc.curves[0]["motion"]))
    np.testing.assert_array_equal(np.asarray(back.curves[0]["motion_base"]),
                                  np.asarray(sc.curves[0]["motion_base"]))
    a = _render(sc)[0]
    assert np.array_equal(a, _render(back)[0])
    assert not np.array_equal(a, _render(_scene())[0])


def test_bad_turn_warns_and_renders_still():
    sc = _scene(export="motion")
    sc.curves[0]["motion"][2] = np.full((4, 4), np.nan)
    img, warnings = _render(sc)
    assert any("fur" in w and "motion step 2" in w for w in warnings), warnings
    assert np.array_equal(img, _render(_scene())[0])
