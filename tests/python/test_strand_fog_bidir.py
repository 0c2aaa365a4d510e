"""Strands beside volumes in lt, bdpt, lvc and cis (docs/curves.md "Strands beside volumes"):
the fur ball (Principled Hair, the fiber measure's vertices; and the Principled Hair + Diffuse
mix, tube vertices) in world fog, no world light. Rays through the fog hit strands, medium
vertices connect to strand vertices and strand vertices to medium vertices
(bdpt_connect_medium), segments ending at strands carry the fog's transmittance. Against pt
(stored per-seed block means, lantern.testing.refs), independent seeds a side,
lantern.metrics. Negative control: the fog's scattering 10 % denser in cis's render. These
renders do not resolve the connection's strand cosines (built once with bdpt_connect_medium's
old |n.w| at strand vertices, cis agreed as well, in this fog and in a thin one: connections to
and from strand vertices carry little of these images); they check that nothing else is
missing for strands in media."""
from pathlib import Path

import pytest

from lantern import metrics
from lantern.scenes_hair import fur_ball

from test_hair_bidir import renders
from test_hair_mix_bidir import mix_fur
from lantern.testing import refs

K = 12
SIZE = 24
DEPTH = 8
REFS = Path(__file__).resolve().parent.parent / "refs" / "strand_fog"


def fog(scene, sigma_s=0.25):
    scene.world["volume"] = {"sigma_s": [sigma_s] * 3, "sigma_a": [0.02, 0.04, 0.08], "g": 0.3}
    return scene


def fur_fog(sigma_s=0.25):
    return fog(fur_ball(SIZE, SIZE, num_strands=150, world=0.0,
                        hair={"parametrization": "melanin", "melanin": 0.4}), sigma_s)


def mix_fog():
    return fog(mix_fur())


SCENES = {"hair": fur_fog, "mix": mix_fog}
_REF = {}


def pt_reference(key):
    if key not in _REF:
        scene = SCENES[key]()
        _REF[key] = refs.reference_blocks(
            REFS / f"fur_{key}_fog_pt.npz", lambda: renders(scene, "pt", 256, 1000),
            dict(scene=scene, integrator="pt", spp=256, seed0=1000, k_seeds=K, max_depth=DEPTH))
    return _REF[key]


SPP = {"bdpt": 64, "lvc": 64, "cis": 64, "lt": 1024}


@pytest.mark.parametrize("key,integrator", [
    ("hair", "cis"),
    pytest.param("hair", "bdpt", marks=pytest.mark.long),
    pytest.param("hair", "lvc", marks=pytest.mark.long),
    pytest.param("hair", "lt", marks=pytest.mark.long),
    pytest.param("mix", "cis", marks=pytest.mark.long),
    pytest.param("mix", "bdpt", marks=pytest.mark.long),
])
def test_fur_in_fog_agrees_with_pt(core, key, integrator):
    imgs = renders(SCENES[key](), integrator, SPP[integrator], 5000)
    # (lt resolves a whole-image bias of about 6 % here and misses a block's 10 %: its control
    # levels are 8 % and 25 %)
    lt = integrator == "lt"
    metrics.assert_agreement(f"fur ({key}) in fog: {integrator} vs pt", imgs,
                             pt_reference(key), block=8, image_bias=0.08 if lt else 0.04,
                             block_bias=0.25 if lt else 0.1)


def test_fur_fog_off_is_caught(core):
    res = metrics.compare_renders(renders(fur_fog(0.275), "cis", 64, 7000), pt_reference("hair"),
                                  block=8, name="fur in fog: cis, sigma_s 0.275 for 0.25")
    print(res)
    assert not res.passed
