"""Integrator "lt" (light tracing to the camera) against "pt": the same images, statistically.

K independent seeds per integrator, compared by lantern.metrics.assert_agreement
(tests/README.md): per 8x8 block and channel a Welch t-test, Bonferroni at alpha = 1e-3 over the
blocks, and z-tests of the image mean and of the block-weighted mean with a 0.2 % cap; then the
negative controls (+-1 % on the whole image, +-5 % on one block, two channels swapped) must
fail on the same renders."""
import time
from pathlib import Path

import numpy as np
import pytest

import lantern
from lantern import metrics, scenes
from lantern.testing import refs

K = 16         # independent renders per integrator: Welch dof >= 15 puts the Bonferroni
SIZE = 32      # threshold over 4x4 blocks x 3 channels near 6 (it was 10 with 8 seeds of
               # twice the samples: more seeds, not more samples, is what buys power here)


def cornell_area():
    return scenes.cornell_box(SIZE, SIZE)  # visible rectangle area light (front only)


def cornell_point():
    scene = scenes.cornell_box(SIZE, SIZE)
    scene.lights = []
    # radius 0: a true point (delta position) whatever soft_falloff says
    scene.add_light("point", position=[0.2, -0.1, 1.5], power=[30.0, 25.0, 20.0], radius=0.0)
    return scene


def cornell_mesh_light():
    scene = scenes.cornell_box(SIZE, SIZE)
    scene.lights = []
    glow = scene.add_material("glow", base_color=(0.5, 0.5, 0.5), emission=(6.0, 5.0, 4.0))
    # a horizontal quad: the camera sees its underside, its upper side lights the ceiling
    pos = np.array([[-0.3, -0.2, 1.5], [0.3, -0.2, 1.5], [0.3, 0.3, 1.5], [-0.3, 0.3, 1.5]],
                   dtype=np.float32)
    idx = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)
    scene.add_mesh(pos, idx, material=glow, name="panel")
    return scene


def cornell_spot():
    scene = scenes.cornell_box(SIZE, SIZE)
    scene.lights = []
    m = np.eye(4)
    m[:3, 3] = (0.1, 0.2, 1.9)  # the cone points down (local -Z)
    scene.add_light("spot", to_world=m.tolist(), power=[40.0] * 3, radius=0.0, spot_size=1.2,
                    spot_blend=0.3)
    return scene


def cornell_sphere():
    scene = scenes.cornell_box(SIZE, SIZE)
    scene.lights = []
    scene.add_light("point", position=[0.2, 0.0, 1.5], power=[30.0] * 3, radius=0.15,
                    soft_falloff=False, visible_camera=True)
    return scene


def cornell_sun():
    scene = scenes.cornell_box(SIZE, SIZE)  # the sun shines in through the open front
    scene.lights = []
    scene.add_light("sun", direction=[0.2, 0.6, -0.3], strength=[2.0] * 3, angle=0.1)
    return scene


# samples per seed (pt, lt): enough for the mean tests to resolve well under 1 % (the printed
# "detects a whole-image bias >= x"); lt is the noisier side where the emitter is seen
SPP = {"cornell_area": (512, 256), "cornell_spot": (768, 384), "cornell_sphere": (512, 256),
       "cornell_sun": (384, 512)}


REFS = Path(__file__).resolve().parent.parent / "refs" / "light_tracing"


def renders(scene, integrator, spp, seed0, backend="cpu"):
    return [lantern.render(scene, spp=spp, seed=seed0 + k, integrator=integrator,
                           backend=backend, max_depth=8) for k in range(K)]


# lt's own part (the light vertex connected to the camera, splatted) is the same for every light;
# what differs per light is the emission sampling, which bdpt, lvc and cis share with lt (their
# light sub-paths). CI keeps the visible rectangle (an emitter the camera sees), the delta point
# and the sphere (no other CI test compares a sphere light's light paths); the rest is `long`
# (bench/long_tests.sh), their emission sampled in CI by light sub-paths elsewhere:
# the spot and the 2-degree sun by test_light_tree.py's room (bdpt, lvc and cis vs pt), the
# emissive quad by its many-lights stage (panel=True: triangle lights), the sun also by
# test_bidirectional.py's sharp sun (test_delta_lights_agree). 169 s CPU of CI (2026-12-05).
LONG = {cornell_spot, cornell_mesh_light, cornell_sun}


@pytest.mark.parametrize("make", [
    pytest.param(m, marks=pytest.mark.long) if m in LONG else m
    for m in (cornell_area, cornell_point, cornell_mesh_light, cornell_spot, cornell_sphere,
              cornell_sun)])
def test_lt_matches_pt(core, make, backend):
    scene = make()
    t0 = time.perf_counter()
    spp_pt, spp_lt = SPP.get(make.__name__, (256, 128))
    # pt's per-seed block means stored in tests/refs (lantern.testing.refs; the backend is not
    # in the key: the CUDA backend's lt is compared with the CPU's stored pt)
    pt = refs.reference_blocks(
        REFS / f"{make.__name__}_pt.npz", lambda: renders(scene, "pt", spp_pt, 1000),
        dict(scene=scene, integrator="pt", spp=spp_pt, seed0=1000, k_seeds=K, max_depth=8))
    lt = renders(scene, "lt", spp_lt, 2000, backend=backend)
    metrics.assert_agreement(f"{make.__name__} lt vs pt", lt, pt, block=8)
    print(f"{make.__name__}: {time.perf_counter() - t0:.1f} s")


def test_lt_same_bits_any_thread_count(core):
    scene = scenes.cornell_box(16, 16)
    a = lantern.render(scene, spp=4, seed=7, integrator="lt", backend="cpu", threads=1)
    b = lantern.render(scene, spp=4, seed=7, integrator="lt", backend="cpu", threads=2)
    c = lantern.render(scene, spp=4, seed=8, integrator="lt", backend="cpu", threads=2)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_lt_refuses_soft_falloff_lights_around_geometry(core, backend):
    """lt traces a soft-falloff light by lines through its ball (soft_light_path.h; against pt:
    test_soft_light_paths.py), but refuses one whose ball holds geometry (here the ceiling)."""
    scene = scenes.cornell_box(8, 8)
    scene.add_light("point", position=[0.0, 0.0, 1.95], power=[10.0] * 3, radius=0.1,
                    soft_falloff=True)
    with pytest.raises(ValueError, match=r"lights\[1\].*soft_falloff.*mesh 'ceiling'"):
        lantern.Session(scene, integrator="lt", backend="cpu")
    # the same light as a sphere (soft_falloff off) or a point (radius 0) renders
    scene.lights[1]["soft_falloff"] = False
    assert lantern.render(scene, spp=1, integrator="lt", backend="cpu").mean() > 0
    scene.lights[1].update(soft_falloff=True, position=[0.4, 0.3, 1.5])  # clear of geometry
    assert lantern.render(scene, spp=1, integrator="lt", backend="cpu").mean() > 0
