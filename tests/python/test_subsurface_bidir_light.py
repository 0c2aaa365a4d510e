"""The light paths of bdpt, lvc and cis walk under the skin (docs/subsurface.md, "Light paths
walk"; integrator/bdpt_sss_light.h): lt's adjoint walk, its exit a light vertex (connectable,
splatted), and the MIS split between the techniques whose camera sub-path holds a walk and those
whose light sub-path holds it (each set weighed as before within itself). Skin only (lt's rule);
the Random Walk scenes of test_subsurface_bidir.py keep camera-side walks alone.

Checked: the furnace (a white Skin walk in a closed sphere under a world of 1 renders 1, the
light exits' splats included), agreement with pt on the lit Skin sphere of
test_subsurface_bidir.py and on the slab lit from behind (Skin), each for bdpt, lvc and cis. The
negative control is the split left out (LANTERN_SSS_ADJOINT=nosplit: both sets at weight 1,
read when the scene is built): every path with a walk that both sets can make counts twice
(furnace about +60 %, sphere +50-70 %), and each comparison must fail it."""
import numpy as np
import pytest

import lantern
from lantern import agreement, metrics

from test_subsurface_bidir import lit_sphere
from test_subsurface_scene import FURNACE_RADIUS, slab_scene, sphere_scene

pytestmark = pytest.mark.skipif(not lantern.native_available(), reason="native core unavailable")

BIDIR = ["bdpt", "lvc", "cis"]


def _renders(scene, integrator, k, spp, seed, max_depth=16, channels=3):
    return [np.asarray(lantern.render(scene, spp=spp, seed=seed + i, max_depth=max_depth,
                                      integrator=integrator, threads=1),
                       np.float64)[..., :channels]
            for i in range(k)]


def _skin(scene, **material):
    scene.materials[0].update(subsurface_method="random_walk_skin", **material)
    return scene


@pytest.fixture
def control(monkeypatch):
    monkeypatch.delenv("LANTERN_SSS_ADJOINT", raising=False)

    def set_control(name):
        monkeypatch.setenv("LANTERN_SSS_ADJOINT", name)
    return set_control


def _furnace_scene():
    r = FURNACE_RADIUS["random_walk_skin"]
    return sphere_scene(method="random_walk_skin", radius=(r, r, r))


def _furnace_check(renders):
    return metrics.compare_renders(renders, np.ones(3), block=4, bias_cap=1e-3, rel_floor=1e-5)


@pytest.mark.parametrize("integ", BIDIR)
def test_furnace_skin_light_walks(integ, control):
    # the camera side's share of a walk renders its exact 1 times its weight, the light exits'
    # splats the rest (lt's noise, weighed down where its lobe peaks): 1 within the noise
    # (about 0.3 % on the image at 8 seeds x 16 spp)
    renders = _renders(_furnace_scene(), integ, 8, 16, seed=11)
    res = _furnace_check(renders)
    print(f"{integ} furnace, light walks:", res)
    assert res.passed, res
    control("nosplit")
    res = _furnace_check(_renders(_furnace_scene(), integ, 8, 16, seed=11))
    assert not res.passed, f"{integ}: the split left out not told apart: {res}"


def test_furnace_cis_exit_splat_count(control):
    # a light exit whose walk began at the light path's first vertex splats with light tracing's
    # count for direct light (cis: n_lt / 4), as the camera side's next event from a first
    # vertex and emission at a second count it for the same paths; with n_lt alone there
    # (LANTERN_SSS_ADJOINT=nodirect) the weights no longer sum to 1: about +3 %
    control("nodirect")
    res = _furnace_check(_renders(_furnace_scene(), "cis", 8, 16, seed=11))
    assert not res.passed, f"cis: the exit splat's count not told apart: {res}"


SEEDS, SPP = 8, 64


@pytest.fixture(scope="module")
def pt_sphere():
    return _renders(_skin(lit_sphere()), "pt", SEEDS, SPP, seed=101)


@pytest.mark.parametrize("integ", BIDIR)
def test_lit_skin_sphere_agrees_with_pt(integ, pt_sphere, control):
    # light paths off the point light enter the sphere's lit side and leave towards the camera
    # (splats) and the floor (their continuation); camera paths meet those exits and walk
    # themselves. 16 x 16, blocks of 4: image-mean noise about 0.5 %
    renders = _renders(_skin(lit_sphere()), integ, SEEDS, SPP, seed=201)
    agreement.assert_agreement(f"{integ} vs pt, Skin sphere, light walks", renders, pt_sphere,
                               block=4, controls=False)
    control("nosplit")
    res = agreement.compare_renders(_renders(_skin(lit_sphere()), integ, SEEDS, SPP, seed=201),
                                    pt_sphere, block=4)
    assert not res.passed, f"{integ}: the split left out not told apart: {res}"


@pytest.fixture(scope="module")
def pt_slab():
    return _renders(_skin(slab_scene(1.0)), "pt", 16, 64, seed=101, channels=2)


@pytest.mark.parametrize("integ", BIDIR)
def test_slab_from_behind_agrees_with_pt(integ, pt_slab, control):
    # a 10 cm slab lit from behind, seen head on (orthographic; red and green: blue hardly comes
    # through): light paths walk through it from the back and splat from the front, camera paths
    # walk through it from the front and take the lamp behind; both sets make these paths
    renders = _renders(_skin(slab_scene(1.0)), integ, 32, 64, seed=201, channels=2)
    agreement.assert_agreement(f"{integ} vs pt, Skin slab, light walks", renders, pt_slab,
                               block=4, controls=False)
    control("nosplit")
    res = agreement.compare_renders(
        _renders(_skin(slab_scene(1.0)), integ, 32, 64, seed=201, channels=2), pt_slab, block=4)
    assert not res.passed, f"{integ}: the split left out not told apart: {res}"
