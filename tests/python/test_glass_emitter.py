"""An emitter inside solid glass (issue 28), as Cycles renders it: radiance crosses a dielectric
unscaled by 1/eta^2 (bsdf/dielectric.h), so an emissive sphere inside a glass sphere is seen
at emission * (1 - F) through smooth glass, where Lantern used to give 1/1.5^2 of that.

- Smooth glass, every camera-path integrator against the exact value (the Fresnel factor at
  the near-normal incidence every pixel has; scenes.emitter_in_glass).
- Rough glass over a diffuse floor: the integrators whose light paths leave the glass (bdpt,
  cis, lt: the adjoint factor 1/eta'^2 of importance transport) against pt, seeds apart.
Both by lantern.agreement with its negative controls (tests/README.md)."""
from pathlib import Path

import numpy as np
import pytest

import lantern
from lantern import metrics, scenes
from lantern.testing import refs

K = 16
SIZE = 24


pytestmark = pytest.mark.usefixtures("core")  # (conftest: skips without the core)


def _renders(scene, integrator, spp, seed0, k=K):
    out = []
    for i in range(k):
        s = lantern.Session(scene, integrator=integrator, seed=seed0 + i, backend="cpu",
                            max_depth=8, spp_per_iteration=spp)
        s.step()
        out.append(s.image())
    return out


@pytest.mark.parametrize("integrator", ["pt", "bdpt", "lvc", "cis"])
def test_smooth_glass_shows_the_emitter_less_fresnel(integrator):
    scene = scenes.emitter_in_glass(SIZE, SIZE, roughness=0.0)
    exact = np.full((SIZE, SIZE, 3), scenes.emitter_in_glass_expected(), np.float32)
    renders = _renders(scene, integrator, 16, 100)
    res = metrics.assert_agreement(f"emitter in smooth glass, {integrator}", renders, exact)
    # the old radiance scaling (1/eta^2) is 2.25x away: far outside any noise
    assert abs(res.mean_rel).max() < 0.01


@pytest.fixture(scope="module")
def rough_pt():
    scene = scenes.emitter_in_glass(SIZE, SIZE, roughness=0.25, floor=True, fov=40.0)
    # pt's per-seed block means, stored in tests/refs (lantern.testing.refs: rendered again
    # only when the scene changed)
    return scene, refs.reference_blocks(
        Path(__file__).resolve().parent.parent / "refs" / "glass_emitter" / "rough_pt.npz",
        lambda: _renders(scene, "pt", 256, 200),
        dict(scene=scene, integrator="pt", spp=256, seed0=200, k_seeds=K, max_depth=8, steps=1))


# lt carries all of the image through light paths: far noisier, so its controls are wider
# (still 1/10 of the 2.25x a wrong adjoint factor gives)
@pytest.mark.parametrize("integrator,spp,controls", [("bdpt", 64, (0.02, 0.1)),
                                                     ("cis", 64, (0.02, 0.1)),
                                                     ("lt", 512, (0.1, 0.5))])
def test_rough_glass_light_paths_agree_with_pt(rough_pt, integrator, spp, controls):
    scene, ref = rough_pt
    renders = _renders(scene, integrator, spp, 300)
    metrics.assert_agreement(f"emitter in rough glass, {integrator} vs pt", renders, ref,
                               image_bias=controls[0], block_bias=controls[1])
