"""Deformation motion blur (docs/motion_blur.md): mesh["deform"], the positions at the shutter's
steps, rendered by pt against an independent estimate of the same shutter integral: each seed's
reference averages J static renders of the mesh with its vertices placed here at the times
(j + u) / J (u uniform per seed), the core's motion code not involved; with transform motion of
the same object too; Embree's motion-blur triangles against the built-in BVH's refitted bottom
level. Compared by lantern.metrics with negative controls (the still frame must differ). Bad
input: a non-finite step or a wrong shape gets a message and a finite image; the scene file
keeps `deform`."""
import numpy as np
import pytest

import lantern
from lantern import metrics, session

from shutter_ref import assert_embree_matches_bvh, shutter_average, tr as _tr

pytestmark = pytest.mark.skipif(not session.native_available(),
                                reason=f"lantern._core not built ({session.native_error()})")

K, SPP, J, SIZE = 8, 64, 16, 32
BLOB = 1  # the deforming mesh
APEX = 4


def _apex_x(t):
    """The pyramid's apex (object space) swings from x = -1.2 m to 0 at the shutter's middle and
    back: piecewise linear with a corner at a step (3 or 5 steps lerp it exactly), and its
    shutter average is not the middle's shape (a linear sweep's would be, nearly)."""
    return -1.2 * abs(2.0 * t - 1.0)


def _local(t):
    v = np.array([[-1, -0.6, 0.0], [1, -0.6, 0.0], [1, 0.6, 0.0], [-1, 0.6, 0.0],
                  [0, 0, 1.3]], np.float64)
    v[APEX, 0] = _apex_x(t)
    return v


def _object(t, moves):  # object-to-world: still at z 0.1, or sliding +-0.5 m along y too
    return _tr(0.0, (t - 0.5) if moves else 0.0, 0.1)


def _place(v, m):
    return (v @ m[:3, :3].T + m[:3, 3]).astype(np.float32)


def _scene(t=0.5, moves=False):
    """The stage: a floor, a pyramid whose apex is at shutter time t (placed by the object's
    matrix at t), lit by a white world."""
    sc = lantern.Scene()
    sc.film["width"] = sc.film["height"] = SIZE
    sc.look_at((0.0, -5.0, 3.0), (0.0, 0.0, 0.5), up=(0, 0, 1), fov=40)
    floor = sc.add_material("floor", base_color=(0.8, 0.8, 0.8))
    red = sc.add_material("red", base_color=(0.8, 0.2, 0.1))
    sc.add_mesh(np.array([[-6, -6, 0], [6, -6, 0], [6, 6, 0], [-6, 6, 0]], np.float32),
                np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=floor)
    f = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4], [0, 3, 2], [0, 2, 1]], np.uint32)
    sc.add_mesh(_place(_local(t), _object(t, moves)), f, material=red, name="Blob")
    sc.world["color"] = (1.0, 1.0, 1.0)
    return sc


def _deforming(steps=3, moves=False):
    """Exported at the shutter's middle; `steps` deform steps placed by the frame's matrix (as
    the add-on places them), and the object's own steps when it moves too."""
    sc = _scene(0.5, moves)
    base = _object(0.5, moves)
    ts = np.linspace(0.0, 1.0, steps)
    sc.meshes[BLOB]["deform"] = np.stack([_place(_local(t), base) for t in ts])
    if moves:
        sc.meshes[BLOB]["motion"] = [_object(t, True) for t in ts]
        sc.meshes[BLOB]["motion_base"] = base
    return sc


def _render(scene, seed=3, spp=4):
    s = lantern.Session(scene, integrator="pt", seed=seed, spp_per_iteration=spp, threads=1,
                        max_depth=3)
    s.step()
    return np.asarray(s.image(), np.float64), list(s.warnings)


def _reference(seed, moves):
    return shutter_average(lambda t: _scene(t, moves), lambda *a: _render(*a)[0], seed, 2000,
                           SPP, J)


@pytest.mark.parametrize("moves", [False, True], ids=["deform", "deform+slide"])
def test_deform_matches_static_average(moves):
    scene = _deforming(moves=moves)
    lan = []
    for k in range(K):
        img, warnings = _render(scene, 1 + k, SPP)
        assert not warnings, warnings
        lan.append(img)
    lan = np.stack(lan)
    assert np.isfinite(lan).all()
    ref = np.stack([_reference(k, moves) for k in range(K)])
    name = "deform+slide" if moves else "deform"
    metrics.assert_agreement(name, lan, ref, block=8, se_floor=1e-6)
    sharp = np.stack([_render(_scene(0.5, moves), 1 + k, SPP)[0] for k in range(K)])
    res = metrics.compare_renders(lan, sharp, block=8, se_floor=1e-6)
    assert not res.passed, f"{name}: the deforming render agrees with the still frame: {res}"


def test_embree_deform_matches_builtin_bvh(monkeypatch):
    """Embree's motion-blur triangles (one vertex buffer per step) against the built-in BVH's
    bottom level refitted over the steps with triangles lerped at the ray's time."""
    if not session.require_core().embree_available():
        pytest.skip("Embree is not available")
    assert_embree_matches_bvh("deform embree/bvh", _deforming(5, moves=True), _render,
                              _scene(0.5, True), K, SPP, monkeypatch)


def test_deform_that_does_not_move_keeps_bits():
    sc = _scene()
    p = np.asarray(sc.meshes[BLOB]["positions"], np.float32)
    still = _render(sc)[0]
    sc.meshes[BLOB]["deform"] = np.stack([p, p, p])
    img, warnings = _render(sc)
    assert not warnings, warnings
    assert np.array_equal(img, still)
    assert not np.array_equal(_render(_deforming())[0], still)  # (the test can fail)


@pytest.mark.parametrize("bad", ["nan", "inf"])
def test_non_finite_step_warns_and_renders_finite(bad):
    sc = _deforming()
    sc.meshes[BLOB]["deform"][2, APEX, 1] = np.nan if bad == "nan" else np.inf
    img, warnings = _render(sc)
    assert np.isfinite(img).all()
    hits = [w for w in warnings if "deform" in w]
    assert len(hits) == 1, warnings
    assert "mesh 'Blob'" in hits[0] and "deformation step 2 is not finite" in hits[0], hits
    assert np.array_equal(img, _render(_scene())[0])  # where it was exported


@pytest.mark.parametrize("shape", [(3, 4, 3), (1, 5, 3), (3, 5, 2), (15, 3)])
def test_wrong_shape_is_refused(shape):
    sc = _scene()
    sc.meshes[BLOB]["deform"] = np.zeros(shape, np.float32)
    with pytest.raises(ValueError, match=r"mesh 1 \('Blob'\) deform: expected shape"):
        sc.validate()


def test_deform_survives_the_scene_file(tmp_path):
    scene = _deforming(5)
    path = tmp_path / "deform.lantern"
    scene.save(path)
    loaded = lantern.load_scene(path)
    got = np.asarray(loaded.meshes[BLOB]["deform"])
    assert got.shape == (5, 5, 3) and got.dtype == np.float32
    assert np.array_equal(got, scene.meshes[BLOB]["deform"])
    assert loaded.meshes[0].get("deform") is None  # the floor has none
    a = _render(scene)[0]
    assert np.array_equal(a, _render(loaded)[0])
    assert not np.array_equal(a, _render(_scene())[0])


@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis", "lt"])
def test_bidirectional_renders_deformation_itself(integrator):
    """No hand-over to pt any more (issue 32; test_motion_bidir.py compares bdpt, cis with pt)."""
    s = lantern.Session(_deforming(), integrator=integrator, seed=2, spp_per_iteration=4,
                        threads=1, max_depth=3)
    s.step()
    assert not any("does not render motion blur" in w for w in s.warnings), list(s.warnings)
    assert not np.array_equal(np.asarray(s.image()), _render(_deforming(), 2, 4)[0])
