"""Subsurface scattering under motion blur (docs/motion_blur.md, "Subsurface"): a box of
Principled BSDF with Subsurface Weight 1 (Random Walk) slides or spins over the shutter; the walk
under its surface traces its rays at the path's time and enters and leaves the box where it is
then. Against an independent estimate of the same shutter integral (test_motion_blur.py's: per
seed, J static renders of the box placed exactly at the times (j + u) / J, u uniform per seed;
the core's motion code not involved), by lantern.metrics.assert_agreement with its negative
controls; each motion render must differ from the still frame, and from the same motion with
the subsurface taken out (the scene resolves the walk). bdpt and cis walk their camera paths at
the path's time (bdpt_sss.h): each against pt's motion render. Cycles: tests/cycles/
test_motion_sss.py."""
import numpy as np
import pytest

import lantern
from lantern import metrics, session

from shutter_ref import box as _box, rz as _rz, shutter_average, tr as _tr

pytestmark = pytest.mark.skipif(not session.native_available(),
                                reason=f"lantern._core not built ({session.native_error()})")

K, SPP, J, SIZE = 8, 64, 16, 24
BOX = 1  # the moving mesh


# object-to-world of the box at shutter time t in [0, 1]
MOTIONS = {
    "slide": lambda t: _tr(-0.8 + 1.6 * t, 0.0, 0.5),
    "spin": lambda t: _tr(0.0, 0.0, 0.5) @ _rz(-0.5 * np.pi + np.pi * t),  # 180 degrees
}


def _scene(local_to_world, sss=1.0):
    """A floor and a 1.6 x 0.5 x 1 box of subsurface material (mean free paths of a few cm to
    30 cm: the light goes through the box's thin side) placed by local_to_world, lit by a
    point light behind and above it and a dim world."""
    sc = lantern.Scene()
    sc.film["width"] = sc.film["height"] = SIZE
    sc.look_at((0.0, -5.0, 3.0), (0.0, 0.0, 0.5), up=(0, 0, 1), fov=40)
    floor = sc.add_material("floor", base_color=(0.8, 0.8, 0.8))
    wax = sc.add_material("wax", type="principled", base_color=(0.9, 0.6, 0.4), roughness=0.5,
                          subsurface={"weight": sss, "radius": [0.3, 0.15, 0.08],
                                      "method": "random_walk"})
    sc.add_mesh(np.array([[-6, -6, 0], [6, -6, 0], [6, 6, 0], [-6, 6, 0]], np.float32),
                np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=floor)
    v, f = _box((0.8, 0.25, 0.5))
    m = local_to_world
    sc.add_mesh((v @ m[:3, :3].T + m[:3, 3]).astype(np.float32), f, material=wax)
    sc.add_light("point", position=(0.5, 2.0, 2.5), radius=0.1, power=(600.0, 600.0, 600.0))
    sc.world["color"] = (0.15, 0.15, 0.15)
    return sc


def _moving(name, sss=1.0):
    """The motion scene: exported at the shutter's middle, 3 matrices over it."""
    f = MOTIONS[name]
    sc = _scene(f(0.5), sss)
    sc.meshes[BOX]["motion"] = [f(t) for t in np.linspace(0.0, 1.0, 3)]
    sc.meshes[BOX]["motion_base"] = f(0.5)
    return sc


def _render(scene, seed, spp, integrator="pt"):
    s = lantern.Session(scene, integrator=integrator, seed=seed, spp_per_iteration=spp,
                        threads=1, max_depth=4)
    s.step()
    return np.asarray(s.image(), np.float64), list(s.warnings)


def _renders(scene, spp, integrator="pt", seed0=1):
    out = []
    for k in range(K):
        img, warnings = _render(scene, seed0 + k, spp, integrator)
        assert not warnings, warnings
        out.append(img)
    out = np.stack(out)
    assert np.isfinite(out).all()
    return out


def _reference(name, seed):
    return shutter_average(lambda t: _scene(MOTIONS[name](t)), lambda *a: _render(*a)[0], seed,
                           2000, SPP, J)


@pytest.mark.parametrize("name", ["slide", "spin"])
def test_sss_motion_matches_static_average(name):
    lan = _renders(_moving(name), SPP)
    ref = np.stack([_reference(name, k) for k in range(K)])
    metrics.assert_agreement(f"sss {name}", lan, ref, block=8, se_floor=1e-6,
                             image_bias=0.02, block_bias=0.10)
    # blurred: the frame's sharp image differs
    sharp = _renders(_scene(MOTIONS[name](0.5)), SPP)
    res = metrics.compare_renders(lan, sharp, block=8, se_floor=1e-6)
    assert not res.passed, f"{name}: the motion render agrees with the still frame: {res}"
    # the scene resolves the walk: the same motion with the diffuse base instead differs
    flat = _renders(_moving(name, sss=0.0), SPP)
    res = metrics.compare_renders(lan, flat, block=8, se_floor=1e-6)
    assert not res.passed, f"{name}: the walk does not show: {res}"


@pytest.mark.parametrize("integrator", ["bdpt", "cis"])
def test_sss_motion_bidirectional_matches_pt(integrator):
    """The bidirectional camera paths' walks at their time (bdpt: the path's own; cis: the
    pass's, as SPP passes of one sample) against pt, on the spin."""
    scene = _moving("spin")
    pt = _renders(scene, SPP)
    if integrator == "cis":
        other = []
        for k in range(K):
            s = lantern.Session(scene, integrator="cis", seed=50 + k, spp_per_iteration=1,
                                threads=1, max_depth=4)
            for _ in range(SPP):
                s.step()
            assert not s.warnings, list(s.warnings)
            other.append(np.asarray(s.image(), np.float64))
        other = np.stack(other)
    else:
        other = _renders(scene, SPP, integrator, seed0=50)
    assert np.isfinite(other).all()
    metrics.assert_agreement(f"sss spin {integrator}", other, pt, block=8, se_floor=1e-6,
                             image_bias=0.02, block_bias=0.10)


def test_sss_still_scene_keeps_bits():
    """Steps that do not move: no motion, the still scene's bits (the walk's time unread)."""
    m = MOTIONS["slide"](0.5)
    still = _scene(m)
    same = _scene(m)
    same.meshes[BOX]["motion"] = [m, m, m]
    same.meshes[BOX]["motion_base"] = m
    a, _ = _render(still, 3, 4)
    assert np.array_equal(a, _render(same, 3, 4)[0])
    assert not np.array_equal(a, _render(_moving("slide"), 3, 4)[0])
