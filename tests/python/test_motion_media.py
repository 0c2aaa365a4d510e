"""Volumes under motion blur (docs/motion_blur.md, "Subsurface and volumes"): a box sliding over
the shutter through a still fog box (a homogeneous scattering mesh volume) and through a world
volume, and the fog box itself sliding around a still box, rendered by pt (its rays through
media, shadow rays and equiangular ones included, at the path's time; a moving volume's
boundary where it is then), against an independent estimate of the same shutter integral (per
seed, J static renders with the mesh placed exactly at the times (j + u) / J, u uniform per
seed; the core's motion code not involved), by lantern.metrics.assert_agreement with its
negative controls; each must differ from the still frame. A moving heterogeneous volume and a
deforming one warn and stay where they were exported (the same bits as without their motion);
a camera that crosses a volume's boundary over the shutter, or that a moving volume may reach,
warns. bdpt, lvc, cis and lt render these scenes themselves: test_motion_media_bidir.py."""
import numpy as np
import pytest

import lantern
from lantern import metrics, session
from lantern.scenes import aabb_mesh

from shutter_ref import box as _box, shutter_average

pytestmark = pytest.mark.skipif(not session.native_available(),
                                reason=f"lantern._core not built ({session.native_error()})")

K, SPP, J, SIZE = 8, 64, 16, 24
BOX = 1  # the moving mesh
FOG = 2  # the fog box (mesh volume scenes)


def _x(t):
    """The box's x over the shutter: 1.6 m, through the fog box."""
    return -0.8 + 1.6 * t


def _fx(t):
    """The fog box's x over the shutter (case "fog"): 0.8 m, the still box inside at all times."""
    return -0.4 + 0.8 * t


def _scene(x, kind, fog_x=0.0):
    """A floor, a red box at x, and either a fog box (1.6 m wide, scattering, around the box's
    path, moved by fog_x; kind "mesh") or a thin world fog (kind "world"), under a point light
    and a dim world."""
    sc = lantern.Scene()
    sc.film["width"] = sc.film["height"] = SIZE
    sc.look_at((0.0, -5.0, 2.5), (0.0, 0.0, 0.5), up=(0, 0, 1), fov=40)
    floor = sc.add_material("floor", base_color=(0.8, 0.8, 0.8))
    red = sc.add_material("red", base_color=(0.8, 0.2, 0.1))
    sc.add_mesh(np.array([[-6, -6, 0], [6, -6, 0], [6, 6, 0], [-6, 6, 0]], np.float32),
                np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=floor)
    v, f = _box((0.35, 0.35, 0.35))
    sc.add_mesh((v + (x, 0.0, 0.4)).astype(np.float32), f, material=red)
    if kind == "mesh":
        fog = sc.add_material("fog")
        sc.materials[fog]["volume"] = {"sigma_s": [0.9, 0.9, 0.9], "sigma_a": [0.1, 0.1, 0.1],
                                       "g": 0.3}
        sc.materials[fog]["volume_only"] = True
        p, idx = aabb_mesh((-0.8 + fog_x, -0.8, 0.02), (0.8 + fog_x, 0.8, 1.2))
        sc.add_mesh(p, idx, material=fog)
    else:
        sc.world["volume"] = {"sigma_s": [0.06, 0.06, 0.06], "sigma_a": [0.02, 0.02, 0.02]}
    sc.add_light("point", position=(1.0, -1.5, 3.0), radius=0.1, power=(400.0, 400.0, 400.0))
    sc.world["color"] = (0.1, 0.1, 0.1)
    return sc


def _moving(kind, mesh=BOX, x=_x):
    """The motion scene: exported at the shutter's middle, 3 matrices over it (mesh: which one
    moves, along x(t))."""
    sc = _scene(_x(0.5), kind)
    sc.meshes[mesh]["motion"] = [np.asarray(np.eye(4)) for _ in range(3)]
    for k, t in enumerate((0.0, 0.5, 1.0)):
        sc.meshes[mesh]["motion"][k][0, 3] = x(t) - x(0.5)
    sc.meshes[mesh]["motion_base"] = np.eye(4)
    return sc


CASES = {  # the motion scene, and the still scene at time t
    "mesh": (lambda: _moving("mesh"), lambda t: _scene(_x(t), "mesh")),
    "world": (lambda: _moving("world"), lambda t: _scene(_x(t), "world")),
    "fog": (lambda: _moving("mesh", FOG, _fx), lambda t: _scene(_x(0.5), "mesh", _fx(t))),
}


def _render(scene, seed, spp, integrator="pt"):
    s = lantern.Session(scene, integrator=integrator, seed=seed, spp_per_iteration=spp,
                        threads=1, max_depth=4)
    s.step()
    return np.asarray(s.image(), np.float64), list(s.warnings)


def _reference(kind, seed):
    return shutter_average(CASES[kind][1], lambda *a: _render(*a)[0], seed, 3000, SPP, J)


@pytest.mark.parametrize("kind", list(CASES))
def test_media_motion_matches_static_average(kind):
    lan = []
    for k in range(K):
        img, warnings = _render(CASES[kind][0](), 1 + k, SPP)
        assert not warnings, warnings
        lan.append(img)
    lan = np.stack(lan)
    assert np.isfinite(lan).all()
    ref = np.stack([_reference(kind, k) for k in range(K)])
    metrics.assert_agreement(f"media {kind}", lan, ref, block=8, se_floor=1e-6,
                             image_bias=0.02, block_bias=0.10)
    sharp = np.stack([_render(CASES[kind][1](0.5), 1 + k, SPP)[0] for k in range(K)])
    res = metrics.compare_renders(lan, sharp, block=8, se_floor=1e-6)
    assert not res.passed, f"{kind}: the motion render agrees with the still frame: {res}"


def _heterogeneous(sc):
    g = sc.add_grid(np.full((4, 4, 4), 0.8, np.float32), np.diag([0.5, 0.5, 0.3, 1.0]) @
                    np.array([[1, 0, 0, -2.0], [0, 1, 0, -2.0], [0, 0, 1, 0.0], [0, 0, 0, 1]]),
                    name="fog:density")
    sc.materials[sc.material_id("fog")].update(density_grid=g)


def _deforming(sc):
    p = np.asarray(sc.meshes[FOG]["positions"], np.float32)
    top = p[:, 2] > 1.0
    steps = []
    for dz in (-0.2, 0.0, 0.2):
        q = p.copy()
        q[top, 2] += dz
        steps.append(q)
    sc.meshes[FOG]["deform"] = np.stack(steps)


@pytest.mark.parametrize("case, words", [
    (_heterogeneous, "bounds a heterogeneous volume that cannot follow it (a density grid"),
    (_deforming, "bounds a volume: its deformation is not motion-blurred"),
])
def test_volume_that_stays_warns(case, words):
    """A sliding heterogeneous fog box, a deforming one (its top rising over the shutter): a
    warning naming it, and the bits of the scene without that motion."""
    sc = _moving("mesh", FOG, _fx) if case is _heterogeneous else _scene(_x(0.5), "mesh")
    case(sc)
    img, warnings = _render(sc, 4, 4)
    assert any(words in w for w in warnings), warnings
    assert np.isfinite(img).all()
    still = _scene(_x(0.5), "mesh")
    case(still)
    still.meshes[FOG].pop("deform", None)
    assert np.array_equal(img, _render(still, 4, 4)[0])


def test_moving_volume_reaching_the_camera_warns():
    sc = _moving("mesh", FOG, _fx)
    sc.look_at((0.5, 0.5, 0.6), (0.5, 5.0, 0.6), up=(0, 0, 1), fov=40)
    img, warnings = _render(sc, 6, 2)
    assert np.isfinite(img).all()
    assert any("may reach the camera" in w for w in warnings), warnings


def test_camera_crossing_a_boundary_warns():
    sc = _scene(_x(0.5), "mesh")
    steps = []
    for y in (-5.0, -2.5, 0.0):  # from outside the fog box to its middle
        c = _scene(_x(0.5), "mesh")
        c.look_at((0.0, y, 0.6), (0.0, y + 5.0, 0.6), up=(0, 0, 1), fov=40)
        steps.append(np.array(c.camera["to_world"]))
    sc.camera["motion"] = steps
    img, warnings = _render(sc, 6, 2)
    assert np.isfinite(img).all()
    assert any("the camera crosses a volume's boundary" in w for w in warnings), warnings
