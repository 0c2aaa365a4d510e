"""Strands under motion blur (docs/motion_blur.md "Strands"): a furry ball sliding over the
shutter (the ball by its matrices, the fur by its points at 3 steps, curves["deform"]) rendered
by pt against an independent estimate of the same shutter integral: each seed's reference
averages J still renders (4 in CI, 8 long) with the ball and fur placed here at the times (j + u) / J (u uniform
per seed), the core's motion code not involved; by lantern.metrics with negative controls (the
still frame must differ); Embree's time-step curves against the built-in BVH's; the
bidirectional integrators against pt (long); bad steps (NaN, a count that does not match the
points) get a message and render the still strands bit for bit; the scene file keeps the steps."""
import numpy as np
import pytest

import lantern
from lantern import metrics, session
from lantern.scenes_hair import fur_ball

from shutter_ref import shutter_average

pytestmark = pytest.mark.skipif(not session.native_available(),
                                reason=f"lantern._core not built ({session.native_error()})")

K, SPP, J, SIZE, STRANDS = 8, 16, 4, 20, 120
LONG_K, LONG_SPP, LONG_J = 16, 64, 8


def _slide(t):
    """Where the ball is at shutter time t: from 0.6 m left and 0.2 m up to the frame's place at
    the shutter's middle and back (piecewise linear with its corner at a step: 3 or 5 steps
    lerp it exactly; its shutter average is not the frame's place, as a linear slide's would be)."""
    a = abs(2.0 * t - 1.0)
    return np.array([-0.6 * a, 0.0, 0.2 * a], np.float32)


def _scene(t=0.5, steps=0, radius_steps=False):
    """The fur ball placed at time t (steps 0), or exported at the frame (t 0.5) with `steps`
    motion steps: the ball's matrices and the fur's points (and radii: thicker at the close)."""
    sc = fur_ball(SIZE, SIZE, num_strands=STRANDS, world=0.3)
    ball, fur = sc.meshes[0], sc.curves[0]
    p0, r0 = fur["points"].copy(), fur["radius"].copy()
    if not steps:
        ball["positions"] = (ball["positions"] + _slide(t)).astype(np.float32)
        fur["points"] = (p0 + _slide(t)).astype(np.float32)
        if radius_steps:
            fur["radius"] = (r0 * (1.0 + t)).astype(np.float32)
        return sc
    ts = np.linspace(0.0, 1.0, steps)
    ball["motion"] = [np.eye(4) for _ in ts]
    for m, u in zip(ball["motion"], ts):
        m[:3, 3] = _slide(u)
    ball["motion_base"] = np.eye(4)
    fur["deform"] = np.stack([p0 + _slide(u) for u in ts]).astype(np.float32)
    if radius_steps:
        fur["deform_radius"] = np.stack([r0 * (1.0 + u) for u in ts]).astype(np.float32)
        fur["radius"] = (r0 * 1.5).astype(np.float32)
    return sc


def _render(scene, seed=3, spp=4, integrator="pt"):
    s = lantern.Session(scene, integrator=integrator, seed=seed, spp_per_iteration=spp,
                        threads=1, max_depth=3)
    s.step()
    return np.asarray(s.image(), np.float64), list(s.warnings)


def _reference(seed, spp, j_times, radius_steps=False):
    return shutter_average(lambda t: _scene(t, radius_steps=radius_steps),
                           lambda *a: _render(*a)[0], seed, 3000, spp, j_times)


def _compare(k, spp, j_times, radius_steps, block, **bias):
    scene = _scene(steps=3, radius_steps=radius_steps)
    lan = []
    for s in range(k):
        img, warnings = _render(scene, 1 + s, spp)
        assert not warnings, warnings
        lan.append(img)
    lan = np.stack(lan)
    assert np.isfinite(lan).all()
    ref = np.stack([_reference(s, spp, j_times, radius_steps) for s in range(k)])
    name = "strand motion" + (" + radii" if radius_steps else "")
    metrics.assert_agreement(name, lan, ref, block=block, se_floor=1e-6, **bias)
    # negative control: the fur left still at the frame (the ball still slides)
    still_fur = _scene(steps=3, radius_steps=radius_steps)
    still_fur.curves[0].pop("deform")
    still_fur.curves[0].pop("deform_radius", None)
    sharp = np.stack([_render(still_fur, 1 + s, spp)[0] for s in range(k)])
    res = metrics.compare_renders(sharp, ref, block=block, se_floor=1e-6)
    print("control, still fur:", res)
    assert not res.passed, f"{name}: the still fur agrees with the sliding fur's reference: {res}"


def test_sliding_fur_matches_static_average():
    """CI's: 8 seeds x 16 spp resolve a few per cent (controls at 3 % and 10 % a block)."""
    _compare(K, SPP, J, False, 10, image_bias=0.03, block_bias=0.10)


@pytest.mark.long
@pytest.mark.parametrize("radius_steps", [False, True], ids=["slide", "slide+thicken"])
def test_sliding_fur_matches_static_average_long(radius_steps):
    _compare(LONG_K, LONG_SPP, LONG_J, radius_steps, 5)


@pytest.mark.long  # (CI: tests/cpp/test_curve_motion.cpp checks Embree's time steps ray by ray)
def test_embree_and_builtin_bvh_agree_on_moving_fur(monkeypatch):
    if not session.require_core().embree_available():
        pytest.skip("Embree is not available")
    scene = _scene(steps=5)
    out = {}
    for accel in ("embree", "bvh"):
        monkeypatch.setenv("LANTERN_ACCEL", accel)
        out[accel] = np.stack([_render(scene, 1 + k, SPP)[0] for k in range(K)])
    metrics.assert_agreement("strand motion embree/bvh",
                             *metrics.paired_sets(out["bvh"], out["embree"]), block=5)


def test_steps_that_do_not_move_keep_bits():
    sc = _scene(0.5)
    still = _render(sc)[0]
    p = sc.curves[0]["points"]
    sc.curves[0]["deform"] = np.stack([p, p, p])
    img, warnings = _render(sc)
    assert not warnings, warnings
    assert np.array_equal(img, still)
    moving = _scene(steps=3)
    moving.meshes[0].pop("motion")  # the fur alone slides
    assert not np.array_equal(_render(moving)[0], still)  # (the test can fail)


@pytest.mark.parametrize("bad", ["nan", "inf", "count", "radius"])
def test_bad_steps_warn_and_render_still(bad):
    sc = _scene(steps=3)
    sc.meshes[0].pop("motion")  # the fur alone moves: its fallback is the still frame
    fur = sc.curves[0]
    if bad in ("nan", "inf"):
        fur["deform"][2, 7, 1] = np.nan if bad == "nan" else np.inf
    elif bad == "radius":
        fur["deform_radius"] = np.stack([fur["radius"]] * 3)
        fur["deform_radius"][1, 3] = -1.0
    if bad == "count":  # a hair system whose strand count changes: the schema refuses the shape
        fur["deform"] = fur["deform"][:, :-5]
        with pytest.raises(ValueError, match=r"curves 0 \('fur'\) deform: expected shape"):
            sc.validate()
        return
    img, warnings = _render(sc)
    assert np.isfinite(img).all()
    hits = [w for w in warnings if "curves 0 ('fur')" in w]
    assert len(hits) == 1, warnings
    what = "a radius at motion step 1" if bad == "radius" else "a point at motion step 2"
    assert what in hits[0] and "without motion blur" in hits[0], hits
    assert np.array_equal(img, _render(_scene(0.5))[0])  # where it was exported


def test_steps_survive_the_scene_file(tmp_path):
    scene = _scene(steps=3, radius_steps=True)
    path = tmp_path / "fur.lantern"
    scene.save(path)
    loaded = lantern.load_scene(path)
    for key in ("deform", "deform_radius"):
        got = np.asarray(loaded.curves[0][key])
        assert got.dtype == np.float32 and np.array_equal(got, scene.curves[0][key])
    a = _render(scene)[0]
    assert np.array_equal(a, _render(loaded)[0])
    assert not np.array_equal(a, _render(_scene(0.5, radius_steps=True))[0])


@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis", "lt"])
def test_bidirectional_renders_moving_strands_itself(integrator):
    s = lantern.Session(_scene(steps=3), integrator=integrator, seed=2, spp_per_iteration=4,
                        threads=1, max_depth=3)
    s.step()
    assert not any("motion blur" in w for w in s.warnings), list(s.warnings)
    still_fur = _scene(steps=3)
    still_fur.curves[0].pop("deform")
    s2 = lantern.Session(still_fur, integrator=integrator, seed=2, spp_per_iteration=4,
                         threads=1, max_depth=3)
    s2.step()
    assert not np.array_equal(np.asarray(s.image()), np.asarray(s2.image()))


def _bidir_render(integrator, seed, spp):
    """lvc and cis as spp passes of one sample (one time per pass: docs/motion_blur.md)."""
    one = integrator in ("lvc", "cis")
    s = lantern.Session(_scene(steps=3), integrator=integrator, seed=seed,
                        spp_per_iteration=1 if one else spp, threads=1, max_depth=3)
    for _ in range(spp if one else 1):
        s.step()
    return np.asarray(s.image(), np.float64)


@pytest.mark.long
@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_bidirectional_agrees_with_pt_on_moving_fur(integrator):
    """Strand vertices at the path's time (bdpt: the camera path's, lvc / cis: the pass's)."""
    pt = np.stack([_render(_scene(steps=3), 1 + k, 64)[0] for k in range(8)])
    other = np.stack([_bidir_render(integrator, 500 + k, 16) for k in range(8)])
    metrics.assert_agreement(f"strand motion {integrator} vs pt", other, pt, block=5,
                             se_floor=1e-6, image_bias=0.02, block_bias=0.10)


def test_sets_of_different_step_counts_share_the_largest():
    """A set of 3 steps beside one of 5 is sampled at the 5 shared steps (scene/curve_motion.cpp):
    the V-shaped slide's corner is a step of both, so the fur renders as its own 5 steps do, up
    to the lerp's rounding (a far-away 5-step set, out of view, sets the count)."""
    def with_far_set(steps):
        sc = _scene(steps=steps)
        sc.meshes[0].pop("motion")  # the fur alone moves
        pts = np.array([[50, 50, 50], [50, 50, 51]], np.float32)
        sc.add_curves(pts, np.full(2, 0.01, np.float32), [0, 2], name="far",
                      deform=np.stack([pts + [0.1 * k, 0, 0] for k in range(5)]))
        return sc
    a, wa = _render(with_far_set(3), 4, 8)
    b, wb = _render(with_far_set(5), 4, 8)
    assert not wa and not wb, (wa, wb)
    differ = np.abs(a - b) > 1e-4 * np.maximum(np.abs(b), 1e-3)
    assert differ.mean() <= 0.01, f"{differ.mean():.2%} of channels differ"
    assert not np.array_equal(a, _render(_scene(0.5), 4, 8)[0])
