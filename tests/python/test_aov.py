"""lantern.aov.render_aovs against values known in closed form: a camera looking straight down
at planes (Depth is the camera z, Normal the world normal, Denoising Normal the camera-space
one with Cycles' axes), a diffuse plane's albedo and diffuse colour, an emitter's emission, and
a mirror passed through to the wall it shows (its albedo tinted by the mirror's colour)."""

import numpy as np
import pytest

import lantern
from lantern.aov import render_aovs

pytestmark = pytest.mark.skipif(not lantern.native_available(),
                                reason="lantern native module not built")


def _plane(scene, z, material, half=50.0, flip=False):
    pos = np.array([[-half, -half, z], [half, -half, z], [half, half, z], [-half, half, z]],
                   dtype=np.float32)
    idx = np.array([[0, 1, 2], [0, 2, 3]] if not flip else [[0, 2, 1], [0, 3, 2]],
                   dtype=np.uint32)
    scene.add_mesh(pos, idx, material=material)


def _looking_down(height=5.0, size=16):
    scene = lantern.Scene()
    scene.film.update(width=size, height=size)
    scene.look_at((0.0, 0.0, height), (0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0), fov=30.0)
    return scene


def test_diffuse_plane_passes():
    scene = _looking_down()
    _plane(scene, 0.0, scene.add_material("grey", base_color=(0.2, 0.4, 0.6)))
    a = render_aovs(scene, spp=4)
    np.testing.assert_allclose(a["Depth"], 5.0, rtol=1e-5)
    np.testing.assert_allclose(a["Denoising Depth"], 5.0, rtol=1e-5)
    np.testing.assert_allclose(a["Normal"], np.broadcast_to([0, 0, 1], (16, 16, 3)), atol=1e-6)
    # camera space (x right, y up, z forward): the plane faces the camera, so z = -1
    np.testing.assert_allclose(a["Denoising Normal"], np.broadcast_to([0, 0, -1], (16, 16, 3)),
                               atol=1e-6)
    np.testing.assert_allclose(a["Denoising Albedo"], np.broadcast_to([0.2, 0.4, 0.6], (16, 16, 3)),
                               rtol=1e-6)
    np.testing.assert_allclose(a["Diffuse Color"], a["Denoising Albedo"], rtol=1e-6)
    assert not a["Emission"].any()


def test_background_and_emitter():
    scene = _looking_down(size=8)
    scene.world["color"] = [0.1, 0.2, 0.3]
    a = render_aovs(scene, spp=2)
    np.testing.assert_array_equal(a["Depth"], 1e10)
    assert not a["Normal"].any()
    np.testing.assert_allclose(a["Denoising Albedo"], np.broadcast_to([0.1, 0.2, 0.3], (8, 8, 3)),
                               rtol=1e-6)
    scene2 = _looking_down(size=8)
    _plane(scene2, 0.0, scene2.add_material("lamp", base_color=0.0, emission=(3.0, 2.0, 1.0)))
    a2 = render_aovs(scene2, spp=2)
    np.testing.assert_allclose(a2["Emission"], np.broadcast_to([3, 2, 1], (8, 8, 3)), rtol=1e-6)


def test_mirror_is_passed_through_for_the_denoiser():
    """A smooth mirror (F0 = 0.9) at z = 0 below the camera, seen head-on, reflects a diffuse
    ceiling (facing down, albedo 0.5) at z = 10: Depth and Normal are the mirror's, the
    denoising features the ceiling's, its albedo times the mirror's reflectance."""
    scene = _looking_down(size=8)
    scene.camera["clip"] = [0.01, 100.0]
    mirror = scene.add_material("mirror", type="conductor", base_color=0.9, roughness=0.0)
    _plane(scene, 0.0, mirror)
    _plane(scene, 10.0, scene.add_material("ceiling", base_color=0.5), flip=True)
    a = render_aovs(scene, spp=2)
    np.testing.assert_allclose(a["Depth"], 5.0, rtol=1e-5)
    # reflected ray: 5 m down to the mirror, 10 m up to the ceiling; Denoising Depth is the
    # ceiling's camera z (z = 10 is 5 m behind the camera)
    np.testing.assert_allclose(a["Denoising Depth"], -5.0, rtol=1e-4)
    np.testing.assert_allclose(a["Denoising Albedo"], 0.9 * 0.5, rtol=1e-4)  # exact: 1.2e-7
    assert not a["Diffuse Color"].any()


def test_same_seed_same_passes():
    scene = _looking_down(size=12)
    _plane(scene, 0.0, scene.add_material("p", type="principled", base_color=0.7, roughness=0.4))
    a, b = render_aovs(scene, spp=3, seed=7), render_aovs(scene, spp=3, seed=7)
    for k in a:
        if k != "warnings":
            np.testing.assert_array_equal(a[k], b[k])
