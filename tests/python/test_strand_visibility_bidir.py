"""Strands hidden from some kind of ray (their object's ray visibility, D58) in the bidirectional
integrators (bdpt, lvc, cis) against pt, statistically (compare_renders: block means, Student
t; no_shadow_compare's 16 seeds x 32 spp a side at max_depth 4).

bdpt, lvc and cis take bidir_ray_visibility.h's rule unchanged: a strand segment hidden from
some kind is an R surface (SceneView::tri_rays holds its object's kinds); the camera pass's
bounce ray passes a strand hidden from its kind (pt_pass_hidden_strand: on from the same origin
past the entry) and the path becomes restricted (pt's two techniques and weights), a light
vertex on such a strand is splatted only. pt's own rule is checked exactly in
test_strand_visibility.py (a cage hidden from a kind: the image without it, bit for bit).

test_no_shadow_strands.py's room (test_linking_bidir.py: white floor and wall, white ball A,
red ball B, the area lamp and the emissive quad hidden from the camera) with its mat of 16
strands over the floor's left (z 1.1), seen by the camera, casting shadows:

- diffuse: the red mat hidden from diffuse rays (the floor's and the wall's bounce light passes
  it; its shadow stays);
- hair: the same with the mat a Principled Hair (melanin 0.4: fiber vertices, bdpt_curve.h).

(The wall a rough metal and the mat hidden from glossy rays was tried: bdpt agreed, but the
control, the mat reflected, was not told apart at this noise.)

The control, the mat seen by every kind, must fail."""
import numpy as np
import pytest

from no_shadow_compare import assert_matches_pt
from test_linking_bidir import room
from test_no_shadow_strands import mat


def diffuse(on=True):
    s = mat(room("red"), False)
    if on:
        s.curves[0]["visible_diffuse"] = False
    return s


def hair(on=True):
    s = diffuse(on)
    h = s.add_material("hair", type="hair", hair={"parametrization": "melanin",
                                                  "melanin": 0.4})
    s.curves[0]["material_ids"] = np.full_like(s.curves[0]["material_ids"], h)
    return s


CASES = {"diffuse": diffuse, "hair": hair}


@pytest.fixture(scope="module")
def pt_refs(core):
    return {}


@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_matches_pt(pt_refs, integrator, case):
    # (the control: the mat seen by every kind is told apart)
    assert_matches_pt(f"strands hidden by kind ({case})", pt_refs, CASES, case, integrator)
