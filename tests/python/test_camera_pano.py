"""Panoramic equirectangular camera (integrator/camera.h pano_direction; lt.h's connection).

- Blender's convention: a full panorama looking along +X (Z up) renders the world's
  equirectangular map itself (docs: "pointing along the positive X-axis ... the default
  environment texture mapping").
- lt, bdpt and cis through the panorama agree with pt (z-test from independent seeds),
  across the 360-degree seam too.
"""
import math

import numpy as np
import pytest

import lantern
from lantern import metrics, scenes

K = 8
ALONG_X = [[0, 0, -1, 0], [-1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 1]]  # -Z_local -> +X, Y -> +Z


@pytest.fixture(scope="module")
def core():
    if not lantern.native_available():
        pytest.skip(f"lantern._core is not built ({lantern.native_error()})")
    from lantern import _core
    return _core


def renders(scene, integrator, spp, seed0, k_seeds=K, **settings):
    out = []
    for k in range(k_seeds):
        s = lantern.Session(scene, integrator=integrator, seed=seed0 + k, backend="cpu",
                            max_depth=6, spp_per_iteration=max(1, spp // 4), **settings)
        for _ in range(4):
            s.step()
        out.append(s.image())
    return out


def smooth_sky(w=64, h=32):
    v = (np.arange(h) + 0.5) / h
    u = (np.arange(w) + 0.5) / w
    m = np.zeros((h, w, 3), np.float32)
    m[..., 0] = 0.3 + 0.6 * v[:, None] + 0.2 * np.sin(2 * np.pi * u)[None, :]
    m[..., 1] = 0.4 + 0.2 * np.cos(2 * np.pi * u)[None, :]
    m[..., 2] = 1.0 - 0.7 * v[:, None]
    return m


def test_full_panorama_renders_the_world_map(core):
    sky = smooth_sky()
    scene = lantern.Scene()
    scene.film.update(width=64, height=32)
    scene.camera.update(type="equirectangular", to_world=ALONG_X)
    scene.world = {"color": [0.0] * 3, "map": sky}
    imgs = renders(scene, "pt", 32, 1)
    expected = np.ascontiguousarray(sky[::-1], np.float64)  # top row first
    # allowance: the pixel filter's blur of this smooth map across block edges (< 1%)
    cmp = metrics.compare_sets(imgs, expected, block=8, se_floor=0.01 * float(sky.max()))
    print(f"panorama vs map: {cmp}")
    assert cmp.passed(1e-3), str(cmp)
    # and a quarter turn of the camera (looking along +Y: the map's u = 0.25 at the centre)
    # rolls the image by a quarter
    scene.camera["to_world"] = [[1, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0], [0, 0, 0, 1]]
    turned = renders(scene, "pt", 32, 50)
    rolled = np.roll(sky[::-1], 16, axis=1).astype(np.float64)
    cmp = metrics.compare_sets(turned, rolled, block=8, se_floor=0.01 * float(sky.max()))
    print(f"turned panorama vs rolled map: {cmp}")
    assert cmp.passed(1e-3), str(cmp)


def pano_box():
    scene = scenes.cornell_box(32, 16)
    scene.camera = {"type": "equirectangular", "clip": [0.01, 100.0],
                    "to_world": [[1, 0, 0, 0.1], [0, 0, -1, 0.2], [0, 1, 0, 0.9],
                                 [0, 0, 0, 1]]}  # inside the box, looking at the back wall
    scene.world = {"color": [0.3, 0.3, 0.35]}      # through the open front: behind the camera
    return scene


@pytest.mark.parametrize("integrator", ["lt", "bdpt", "cis"])
def test_light_paths_through_the_panorama_agree_with_pt(core, integrator):
    scene = pano_box()
    if integrator == "lt":  # lt cannot see the world directly: hidden from the camera in both
        scene.world["visible_camera"] = False
    pt = renders(scene, "pt", 128, 1000)
    other = renders(scene, integrator, 128, 3000)
    ok, cmp, over3, allowed = metrics.agreement(other, pt, block=8)
    print(f"panorama {integrator}: {cmp}; |z| > 3 in {over3} (allowed {allowed})")
    assert all(np.isfinite(i).all() for i in other)
    assert ok, str(cmp)
