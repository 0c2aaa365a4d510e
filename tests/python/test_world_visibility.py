"""The world's ray visibility (Cycles' World > Settings > Ray Visibility; pt only:
integrator/pt.h pt_world_sees): a kind of scattering that does not see the world finds it black
and is lit by it neither through next-event estimation nor through BSDF sampling.

A convex ball under a constant world of 0.5, seen by the camera: white diffuse, white metal and
clear glass balls are each a furnace (their image is the world's 0.5 where their kind sees it),
and exactly black (diffuse, metal) or only their reflection (glass) where it does not."""
import numpy as np
import pytest

import lantern
from lantern import metrics, scenes

WORLD = 0.5


@pytest.fixture(scope="module")
def core():
    if not lantern.native_available():
        pytest.skip(f"lantern._core is not built ({lantern.native_error()})")
    from lantern import _core
    return _core


def ball_scene(kind, hidden=(), size=16):
    scene = lantern.Scene()
    scene.film.update(width=size, height=size)
    scene.look_at((0.0, -3.0, 0.0), (0.0, 0.0, 0.0), fov=50.0)
    props = {"diffuse": dict(type="diffuse", base_color=(1.0, 1.0, 1.0)),
             "metal": dict(type="conductor", base_color=(1.0, 1.0, 1.0), roughness=0.3),
             "glass": dict(type="dielectric", base_color=(1.0, 1.0, 1.0), roughness=0.0)}[kind]
    m = scene.add_material(kind, **props)
    pos, idx = scenes.icosphere(2, 0.9)
    scene.add_mesh(pos, idx, material=m, name="ball")
    scene.world = {"color": [WORLD] * 3}
    scene.world.update({f"visible_{ray}": False for ray in hidden})
    return scene


def render(scene, seed, spp=16, integrator="pt"):
    s = lantern.Session(scene, integrator=integrator, seed=seed, backend="cpu", max_depth=12,
                        spp_per_iteration=spp)
    s.step()
    return np.asarray(s.image(), np.float64)


BALL = (slice(6, 10), slice(6, 10))  # the middle of the ball (the world in the corners)


@pytest.mark.parametrize("kind,visible,hidden", [
    ("diffuse", ("glossy", "transmission"), "diffuse"),
    ("metal", ("diffuse", "transmission"), "glossy"),
])
def test_reflections_see_the_world_by_kind(core, kind, visible, hidden):
    lit = [render(ball_scene(kind, visible), seed=k)[BALL] for k in range(6)]
    cmp = metrics.compare_sets(lit, [WORLD], block=2, se_floor=1e-6)
    print(f"{kind}, world hidden from {visible}: {cmp}")
    assert cmp.passed(1e-3), str(cmp)
    dark = render(ball_scene(kind, (hidden,)), seed=1)
    assert dark[BALL].max() == 0.0                # no light through either strategy
    assert dark[0, 0] == pytest.approx([WORLD] * 3)  # the camera still sees the world


def test_glass_without_transmission_shows_only_its_reflection(core):
    full = [render(ball_scene("glass"), seed=k)[BALL] for k in range(6)]
    cmp = metrics.compare_sets(full, [WORLD], block=2, se_floor=1e-6)  # a clear glass furnace
    assert cmp.passed(1e-3), str(cmp)
    refl = np.mean([render(ball_scene("glass", ("transmission",)), seed=k)[BALL].mean()
                    for k in range(4)])
    # head-on Fresnel reflection of glass is 4 %; the middle of the ball is near normal
    assert 0.0 < refl < 0.15 * WORLD, refl
    # and without glossy either the camera sees nothing of the world through the ball
    none = render(ball_scene("glass", ("transmission", "glossy")), seed=1)
    assert none[BALL].max() == 0.0


def test_the_other_integrators_ignore_it(core):
    """bdpt keeps the world visible to every kind (the export warns, addon/export/world.py):
    the diffuse furnace stays lit."""
    img = render(ball_scene("diffuse", ("diffuse",)), seed=1, integrator="bdpt")
    assert img[BALL].mean() > 0.8 * WORLD
