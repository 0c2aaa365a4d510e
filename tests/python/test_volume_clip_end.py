"""World fog past the camera's clip end (D46, docs/difftest.md): a camera ray that misses goes on
to infinity in the world's medium, whatever its clip end, so light from the world through an
absorbing world fog is 0, as in Cycles (shade_volume gives a miss the segment FLT_MAX). Lantern
ended the segment at the clip end: exp(-sigma x clip) of the world came through. A lamp past
the clip end is still not met, one inside it is, through the fog up to it (the positive
controls: the fog is there and the image is not black for want of light)."""
import math

import numpy as np
import pytest

import lantern

pytestmark = pytest.mark.skipif(not lantern.native_available(), reason="native core unavailable")

SIGMA = 0.05  # absorption, 1/m: exp(-SIGMA x 10) = 0.61 of the world came through before


def fog_scene(clip_end, lamp_at=None):
    s = lantern.Scene()
    s.film.update(width=4, height=4)
    s.camera = {"type": "orthographic", "screen": [-0.1, 0.1, -0.1, 0.1], "clip": [0.0, clip_end]}
    s.world = {"color": [1.0, 1.0, 1.0], "volume": {"sigma_a": [SIGMA] * 3}}
    if lamp_at is not None:  # a large rectangle facing the camera at z = -lamp_at
        to_world = np.diag([1.0, -1.0, -1.0, 1.0])
        to_world[2, 3] = -lamp_at
        s.add_light("area", to_world=to_world.tolist(), shape="rectangle", size=[4.0, 4.0],
                    power=[16.0 * math.pi] * 3, visible_camera=True)
    return s


def mean_rgb(scene, integrator):
    sess = lantern.Session(scene, integrator=integrator, seed=1, spp_per_iteration=4,
                           max_depth=1, threads=1)
    sess.step()
    return np.asarray(sess.image())[..., :3].reshape(-1, 3).mean(axis=0)


@pytest.mark.parametrize("integrator", ["pt", "bdpt"])
def test_world_through_fog_past_clip_end_is_black(integrator):
    np.testing.assert_array_equal(mean_rgb(fog_scene(10.0), integrator), 0.0)


@pytest.mark.parametrize("integrator", ["pt", "bdpt"])
def test_lamp_in_fog_within_clip_end_only(integrator):
    # the lamp's radiance: power / (area x pi) = 1, through 20 m of fog
    seen = mean_rgb(fog_scene(100.0, lamp_at=20.0), integrator)
    np.testing.assert_allclose(seen, math.exp(-SIGMA * 20.0), rtol=1e-3)
    np.testing.assert_array_equal(mean_rgb(fog_scene(10.0, lamp_at=20.0), integrator), 0.0)
