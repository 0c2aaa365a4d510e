"""Depth of field (integrator/camera.h, the thin lens; lt.h connect_camera through the lens).

- A point in the focal plane stays sharp: an emitter there renders as with a pinhole.
- A defocused one blurs by the radius the aperture gives: an emitter at depth D seen through a
  lens of radius R focused at F spreads over a disk of radius R |D - F| / D on the focal plane;
  its image's spatial variance grows by that disk's (r^2 / 4 per axis), its total stays.
- Light tracing (lt), bdpt and cis through the lens agree with pt
  (lantern.metrics.assert_agreement, tests/README.md, with its negative controls).
- f-stop 0 or huge and focus distance 0: finite images.
"""
import math
from pathlib import Path

import numpy as np
import pytest

import lantern
from lantern import metrics, scenes, student_t
from lantern.testing import refs

K = 8


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
    pin = renders(sharp, "pt", 16, 1, k_seeds=16)
    dof = renders(lens, "pt", 16, 100, k_seeds=16)
    metrics.assert_agreement("in focus vs pinhole", dof, pin, block=8)


def _moment_test(name, a, b, expected, cap):
    """a, b: per-seed values of two independent sets (K,); passes when the difference of their
    means is `expected` within cap + t(alpha, Welch dof) se, relative to `expected` (the
    z-test of tests/README.md, on a statistic of the image rather than its blocks)."""
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    se2a, se2b = a.var(ddof=1) / len(a), b.var(ddof=1) / len(b)
    rel = (a.mean() - b.mean()) / expected - 1.0
    se = math.sqrt(se2a + se2b) / abs(expected)
    dof = float(student_t.welch_dof(se2a, len(a), se2b, len(b)))
    allowed = cap + student_t.quantile(ALPHA, dof) * se
    return abs(rel) <= allowed, f"{name}: {rel:+.3%} (se {se:.3%}, allowed {allowed:.3%})"


ALPHA = 1e-3


@pytest.mark.parametrize("blades", [0, 5])
def test_defocus_blurs_by_the_aperture(core, blades):
    """The image is the pinhole's convolved with the circle of confusion: the total stays and
    the variances add. Per seed a pinhole and a lens render (independent seeds); the per-seed
    differences of the moments against the aperture's exact ones (z-test, Student t over the
    seeds), and negative controls: a 1 % brighter image and a lens 2.5 % wider (5 % more
    variance) must fail. The lens side's samples go where its noise is (the blurred edges)."""
    depth, focus, radius, side = 2.0, 4.0, 0.05, 0.02
    dof = {"radius": radius, "focus_distance": focus, "blades": blades, "rotation": 0.3}
    pin = renders(spot_scene(depth, side), "pt", 32, 1, k_seeds=K_MOMENTS)
    blur = renders(spot_scene(depth, side, dof=dof), "pt", 256, 50, k_seeds=K_MOMENTS)
    m0 = np.array([moments(i) for i in pin])
    m1 = np.array([moments(i) for i in blur])
    # circle of confusion on the focal plane, in screen units of the z = -1 plane, in pixels
    r_pix = radius * abs(depth - focus) / depth / focus / (2 * HALF) * 64
    if blades >= 3:  # a regular n-gon of circumradius 1: variance per axis (1 + 2 cos^2(pi/n)) / 12
        n = blades
        var = r_pix ** 2 * (1.0 + 2.0 * math.cos(math.pi / n) ** 2) / 12.0
    else:
        var = r_pix ** 2 / 4.0  # uniform disk
    # the total: the square's area in pixels (exact; the pinhole's reads 0.3 % low, see
    # tests/README.md); the added variances: lens minus pinhole, the aperture's
    area = (side / depth / (2 * HALF) * 64) ** 2
    checks = {"total": (m1[:, 0], np.zeros(len(m1)), area),
              "variance x": (m1[:, 1], m0[:, 1], var), "variance y": (m1[:, 2], m0[:, 2], var)}
    for what, (a, b, exact) in checks.items():
        ok, line = _moment_test(f"blades {blades} {what}", a, b, exact, CAP)
        print(line)
        assert ok, line
    # negative controls: the same tests against a 1 % dimmer total and a 5 % smaller variance
    # (a lens radius off by 2.5 %), both signs
    for sign in (1.0, -1.0):
        for (what, (a, b, exact)), bias in zip(checks.items(), (0.01, 0.05, 0.05)):
            ok, line = _moment_test(f"control {what} {sign * bias:+.0%}", a, b,
                                    exact * (1.0 + sign * bias), CAP)
            assert not ok, f"negative control passed, so this test cannot see it: {line}"


K_MOMENTS = 16
CAP = 0.002  # the pixel grid's quantisation of the moments, far below the noise


def dof_box():
    scene = scenes.cornell_box(32, 32)
    # focused on the short box, aperture wide enough to blur the back wall and the light
    scene.camera["dof"] = {"radius": 0.15, "focus_distance": 3.2, "blades": 6, "rotation": 0.2}
    return scene


# lt is `long` (bench/long_tests.sh; 28 s of CI's CPU, 2026-12-05): its splat through the lens
# is bdpt's light-tracing technique (t = 1), which bdpt's and cis's comparisons weigh in CI
@pytest.mark.parametrize("integrator", [pytest.param("lt", marks=pytest.mark.long),
                                        "bdpt", "cis"])
def test_light_paths_through_the_lens_agree_with_pt(core, integrator, pt_dof_box):
    other = renders(dof_box(), integrator, 32 if integrator != "lt" else 64, 3000, k_seeds=16)
    assert all(np.isfinite(i).all() for i in other)
    metrics.assert_agreement(f"dof {integrator} vs pt", other, pt_dof_box, block=8)


@pytest.fixture(scope="module")
def pt_dof_box(core):
    """pt's reference, shared by the three comparisons: its per-seed block means, stored in
    tests/refs (lantern.testing.refs: rendered again only when the scene changed)."""
    scene = dof_box()
    return refs.reference_blocks(
        Path(__file__).resolve().parent.parent / "refs" / "camera_dof" / "dof_box_pt.npz",
        lambda: renders(scene, "pt", 256, 1000, k_seeds=16),
        dict(scene=scene, integrator="pt", spp=256, seed0=1000, k_seeds=16, max_depth=6,
             steps=4))


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
