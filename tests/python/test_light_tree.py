"""Next-event estimation with the light tree (scene/light_tree.h) on scenes of several lights:
pt, bdpt, lvc and cis still converge to the same image (an MIS weight with the wrong pick
probability, forward or reverse, biases them apart), and pt with the tree agrees with pt on the
global power CDF (LANTERN_LIGHT_TREE=0). Statistics as in test_bidirectional.py (K seeds,
lantern.metrics.assert_agreement with its negative controls)."""
import pytest

import lantern
from lantern import scenes

from test_bidirectional import K, SIZE, SPP, check_agreement, renders

PT_REF = 256  # spp per seed of the pt references (the control levels below were measured at it)

# the many-light stage: 16 point lights of different powers, a spot, a sun and an emissive
# panel (triangle lights); the room of issue 14: a spot, and a sun and a world colour through
# a window
SCENES = {
    "many": lambda: scenes.many_lights_stage(SIZE, SIZE, n=16, panel=True),
    "room": lambda: scenes.room_spot_sun_world(SIZE, SIZE),
}
CONTROLS = {"many": (0.02, 0.06), "room": (0.04, 0.10)}


@pytest.fixture(scope="module")
def core():
    if not lantern.native_available():
        pytest.skip(f"lantern._core is not built ({lantern.native_error()})")
    from lantern import _core
    return _core


def global_cdf(monkeypatch):
    """Scenes built from here on pick lights by the global power CDF."""
    monkeypatch.setenv("LANTERN_LIGHT_TREE", "0")


@pytest.mark.parametrize("scene_name", list(SCENES))
def test_integrators_agree_with_the_tree(core, scene_name, backend):
    scene = SCENES[scene_name]()
    ref = renders(scene, "pt", PT_REF, 1000, backend=backend)
    for integrator, settings in (("bdpt", {}), ("lvc", {}), ("cis", {})):
        r = renders(scene, integrator, SPP, 2000, backend=backend, **settings)
        check_agreement(f"{scene_name} {integrator} vs pt (tree)", r, ref, CONTROLS[scene_name])


def test_tree_agrees_with_the_global_cdf(core, backend, monkeypatch):
    scene = SCENES["many"]()
    tree = renders(scene, "pt", PT_REF, 3000, backend=backend)
    global_cdf(monkeypatch)
    flat = renders(scene, "pt", PT_REF, 3000, backend=backend)  # the same seeds
    assert not (tree[0] == flat[0]).all(), "LANTERN_LIGHT_TREE=0 changed nothing"
    check_agreement("many pt tree vs global CDF", tree, flat, CONTROLS["many"])


@pytest.mark.parametrize("scene_name", list(SCENES))
def test_resampled_direct_light_agrees(core, scene_name, backend):
    """light_candidates M = 4 (integrator/nee_resample.h): the resampled weight W with the plain
    strategy's MIS weights converges to pt's image; the plain weight would not."""
    scene = SCENES[scene_name]()
    plain = renders(scene, "pt", PT_REF, 5000, backend=backend)
    ris = renders(scene, "pt", SPP, 6000, backend=backend, light_candidates=4)
    check_agreement(f"{scene_name} pt M=4 vs pt", ris, plain, CONTROLS[scene_name])
