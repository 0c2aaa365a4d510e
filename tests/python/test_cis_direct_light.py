"""cis's MIS count for light tracing of direct light (bdpt.h, BdptSettings::lt_direct: n_lt / 4
on paths light - surface - camera) must enter all three weights of such a path: the light tracing
splat, next-event estimation at the first camera vertex and the second camera vertex's emission.
At max_depth 2 only those three techniques render, so cis must agree with pt, which has no light
tracing at all (lantern.metrics.assert_agreement with its negative controls, tests/README.md).

The scene makes each technique carry weight: a rough metal floor under a large rectangle light
half a metre above it (BSDF sampling finds the light often, next-event estimation elsewhere,
light tracing everywhere). Negative control, measured when the test was written: with the
factor left out of the emission weight only (the other two weights kept), cis read 9.5 % low
here (z 82), while the Cornell, glossy and principled agreement tests of test_bidirectional.py
still passed."""
from pathlib import Path

import numpy as np
import pytest

import lantern
from lantern import metrics, scenes
from lantern.testing import refs
from seed_renders import render_seeds

K = 16
SIZE = 32


def light_over_metal(n=SIZE):
    sc = lantern.Scene()
    sc.film.update(width=n, height=n)
    sc.look_at((0.0, -2.0, 1.6), (0.0, 0.3, 0.0), fov=50.0)
    metal = sc.add_material("rough_metal", type="conductor", base_color=(0.9, 0.7, 0.5),
                            roughness=0.35)
    wall = sc.add_material("wall", base_color=(0.3, 0.5, 0.8))
    sc.add_mesh(*scenes._quad((-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0)), material=metal,
                name="floor")
    sc.add_mesh(*scenes._quad((-2, 2, 0), (2, 2, 0), (2, 2, 2), (-2, 2, 2)), material=wall,
                name="back")
    sc.add_light("area", to_world=scenes._aim((0.0, 0.6, 0.6), (0.0, 0.6, 0.0)),
                 shape="rectangle", size=[1.5, 1.0], power=[60.0] * 3)
    return sc


def renders(scene, integrator, spp, seed0, backend):
    return render_seeds(scene, integrator, range(seed0, seed0 + K), spp, backend=backend,
                        max_depth=2)


@pytest.mark.parametrize("integrator", ["cis", "lvc"])
def test_direct_light_weights_sum_to_one(core, integrator, backend):
    scene = light_over_metal()
    # pt's per-seed block means, stored in tests/refs (lantern.testing.refs; the backend is
    # not in the key)
    pt = refs.reference_blocks(
        Path(__file__).resolve().parent.parent / "refs" / "cis_direct_light" / "pt.npz",
        lambda: renders(scene, "pt", 256, 1000, backend),
        dict(scene=scene, integrator="pt", spp=256, seed0=1000, k_seeds=K, max_depth=2,
             steps=1))
    r = renders(scene, integrator, 64, 2000, backend)
    assert all(np.isfinite(x).all() for x in r)
    metrics.assert_agreement(f"direct light, {integrator} vs pt", r, pt, block=8,
                             image_bias=0.01, block_bias=0.05)
