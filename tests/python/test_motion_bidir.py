"""Motion blur in the bidirectional integrators (docs/motion_blur.md, issue 32): bdpt, lvc and
cis against pt on test_motion_blur.py's sliding box, spinning box and moving camera, and on
test_deform_motion.py's deforming pyramid (pt's own motion blur is checked there against an
independent average of still renders). lantern.metrics.assert_agreement with its negative
controls; and each motion render must differ from pt's still frame. bdpt draws a time per path
pair (pt's), lvc and cis one per pass: they render 1 sample per iteration here, so that a seed's
image averages 16 stratified times. lt (its own time per light path) cannot see the world, so it
renders the same motions lit by a point light under a camera looking down at the floor."""
import numpy as np
import pytest

import lantern
from lantern import metrics, session

import test_deform_motion as deform
import test_motion_blur as mb

pytestmark = pytest.mark.skipif(not session.native_available(),
                                reason=f"lantern._core not built ({session.native_error()})")

K, SPP = 8, 16


def _render(scene, integrator, seed):
    """SPP samples a pixel: one step for pt and bdpt, SPP passes of one sample for lvc, cis;
    lt 16 SPP in one step."""
    per_pass = integrator in ("lvc", "cis")
    spp = 1 if per_pass else SPP * (16 if integrator == "lt" else 1)
    s = lantern.Session(scene, integrator=integrator, seed=seed, threads=1, max_depth=3,
                        spp_per_iteration=spp)
    for _ in range(SPP if per_pass else 1):
        s.step()
    return np.asarray(s.image(), np.float64), list(s.warnings)


def _renders(scene, integrator, seed0):
    out = []
    for k in range(K):
        img, warnings = _render(scene, integrator, seed0 + k)
        assert not warnings, warnings
        out.append(img)
    return np.stack(out)


_PT = {}


def _pt(key, scene):  # pt's motion renders and still frame, once per scene (other seeds)
    if key not in _PT:
        _PT[key] = _renders(scene, "pt", 1001)
    return _PT[key]


@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
@pytest.mark.parametrize("name", ["slide", "spin", "camera"])
def test_bidirectional_motion_matches_pt(name, integrator):
    scene = mb._moving(name)
    lan = _renders(scene, integrator, 1)
    assert np.isfinite(lan).all()
    metrics.assert_agreement(f"{name} {integrator}", lan, _pt(name, scene), block=8,
                             se_floor=1e-6)
    # and it is blurred: pt's still frame differs
    still = _pt(name + " still", mb._static_at(name, 0.5))
    res = metrics.compare_renders(lan, still, block=8, se_floor=1e-6)
    assert not res.passed, f"{name} {integrator}: agrees with the still frame: {res}"


EYE, AT = (0.0, -2.0, 7.0), (0.0, 0.0, 0.5)


def _lit(sc, dx=0.0, soft=False):
    """A scene of test_motion_blur.py lit by a point light instead of the world (soft: a
    soft-falloff ball of radius 0.4), the camera (moved by dx along x) looking down so that it
    sees only the floor and the box."""
    sc.world["color"] = (0.0, 0.0, 0.0)
    sc.add_light("point", position=[1.0, -1.5, 3.0], power=[400.0] * 3,
                 radius=0.4 if soft else 0.0, soft_falloff=soft)
    sc.look_at((EYE[0] + dx, EYE[1], EYE[2]), (AT[0] + dx, AT[1], AT[2]), up=(0, 0, 1), fov=24)
    return sc


def _lit_moving(name, soft=False):
    sc = _lit(mb._moving(name), soft=soft)
    if name == "camera":
        sc.camera["motion"] = [np.array(_lit(mb._scene(), mb.CAMERA_SLIDE * (2 * t - 1))
                                        .camera["to_world"]) for t in np.linspace(0, 1, 3)]
    return sc


@pytest.mark.parametrize("name", [  # CI: the camera (lt's own part: splats to the camera at
    "camera",                        # the path's time); the moving meshes long (bdpt's cover)
    pytest.param("slide", marks=pytest.mark.long), pytest.param("spin", marks=pytest.mark.long)])
def test_light_tracing_motion_matches_pt(name):
    scene = _lit_moving(name)
    lan = _renders(scene, "lt", 1)
    assert np.isfinite(lan).all()
    # (lt's noise at 8 x 64 spp resolves X on the image: controls 5 %, 15 %)
    metrics.assert_agreement(f"{name} lt", lan, _pt(name + " lit", scene), block=8,
                             se_floor=1e-6, image_bias=0.02, block_bias=0.10)
    still = _pt(name + " lit still", _lit(mb._static_at(name, 0.5)))
    res = metrics.compare_renders(lan, still, block=8, se_floor=1e-6)
    assert not res.passed, f"{name} lt: agrees with the still frame: {res}"


@pytest.mark.parametrize("integrator", ["bdpt", "cis"])
def test_bidirectional_deformation_matches_pt(integrator):
    scene = deform._deforming(moves=True)
    lan = _renders(scene, integrator, 1)
    metrics.assert_agreement(f"deform+slide {integrator}", lan, _pt("deform", scene), block=8,
                             se_floor=1e-6)
    still = _pt("deform still", deform._scene(0.5, True))
    res = metrics.compare_renders(lan, still, block=8, se_floor=1e-6)
    assert not res.passed, f"deform {integrator}: agrees with the still frame: {res}"


def test_bdpt_motion_soft_falloff_matches_pt():
    """A soft-falloff light's own visibility rays (V(c, x), soft_light_path.h) at the path's
    time too: the box's shadow slides under a ball light."""
    scene = _lit_moving("slide", soft=True)
    lan = _renders(scene, "bdpt", 1)
    metrics.assert_agreement("slide soft bdpt", lan, _pt("slide soft", scene), block=8,
                             se_floor=1e-6)
    still = _pt("slide soft still", _lit(mb._static_at("slide", 0.5), soft=True))
    res = metrics.compare_renders(lan, still, block=8, se_floor=1e-6)
    assert not res.passed, f"slide soft bdpt: agrees with the still frame: {res}"
