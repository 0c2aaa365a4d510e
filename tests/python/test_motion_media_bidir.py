"""Volumes under motion blur in the light-path integrators (docs/motion_blur.md, "Volumes";
issues 29 and 32): every medium ray of lt's, bdpt's, lvc's and cis's light and camera
sub-paths, the connections and shadow rays through media and the camera segments, carries its
path's time, and a moving volume's boundary is crossed where it is then (medium_motion.h). On
test_motion_media.py's scenes (a box sliding through a still fog box, "mesh"; the fog box
sliding around a still box, "fog"), each against pt's motion render of the same scene (checked
there against an independent average of still renders) by lantern.metrics.assert_agreement
with its negative controls. The negative control of the change itself: the same renders with
the medium rays at time 0 (the test hook LANTERN_TEST_UNTIMED_MEDIA=1) must not agree. bdpt
draws a time per path pair, lvc and cis one per pass (SPP passes of one sample here); lt cannot
see the world or start on a soft-falloff light in media: its scenes have a black world and a
sphere light, against pt on the same."""
import numpy as np
import pytest

import lantern
from lantern import metrics, session

import test_motion_media as mm

pytestmark = pytest.mark.skipif(not session.native_available(),
                                reason=f"lantern._core not built ({session.native_error()})")

K, SPP = 8, 32


def _scene(kind, integrator):
    sc = mm.CASES[kind][0]()
    if integrator == "lt":
        sc.world["color"] = (0.0, 0.0, 0.0)
        sc.lights[0]["soft_falloff"] = False
    return sc


def _renders(sc, integrator, seed0):
    """K renders of SPP samples a pixel: one step (pt, bdpt), SPP passes of one sample (lvc,
    cis), 32 SPP in one step (lt: its noise)."""
    per_pass = integrator in ("lvc", "cis")
    spp = 1 if per_pass else SPP * (32 if integrator == "lt" else 1)
    out = []
    for k in range(K):
        s = lantern.Session(sc, integrator=integrator, seed=seed0 + k, spp_per_iteration=spp,
                            threads=1, max_depth=4)
        for _ in range(SPP if per_pass else 1):
            s.step()
        assert not s.warnings, list(s.warnings)
        out.append(np.asarray(s.image(), np.float64))
    out = np.stack(out)
    assert np.isfinite(out).all()
    return out


_PT = {}


def _pt(kind, lt):
    key = (kind, lt)
    if key not in _PT:
        _PT[key] = _renders(_scene(kind, "lt" if lt else "pt"), "pt", 1001)
    return _PT[key]


@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis", "lt"])
@pytest.mark.parametrize("kind", ["mesh", "fog"])
def test_media_motion_light_paths_match_pt(kind, integrator, monkeypatch):
    sc = _scene(kind, integrator)
    pt = _pt(kind, integrator == "lt")
    lan = _renders(sc, integrator, 1)
    metrics.assert_agreement(f"media {kind} {integrator}", lan, pt, block=8, se_floor=1e-6,
                             image_bias=0.02, block_bias=0.10)
    # the medium rays at time 0 (the hand-over's reason): they must not agree
    monkeypatch.setenv("LANTERN_TEST_UNTIMED_MEDIA", "1")
    untimed = _renders(sc, integrator, 1)
    res = metrics.compare_renders(untimed, pt, block=8, se_floor=1e-6)
    print("untimed:", res)
    assert not res.passed, f"{kind} {integrator}: medium rays at time 0 agree with pt: {res}"


def test_still_scene_keeps_bits():
    """Steps that do not move: no motion, the still scene's bits; and the test hook reads
    nothing in a still scene."""
    still = mm._scene(mm._x(0.5), "mesh")
    same = mm._scene(mm._x(0.5), "mesh")
    same.meshes[mm.BOX]["motion"] = [np.eye(4)] * 3
    same.meshes[mm.BOX]["motion_base"] = np.eye(4)
    for integrator in ("bdpt", "lt"):
        if integrator == "lt":
            for sc in (still, same):
                sc.world["color"] = (0.0, 0.0, 0.0)
                sc.lights[0]["soft_falloff"] = False
        a = lantern.Session(still, integrator=integrator, seed=3, spp_per_iteration=2,
                            threads=1, max_depth=4)
        b = lantern.Session(same, integrator=integrator, seed=3, spp_per_iteration=2,
                            threads=1, max_depth=4)
        a.step()
        b.step()
        assert np.array_equal(np.asarray(a.image()), np.asarray(b.image()))
