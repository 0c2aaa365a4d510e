"""Shadow linking in media in the bidirectional integrators against pt, statistically
(compare_renders: block means, Student t). pt's shadow rays through media pass what is outside
a shadow-linked light's blocker sets (pt_volume.h pt_shadow_loop; against Cycles:
tests/cycles/test_shadow_linking_fog.py); bdpt, lvc and cis render such a scene themselves
(bidir_linking.h's classes: s = 1 at a medium vertex alone, its shadow ray through media with
the blocker sets, bdpt_medium.h bdpt_medium_shadow; a light sub-path's first vertex in a medium
neither stored, splatted nor continued, bdpt_medium_light.h).

test_linking_bidir.py's shadow-linking room (the lamp's and the quad's shadows cast by the
glass ball alone, not by the slab) in

- world: world fog;
- box: a fog box (a mesh volume, no blocker) around the floor, the balls and the slab, its
  top under the lamp and the quad: their shadow rays pass its boundary and stay in its fog.

The control, the scene without the linking (the slab casts its shadows), must fail."""
import numpy as np
import pytest

import lantern
from lantern import metrics

from test_linking_bidir import shadow_linked
from test_linking_media import FOG  # the same fog as light linking in media
from test_volume_bidir import _volume_box

K, SPP = 16, 32  # seeds x samples per pixel (tests/README.md: Welch dof >= 15)


def foggy(case, linked=True):
    s = shadow_linked(linked)
    if case == "world":
        s.world = {"color": [0.0] * 3, "volume": dict(FOG)}
    else:  # under the slab (z 1.1), the quad (1.6) and the lamp (1.8)
        _volume_box(s, "fog", dict(FOG), (-2.5, -2.5, -0.1), (2.5, 1.4, 1.3))
    return s


def render(scene, integrator, seed, spp=SPP):
    s = lantern.Session(scene, integrator=integrator, seed=seed, backend="cpu", max_depth=4,
                        spp_per_iteration=spp, threads=1)
    s.step()
    return np.asarray(s.image(), np.float64)[..., :3], s.warnings


def renders(case, integrator, seed0, linked=True):
    out, warnings = [], []
    for k in range(K):
        img, warnings = render(foggy(case, linked), integrator, seed0 + k)
        out.append(img)
    return out, warnings


@pytest.fixture(scope="module")
def pt_refs(core):
    return {case: renders(case, "pt", 1000)[0] for case in ("world", "box")}


@pytest.mark.parametrize("case", ["world", "box"])
@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_shadow_linking_in_media_matches_pt(pt_refs, integrator, case):
    imgs, warnings = renders(case, integrator, 2000)
    assert not warnings, warnings  # rendered by the integrator itself
    metrics.assert_agreement(f"shadow linking in {case} fog, {integrator} vs pt", imgs,
                             pt_refs[case], block=4, image_bias=0.025, block_bias=0.1)
    # the control: linking ignored (the slab casts the lamp's shadow) is seen
    free, _ = renders(case, integrator, 3000, linked=False)
    assert not metrics.compare_renders(free, pt_refs[case], block=4).passed
