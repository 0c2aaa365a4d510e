"""Depth of field (integrator/camera.h, the thin lens; lt.h connect_camera through the lens).

- A point in the focal plane stays sharp: an emitter there renders as with a pinhole.
- A defocused one blurs by the radius the aperture gives: an emitter at depth D seen through a
  lens of radius R focused at F spreads over a disk of radius R |D - F| / D on the focal plane;
  its image's spatial variance grows by that disk's (r^2 / 4 per axis), its total stays.
- Light tracing (lt) and bdpt through the lens agree with pt (z-test from independent seeds).
- f-stop 0 or huge and focus distance 0: finite images.
"""
import math

import numpy as np
import pytest

import lantern
from lantern import metrics, scenes

K = 8


@pytest.fixture(scope="module")
def core():
    if not lantern.native_available():
        pytest.skip(f"lantern._core is not built ({lantern.native_error()})")
    from lantern import _core
    return _core


def renders(scene, integrator, spp, seed0, k_seeds=K, max_depth=6, **settings):
    out = []
    for k in range(k_seeds):
        s = lantern.Session(scene, integrator=integrator, seed=seed0 + k, backend="cpu",
                            max_depth=max_depth, spp_per_iteration=max(1, spp // 4), **settings)
        for _ in range(4):
            s.step()
        out.append(s.image())
    return out


HALF = 0.05  # screen half-width on the z = -1 plane


def spot_scene(depth, side, size=64, dof=None):
    """Camera at the origin looking down -Z; a black emissive square of `side` m facing it at
    `depth` m, centred on the view axis."""
    scene = lantern.Scene()
    scene.film.update(width=size, height=size)
    scene.camera["screen"] = [-HALF, HALF, -HALF, HALF]
    scene.camera["clip"] = [0.01, 100.0]
    if dof is not None:
        scene.camera["dof"] = dof
    glow = scene.add_material("glow", base_color=(0.0, 0.0, 0.0), emission=(1.0, 1.0, 1.0))
    h = side / 2
    scene.add_mesh(np.array([[-h, -h, -depth], [h, -h, -depth], [h, h, -depth],
                             [-h, h, -depth]], np.float32),
                   np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=glow, name="spot")
    return scene


def moments(img):
    """Total, and the variance in x and y (pixels^2) of an image's luminance."""
    lum = img[..., :3].mean(axis=2).astype(np.float64)
    h, w = lum.shape
    y, x = np.mgrid[0:h, 0:w] + 0.5
    tot = lum.sum()
    mx, my = (lum * x).sum() / tot, (lum * y).sum() / tot
    return tot, (lum * (x - mx) ** 2).sum() / tot, (lum * (y - my) ** 2).sum() / tot


def test_focal_plane_stays_sharp(core):
    depth = 2.0
    sharp = spot_scene(depth, 0.04)
    lens = spot_scene(depth, 0.04, dof={"radius": 0.05, "focus_distance": depth})
    pin = renders(sharp, "pt", 16, 1)
    dof = renders(lens, "pt", 16, 100)
    ok, cmp, over3, allowed = metrics.agreement(dof, pin, block=8)
    print(f"in focus vs pinhole: {cmp}")
    assert ok, str(cmp)


@pytest.mark.parametrize("blades", [0, 5])
def test_defocus_blurs_by_the_aperture(core, blades):
    # (the image is the pinhole's convolved with the circle of confusion: variances add, so a
    # square of a few pixels keeps the hit counts, and the noise, small)
    depth, focus, radius, side = 2.0, 4.0, 0.05, 0.02
    dof = {"radius": radius, "focus_distance": focus, "blades": blades, "rotation": 0.3}
    pin = renders(spot_scene(depth, side), "pt", 512, 1, k_seeds=2)
    blur = renders(spot_scene(depth, side, dof=dof), "pt", 1024, 50, k_seeds=2)
    t0, vx0, vy0 = moments(np.mean(pin, axis=0))
    t1, vx1, vy1 = moments(np.mean(blur, axis=0))
    # circle of confusion on the focal plane, in screen units of the z = -1 plane, in pixels
    r_pix = radius * abs(depth - focus) / depth / focus / (2 * HALF) * 64
    if blades >= 3:  # a regular n-gon of circumradius 1: variance per axis (1 + 2 cos^2(pi/n)) / 12
        n = blades
        var = r_pix ** 2 * (1.0 + 2.0 * math.cos(math.pi / n) ** 2) / 12.0
    else:
        var = r_pix ** 2 / 4.0  # uniform disk
    print(f"blades {blades}: r {r_pix:.2f} px, total {t1 / t0:.4f} of the pinhole's, added "
          f"variance x {vx1 - vx0:.3f} y {vy1 - vy0:.3f}, expected {var:.3f}")
    assert abs(t1 / t0 - 1.0) < 0.02
    assert abs((vx1 - vx0) / var - 1.0) < 0.05
    assert abs((vy1 - vy0) / var - 1.0) < 0.05


def dof_box():
    scene = scenes.cornell_box(32, 32)
    # focused on the short box, aperture wide enough to blur the back wall and the light
    scene.camera["dof"] = {"radius": 0.15, "focus_distance": 3.2, "blades": 6, "rotation": 0.2}
    return scene


@pytest.mark.parametrize("integrator", ["lt", "bdpt", "cis"])
def test_light_paths_through_the_lens_agree_with_pt(core, integrator):
    scene = dof_box()
    pt = renders(scene, "pt", 128, 1000)
    other = renders(scene, integrator, 64 if integrator != "lt" else 128, 3000)
    ok, cmp, over3, allowed = metrics.agreement(other, pt, block=8)
    print(f"dof {integrator}: {cmp}; |z| > 3 in {over3} (allowed {allowed})")
    assert all(np.isfinite(i).all() for i in other)
    assert ok, str(cmp)


@pytest.mark.parametrize("dof", [{"radius": 0.05 / (2 * 1e-5), "focus_distance": 1.0},
                                 {"radius": 0.05 / (2 * 1e6), "focus_distance": 1.0},
                                 {"radius": 0.01, "focus_distance": 0.0}],
                         ids=["fstop-0", "fstop-huge", "focus-0"])
def test_extreme_lenses_stay_finite(core, dof):
    scene = scenes.cornell_box(16, 16)
    scene.camera["dof"] = dof
    for integrator in ("pt", "bdpt"):
        img = lantern.render(scene, spp=4, integrator=integrator, seed=1)
        assert np.isfinite(img).all()
