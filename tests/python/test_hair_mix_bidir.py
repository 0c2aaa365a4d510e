"""Principled Hair in a mix with another BSDF on strands, in bdpt, lvc, cis and lt
(docs/curves.md "Principled Hair in a mix"; bsdf/hair_lobe.h kHairTube, bdpt_curve.h): the strand
vertex is pt's point on the tube in the surface measure for both leaves, the hair lobe with the
offset h(w) at which each side's direction meets that point.

- Agreement with pt on the fur ball (lantern.scenes_hair.fur_ball, no world light) whose strands
  mix Principled Hair (melanin 0.4) with a Diffuse BSDF, 0.5 each; pt's per-seed block means
  stored (lantern.testing.refs), independent seeds a side, lantern.metrics. Negative control:
  the hair leaf's melanin 0.7 for 0.4 in cis's render must be caught. These renders do not
  resolve the lobe's Importance form (built once with its Jacobian dropped, bdpt, lvc and cis
  still agreed: the light sub-paths' share of the fur is small here); tests/cpp/
  test_hair_lobe_tube.cpp checks that form exactly (pt's BSDF with the sides swapped).
- Hair furnace through the mix: white non-absorbing hair and a white Diffuse, 0.5 each, in a
  white world: every pixel is 1.
- lt: the hair lobe at a tube vertex transmits through the strand from the side the camera
  sees; a light path reaches that light inside the fiber by going on through the strand to
  where its ray leaves it (integrator/lt_strand.h, docs/curves.md "lt through a strand"). lt
  against the same stored pt blocks; its negative control is lt without that step
  (LANTERN_LT_STRAND=nothrough, read when the scene is built). Strands with a Translucent leaf
  still go to pt for lt (a message)."""
from pathlib import Path

import numpy as np
import pytest

from lantern import metrics
from lantern.scenes_hair import fur_ball, hair_furnace
from lantern.testing import refs

from test_hair_bidir import render, renders

K = 12         # seeds a side
SIZE = 24
DEPTH = 8
REFS = Path(__file__).resolve().parent.parent / "refs" / "hair_mix"


def mix_fur(melanin=0.4, hair_weight=0.5, diffuse_weight=0.5):
    """The fur ball with its strands shaded by hair_weight x Principled Hair (melanin) +
    diffuse_weight x Diffuse (0.8, 0.5, 0.3)."""
    scene = fur_ball(SIZE, SIZE, num_strands=150, world=0.0,
                     hair={"parametrization": "melanin", "melanin": melanin})
    hair = len(scene.materials) - 1
    d = scene.add_material("fur_diffuse", type="diffuse", base_color=(0.8, 0.5, 0.3))
    mix = scene.add_material("fur_mix", type="mix", mix=[[hair, hair_weight],
                                                        [d, diffuse_weight]])
    scene.curves[0]["material_ids"][:] = mix
    return scene


_REF = {}


def pt_reference():
    if "mix" not in _REF:
        scene = mix_fur()
        _REF["mix"] = refs.reference_blocks(
            REFS / "fur_mix_pt.npz", lambda: renders(scene, "pt", 256, 1000),
            dict(scene=scene, integrator="pt", spp=256, seed0=1000, k_seeds=K, max_depth=DEPTH))
    return _REF["mix"]


@pytest.mark.parametrize("integrator", [pytest.param("bdpt", marks=pytest.mark.long),
                                        pytest.param("lvc", marks=pytest.mark.long), "cis"])
def test_hair_mix_agrees_with_pt(core, integrator):
    imgs = renders(mix_fur(), integrator, 64, 5000)
    assert all(np.isfinite(x).all() for x in imgs)
    metrics.assert_agreement(f"fur (Principled Hair + Diffuse) {integrator} vs pt", imgs,
                             pt_reference(), block=8, image_bias=0.03, block_bias=0.15)


def test_hair_mix_melanin_off_is_caught(core):
    """Negative control: the hair leaf's melanin 0.7 for 0.4 in cis's render (measured: image
    -2.8 % against 1.4 % allowed, worst block |z| 10; 0.55 moved it by 1.7 %, at the edge)."""
    res = metrics.compare_renders(renders(mix_fur(melanin=0.7), "cis", 64, 7000),
                                  pt_reference(), block=8, name="fur mix: cis, melanin 0.7")
    print(res)
    assert not res.passed


def mix_furnace():
    """hair_furnace with its strands shaded by 0.5 x its white hair + 0.5 x a white Diffuse:
    both leaves reflect all they receive, so every pixel is the world's 1."""
    scene = hair_furnace()
    d = scene.add_material("white_diffuse", type="diffuse", base_color=(1.0, 1.0, 1.0))
    scene.curves[0]["material_ids"][:] = scene.add_material("white_mix", type="mix",
                                                            mix=[[0, 0.5], [d, 0.5]])
    return scene


@pytest.mark.parametrize("integrator", ["bdpt", pytest.param("lvc", marks=pytest.mark.long),
                                        "cis"])
def test_hair_mix_furnace(core, integrator):
    imgs = renders(mix_furnace(), integrator, 64, 11, k=8, max_depth=64)
    metrics.assert_agreement(f"hair mix furnace ({integrator})", imgs, [1.0] * 3, block=4,
                             se_floor=1e-6, image_bias=0.02, block_bias=0.1)


def test_hair_mix_goes_to_pt_for_lt_only_with_translucent(core):
    scene = mix_fur()
    hair = len(scene.materials) - 3  # (mix_fur: the hair, its Diffuse, the mix)
    t = scene.add_material("fur_translucent", type="translucent", base_color=(0.8, 0.8, 0.8))
    scene.curves[0]["material_ids"][:] = scene.add_material(
        "fur_mix_t", type="mix", mix=[[hair, 0.5], [t, 0.5]])
    _, w = render(scene, "lt", 1, 1, max_depth=4)
    assert any("BSDF that transmits" in x and "rendering with pt" in x for x in w), w
    for integ in ("bdpt", "lvc", "cis", "lt"):
        _, w = render(mix_fur(), integ, 1, 1, max_depth=4)
        assert not any("rendering with pt" in x for x in w), (integ, w)


LT_SPP = 1024


def test_hair_mix_lt_agrees_with_pt(core, monkeypatch):
    """lt on the mix fur against pt's stored blocks; without its step through the strand (the
    light inside a tube vertex's fiber) lt must read dark and fail."""
    imgs = renders(mix_fur(), "lt", LT_SPP, 5000)
    assert all(np.isfinite(x).all() for x in imgs)
    # Seed 5008 made a firefly (a pixel of 12.9, its image +34 %) before the continuation from
    # inside the fiber took a mixture with a cosine (lt_strand.h lt_strand_inside_sample); the
    # comparison then could not resolve +10 % on a block and ran without its controls. Now with
    # them, at what pt's 12 x 256 blocks resolve (2.9 %): 3 %, and 15 % on a block (+10 % on the
    # dark block (2, 1) read |z| 5.4). The step left out, below, is the step's own control.
    metrics.assert_agreement("fur (Principled Hair + Diffuse) lt vs pt", imgs, pt_reference(),
                             block=8, image_bias=0.03, block_bias=0.15)
    monkeypatch.setenv("LANTERN_LT_STRAND", "nothrough")
    res = metrics.compare_renders(renders(mix_fur(), "lt", LT_SPP // 2, 5000), pt_reference(),
                                  block=8, name="fur mix: lt without the step through")
    print(res)
    assert not res.passed
