"""Deformation motion blur's scene input (docs/motion_blur.md): mesh["deform"], the positions at
the shutter's steps, is checked (its shape by the schema; non-finite values by the core) and
kept by the scene file. The core does not render deformation yet: a deforming mesh renders where
it was exported, bit for bit, with one warning naming it; bad steps (NaN, a wrong count) get
their own message and a finite image."""
import numpy as np
import pytest

import lantern
from lantern import session

pytestmark = pytest.mark.skipif(not session.native_available(),
                                reason=f"lantern._core not built ({session.native_error()})")

SIZE = 16
BLOB = 1  # the deforming mesh


def _scene():
    sc = lantern.Scene()
    sc.film["width"] = sc.film["height"] = SIZE
    sc.look_at((0.0, -5.0, 3.0), (0.0, 0.0, 0.5), up=(0, 0, 1), fov=40)
    floor = sc.add_material("floor", base_color=(0.8, 0.8, 0.8))
    red = sc.add_material("red", base_color=(0.8, 0.2, 0.1))
    sc.add_mesh(np.array([[-6, -6, 0], [6, -6, 0], [6, 6, 0], [-6, 6, 0]], np.float32),
                np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=floor)
    v = np.array([[-1, -1, 0.2], [1, -1, 0.2], [1, 1, 0.2], [-1, 1, 0.2], [0, 0, 1.5]],
                 np.float32)
    f = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]], np.uint32)
    sc.add_mesh(v, f, material=red, name="Blob")
    sc.world["color"] = (1.0, 1.0, 1.0)
    return sc


def _deforming(steps=3):
    """The pyramid's apex moves from -0.8 to +0.8 m along x over the shutter."""
    sc = _scene()
    p = np.asarray(sc.meshes[BLOB]["positions"], np.float32)
    out = []
    for t in np.linspace(0.0, 1.0, steps):
        q = p.copy()
        q[4, 0] = -0.8 + 1.6 * t
        out.append(q)
    sc.meshes[BLOB]["deform"] = np.stack(out)
    return sc


def _render(scene, seed=3, spp=4):
    s = lantern.Session(scene, integrator="pt", seed=seed, spp_per_iteration=spp, threads=1,
                        max_depth=3)
    s.step()
    return np.asarray(s.image(), np.float64), list(s.warnings)


def test_deforming_mesh_warns_and_renders_as_exported():
    still, quiet = _render(_scene())
    assert not [w for w in quiet if "deform" in w], quiet
    img, warnings = _render(_deforming())
    hits = [w for w in warnings if "deformation motion blur is not rendered yet" in w]
    assert len(hits) == 1 and "mesh 'Blob'" in hits[0], warnings
    assert np.array_equal(img, still)


@pytest.mark.parametrize("bad", ["nan", "inf"])
def test_non_finite_step_warns_and_renders_finite(bad):
    sc = _deforming()
    sc.meshes[BLOB]["deform"][2, 4, 1] = np.nan if bad == "nan" else np.inf
    img, warnings = _render(sc)
    assert np.isfinite(img).all()
    hits = [w for w in warnings if "deform" in w]
    assert len(hits) == 1, warnings
    assert "mesh 'Blob'" in hits[0] and "deformation step 2 is not finite" in hits[0], hits
    assert np.array_equal(img, _render(_scene())[0])


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
