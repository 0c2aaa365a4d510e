"""The light tracer renders object and lamp ray visibility by kind beside media itself
(integrator/lt_ray_visibility.h lt_rays_medium_weight, lt_medium.h), against pt (compare_renders:
block means, Student t; tests/README.md). Until ltkinds it handed such scenes to pt.

pt's rule in media (pt_volume.h, Cycles since Blender 4.4): a medium vertex's phase ray is of
kind Volume Scatter alone, passes surfaces hidden from it and skips a lamp hidden from it; its
next event skips a light hidden from Volume Scatter; its weights are the solid-angle power
heuristic (the phase's density against the light's), without the flights' factors. In lt a
medium vertex is a scattering of kind Volume Scatter: it counts where no surface its segment
passed is seen by Volume Scatter rays and the vertex the segment left is (a medium point: every
kind; at y1: the light not hidden from Volume Scatter), and at y1 past surfaces all hidden from
it takes pt's phase ray's share 1 - w_nee (none from a delta light). In a scene with media lt's
segments also walk past surfaces hidden from Volume Scatter alone (lt_rays_all); a surface
vertex past one counts for no surface kind. Volume boundaries are crossed before any kind is
read, as pt does; a passed surface keeps the medium (a memoryless flight goes on).

The scenes are test_ray_visibility_media.py's (test_linking_bidir.py's room in
test_linking_media.py's fog; max_depth 4): world_volume, world_diffuse, world_lamp,
world_lamp_glossy, box_inside, box_crossing, grid (a heterogeneous fog box). Each against pt, 16
seeds; the control, the kinds cleared, must fail. CI runs world_volume; the rest is long. Exact:
world fog lit only by an area lamp hidden from Volume Scatter is black in lt
(test_lt_hidden_from_volume_scatter_lights_no_fog; test_ray_visibility_media.py's emissive floor,
100 m wide, is too wide for lt's few light paths to reach the camera's fog).

Linking or Cast Shadow off beside the kinds in media, and media with subsurface walks beside
them, stay pt's (test_lt_hands_over_with_linking)."""
import numpy as np
import pytest

from lantern import metrics

from test_linking_shadow_media import render  # noqa: E402
from test_ray_visibility_media import CASES, K, SPP, world_volume  # noqa: E402

LT = 4  # lt's samples a seed over pt's (the noisier, the cheaper side)


def renders(name, integrator, seed0, on=True, spp=SPP):
    out, warnings = [], []
    for k in range(K):
        img, warnings = render(CASES[name](on), integrator, seed0 + k, spp)
        out.append(img)
    return out, warnings


# (world_lamp_glossy: the lamp seen only past the metal ball's reflection, lt resolves about
# 20 % on a block there: its block control 25 %)
BLOCK_BIAS = {"world_lamp_glossy": 0.25}


def check(case):
    ref, _ = renders(case, "pt", 1000, spp=2 * SPP)
    imgs, warnings = renders(case, "lt", 2000, spp=LT * SPP)
    assert not warnings, warnings  # rendered by lt itself, no hand-over
    metrics.assert_agreement(f"{case} (ray kinds in media), lt vs pt", imgs, ref, block=4,
                             image_bias=0.04, block_bias=BLOCK_BIAS.get(case, 0.15))
    # the control: the kinds cleared (the scene without them) is seen
    free, _ = renders(case, "lt", 3000, on=False, spp=LT * SPP)
    res = metrics.compare_renders(free, ref, block=4, name=f"{case} kinds off")
    print(res)
    assert not res.passed, res


def test_lt_world_volume(core):
    """CI's case: the slab hidden from Volume Scatter in world fog."""
    check("world_volume")


@pytest.mark.long
@pytest.mark.parametrize("case", [c for c in CASES if c != "world_volume"])
def test_lt_matches_pt(core, case):
    check(case)


def test_lt_hands_over_with_linking(core):
    """Beside a lamp's Cast Shadow off in media lt's kinds stay pt's, saying so; same bits."""
    s = world_volume()
    s.lights[0]["cast_shadow"] = False
    img, warnings = render(s, "lt", 7, spp=2)
    assert any("linking or Cast Shadow off" in w and "with pt" in w for w in warnings), warnings
    t = world_volume()
    t.lights[0]["cast_shadow"] = False
    np.testing.assert_array_equal(img, render(t, "pt", 7, spp=2)[0])


def test_lt_hidden_from_volume_scatter_lights_no_fog(core):
    """Exact: world fog lit only by an area lamp hidden from Volume Scatter rays is black in lt
    (a medium vertex at y1 counts for no light hidden from its kind); hidden from Diffuse rays
    instead (the control) it is lit, as pt's."""
    import test_lamp_visibility as la
    dark, warnings = la.render(la.fog_scene(la.hidden("volume_scatter")), spp=4,
                               integrator="lt")
    assert not warnings, warnings  # rendered by lt itself
    assert dark.max() == 0.0
    lit, _ = la.render(la.fog_scene(la.hidden("diffuse")), spp=4, integrator="lt")
    assert lit[..., :3].mean() > 0.1
