"""Panoramic equirectangular camera (integrator/camera.h pano_direction; lt.h's connection).

- Blender's convention: a full panorama looking along +X (Z up) renders the world's
  equirectangular map itself (docs: "pointing along the positive X-axis ... the default
  environment texture mapping").
- lt, bdpt and cis through the panorama agree with pt (lantern.metrics.assert_agreement with
  its 1 % / 5 % negative controls, tests/README.md), across the 360-degree seam too.
"""

import numpy as np
import pytest

import lantern
from lantern import metrics, scenes

K = 16  # seeds per set (Welch dof >= 15)
ALONG_X = [[0, 0, -1, 0], [-1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 1]]  # -Z_local -> +X, Y -> +Z


def renders(scene, integrator, spp, seed0, k_seeds=K, **settings):
    out = []
    for k in range(k_seeds):
        s = lantern.Session(scene, integrator=integrator, seed=seed0 + k, backend="cpu",
                            max_depth=6, spp_per_iteration=max(1, spp // 4), **settings)
        for _ in range(4):
            s.step()
        out.append(s.image())
    return out


PANO_CAP = 0.002
POLES = slice(2, 30)  # rows compared: the filter (1.5 px) of rows 2..29 stays off the poles


def smooth_sky(w=64, h=32):
    v = (np.arange(h) + 0.5) / h
    u = (np.arange(w) + 0.5) / w
    m = np.zeros((h, w, 3), np.float32)
    m[..., 0] = 0.3 + 0.6 * v[:, None] + 0.2 * np.sin(2 * np.pi * u)[None, :]
    m[..., 1] = 0.4 + 0.2 * np.cos(2 * np.pi * u)[None, :]
    m[..., 2] = 1.0 - 0.7 * v[:, None]
    return m


def panorama_map(turned, seed0):
    """test_full_panorama_renders_the_world_map's renders (rows POLES) and their exact map:
    looking along +X, or `turned` a quarter (along +Y: the map rolled by a quarter)."""
    sky = smooth_sky()
    scene = lantern.Scene()
    scene.film.update(width=64, height=32)
    scene.camera.update(type="equirectangular", to_world=ALONG_X)
    scene.world = {"color": [0.0] * 3, "map": sky}
    if turned:
        scene.camera["to_world"] = [[1, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0], [0, 0, 0, 1]]
        expected = np.roll(sky[::-1], 16, axis=1).astype(np.float64)
    else:
        expected = np.ascontiguousarray(sky[::-1], np.float64)  # top row first
    return [x[POLES] for x in renders(scene, "pt", 16, seed0)], expected[POLES]


def test_full_panorama_renders_the_world_map(core):
    imgs, expected = panorama_map(False, 1)
    # the pixel filter and the texture lookup blur this smooth map; inside a block that
    # averages out to second order (the sine's curvature times the filter's variance: ~2e-4
    # of the sky's level), within the bias cap PANO_CAP. The two rows at the top and the
    # bottom are left out: their filter reaches over the pole, where u turns by half
    metrics.assert_agreement("panorama vs map", imgs, expected, block=4, bias_cap=PANO_CAP)
    # and a quarter turn of the camera (looking along +Y: the map's u = 0.25 at the centre)
    # rolls the image by a quarter
    turned, rolled = panorama_map(True, 50)
    metrics.assert_agreement("turned panorama vs rolled map", turned, rolled, block=4,
                             bias_cap=PANO_CAP)


def pano_box():
    scene = scenes.cornell_box(32, 16)
    scene.camera = {"type": "equirectangular", "clip": [0.01, 100.0],
                    "to_world": [[1, 0, 0, 0.1], [0, 0, -1, 0.2], [0, 1, 0, 0.9],
                                 [0, 0, 0, 1]]}  # inside the box, looking at the back wall
    scene.world = {"color": [0.3, 0.3, 0.35]}      # through the open front: behind the camera
    return scene


_PT = {}


def pt_reference(lt):
    """pt through the panorama, rendered once for the three comparisons (lt's with the world
    hidden from the camera)."""
    if lt not in _PT:
        scene = pano_box()
        scene.world["visible_camera"] = not lt
        _PT[lt] = renders(scene, "pt", PT_SPP, 1000)
    return _PT[lt]


# spp per seed: pt's two references (16 x 96: the samples of the 3 x 8 x 128 it took before),
# and each integrator's, where its noise is: lt's is 7x pt's per block at equal samples (lt at
# 64 resolved 2.25 % / 10 %), bdpt and cis at 64 over-resolved (0.68-0.74 % / 1.5-1.7 %)
PT_SPP, SPP = 96, {"lt": 384, "bdpt": 32, "cis": 32}


@pytest.mark.parametrize("integrator", ["lt", "bdpt", "cis"])
def test_light_paths_through_the_panorama_agree_with_pt(core, integrator):
    scene = pano_box()
    if integrator == "lt":  # lt cannot see the world directly: hidden from the camera in both
        scene.world["visible_camera"] = False
    pt = pt_reference(integrator == "lt")
    other = renders(scene, integrator, SPP[integrator], 3000)
    assert all(np.isfinite(i).all() for i in other)
    metrics.assert_agreement(f"panorama {integrator} vs pt", other, pt, block=8)
