"""Strand vertices in lt, bdpt, lvc and cis (docs/curves.md "Bidirectional"; integrator/
bdpt_curve.h): light paths that scatter off strands, cache vertices on strands, connections to
and from them, lt's camera splats from strands, all with the Principled Hair lobe's reverse pdf.

- Agreement with pt on fur on a sphere (Principled Hair, lantern.scenes_hair.fur_ball, no world
  light so that lt sees what pt sees), independent seeds a side, lantern.metrics; the negative
  control: melanin 5 % higher in the bidirectional render must be caught.
- Hair furnace (white strands that absorb nothing in a uniform white world): every pixel is 1,
  on bdpt, lvc and cis (lt does not draw the world for the camera: there the strands' pixels
  against pt's render of the same furnace with the world hidden from the camera).
- Strands shaded by an ordinary BSDF: tests/python/test_strand_tube_bidir.py."""
from pathlib import Path

import numpy as np
import pytest

import lantern
from lantern import metrics
from lantern.testing import refs
from lantern.scenes_hair import fur_ball, hair_furnace

K = 12         # seeds a side
SIZE = 24
DEPTH = 8


def render(scene, integrator, seed, spp, max_depth=DEPTH):
    s = lantern.Session(scene, integrator=integrator, seed=seed, backend="cpu", threads=1,
                        max_depth=max_depth, spp_per_iteration=spp)
    s.step()
    return np.asarray(s.image(), np.float64), s.warnings


def renders(scene, integrator, spp, seed0, k=K, max_depth=DEPTH):
    out = []
    for j in range(k):
        img, w = render(scene, integrator, seed0 + j, spp, max_depth)
        assert not any("rendering with pt" in x for x in w), w
        out.append(img)
    return out


def fur(melanin=0.4):
    return fur_ball(SIZE, SIZE, num_strands=150, world=0.0,
                    hair={"parametrization": "melanin", "melanin": melanin})


_REF = {}


REFS = Path(__file__).resolve().parent.parent / "refs" / "hair_bidir"


def pt_reference():
    """pt's per-seed block means on the fur ball, stored in tests/refs (lantern.testing.refs:
    rendered again only when the scene changed)."""
    if "fur" not in _REF:
        scene = fur()
        _REF["fur"] = refs.reference_blocks(
            REFS / "fur_pt.npz", lambda: renders(scene, "pt", 256, 1000),
            dict(scene=scene, integrator="pt", spp=256, seed0=1000, k_seeds=K, max_depth=DEPTH))
    return _REF["fur"]


SPP = {"bdpt": 64, "lvc": 64, "cis": 64, "lt": 1024}


@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis", "lt"])
def test_strand_vertices_agree_with_pt_on_fur(core, integrator):
    imgs = renders(fur(), integrator, SPP[integrator], 5000)
    assert all(np.isfinite(x).all() for x in imgs)
    # what these seeds resolve (measured): a whole-image bias of 2.1-2.9 % (bdpt, lvc, cis),
    # 3.1 % (lt), so the controls' levels are 4 % (5 % for lt) on the image, 10 % on a block
    metrics.assert_agreement(f"fur (Principled Hair) {integrator} vs pt", imgs, pt_reference(),
                             block=8, image_bias=0.05 if integrator == "lt" else 0.04,
                             block_bias=0.1)


def test_melanin_off_is_caught(core):
    """Negative control: the fur's melanin 5 % higher in cis's render than in pt's."""
    res = metrics.compare_renders(renders(fur(0.55), "cis", SPP["cis"], 7000), pt_reference(),
                                  block=8, name="fur: cis with melanin 0.55 for 0.4")
    print(res)
    assert not res.passed


@pytest.mark.parametrize("integrator", ["bdpt", pytest.param("lvc", marks=pytest.mark.long),
                                        "cis"])
def test_hair_furnace_bidirectional(core, integrator):
    imgs = renders(hair_furnace(), integrator, 64, 11, k=8, max_depth=64)
    # (resolves a whole-image bias of 1.0-1.2 %: the control's level is 2 %)
    metrics.assert_agreement(f"hair furnace ({integrator})", imgs, [1.0] * 3, block=4,
                             se_floor=1e-6, image_bias=0.02, block_bias=0.1)


@pytest.mark.long  # 17 s; lt's furnace resolves only 8 % (the fur's lt case stays in CI)
def test_hair_furnace_lt(core):
    """lt draws no world for the camera: its furnace is the strands' light, against pt's with
    the world hidden from the camera (the strands still see it), light paths of up to 8
    segments (lt's weights grow along long paths through the fur: cos theta ratios); it
    resolves a whole-image bias of 8 % (measured): the control's level is 10 %."""
    scene = hair_furnace()
    scene.world["visible_camera"] = False
    ref = renders(scene, "pt", 64, 100, k=8, max_depth=8)
    imgs = renders(scene, "lt", 1024, 200, k=8, max_depth=8)
    metrics.assert_agreement("hair furnace (lt vs pt)", imgs, ref, block=8, image_bias=0.1,
                             block_bias=0.3)
