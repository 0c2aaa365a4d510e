"""Random-walk subsurface scattering in the bidirectional integrators (docs/subsurface.md,
"Bidirectional integrators"; integrator/bdpt_sss.h): their camera paths walk, their exits are
connectable camera vertices. The furnace (a white walk in a closed sphere under a world of 1
renders 1) with a grey walk as its negative control, and agreement with pt on a sphere with
subsurface on a diffuse floor under a point light (light paths off the floor connect to the
walks' exits), whose negative control is pt with the radius doubled. pt's images: unchanged
(bench/bits_check.py)."""
import numpy as np
import pytest

import lantern
from lantern import agreement, metrics, scenes_sss

from test_subsurface_scene import FURNACE_RADIUS, sphere_scene

pytestmark = pytest.mark.skipif(not lantern.native_available(), reason="native core unavailable")

BIDIR = ["bdpt", "lvc", "cis"]


def _renders(scene, integrator, k, spp, max_depth=16, seed=11):
    return [np.asarray(lantern.render(scene, spp=spp, seed=seed + i, max_depth=max_depth,
                                      integrator=integrator, threads=1), np.float64)
            for i in range(k)]


@pytest.mark.parametrize("integ,method", [("bdpt", "random_walk"), ("lvc", "random_walk"),
                                          ("cis", "random_walk")])
def test_furnace_white_walk(integ, method):
    # as pt's (test_subsurface_scene.py): albedo 1 in a closed convex mesh under a world of 1;
    # light paths from the world see the sphere's other lobes (none: Specular IOR Level 0).
    # Random Walk: light paths do not walk it (Skin only, bdpt_sss_light.h), so every path is
    # the camera side's, exact. Skin's light paths walk: its furnace, within their noise, is
    # test_subsurface_bidir_light.py's
    r = FURNACE_RADIUS[method]
    renders = _renders(sphere_scene(method=method, radius=(r, r, r)), integ, 6, 16)
    metrics.assert_agreement(f"{integ} subsurface furnace {method}", renders, np.ones(3), block=4,
                             bias_cap=1e-3, rel_floor=1e-5)


def test_furnace_grey_walk_is_darker_cis():
    renders = _renders(sphere_scene(base=0.5, radius=(6.0, 6.0, 6.0)), "cis", 4, 16)
    # (the same comparison as the furnace's, which must fail: a base of 0.5 absorbs inside)
    res = metrics.compare_renders(renders, np.ones(3), block=4, bias_cap=1e-3, rel_floor=1e-5)
    assert not res.passed


def lit_sphere(radius_scale=1.0, size=16):
    """A unit sphere with Random Walk subsurface (radius 0.4, 0.2, 0.1 m) on a grey floor under
    a point light, world black (lantern.scenes_sss.lit_sphere): the walk carries light into the
    sphere's shadow side."""
    return scenes_sss.lit_sphere(size, size, method="random_walk", radius_scale=radius_scale)


SEEDS, SPP = 8, 64


@pytest.fixture(scope="module")
def pt_reference():
    return _renders(lit_sphere(), "pt", SEEDS, SPP, seed=101)


@pytest.fixture(scope="module")
def pt_radius_x2():
    return _renders(lit_sphere(2.0), "pt", SEEDS, SPP, seed=301)


@pytest.mark.parametrize("integ", BIDIR)
def test_agrees_with_pt(integ, pt_reference, pt_radius_x2):
    # 16 x 16, 8 seeds x 64 spp a side: image-mean noise about 0.5 %; the stock controls (1 %
    # on the image) are below it, so the control is a physical one: the radius doubled (about
    # +3 % red, more on the shadow side) must be told apart
    renders = _renders(lit_sphere(), integ, SEEDS, SPP, seed=201)
    agreement.assert_agreement(f"{integ} vs pt, subsurface", renders, pt_reference, block=4,
                               controls=False)
    res = agreement.compare_renders(renders, pt_radius_x2, block=4)
    assert not res.passed, f"{integ}: radius x2 not told apart: {res}"
