"""Ray visibility by kind beside light linking, shadow linking and Cast Shadow off (a lamp's, an
object's) in the bidirectional integrators (bdpt, lvc, cis) against pt, statistically
(compare_renders: block means, Student t), in test_ray_visibility_bidir.py's room with every
kind rule on at once: the wall a rough metal, ball A hidden from glossy rays, the slab from
diffuse ones, the wall from transmission, the lamp from glossy rays (kinds_all); each scene
adds one rule of bidir_linking.h / bidir_no_shadow.h:

- light linking: the lamp lights the floor, the wall, the slab and ball A, the emissive quad
  the glass ball B alone;
- shadow linking: the lamp's and the quad's shadows cast by the glass ball alone;
- the lamp's Cast Shadow off (next-event estimation unoccluded, pt's two weights);
- the slab's Cast Shadow off (pt's shadow rays pass it; it is hidden from diffuse rays too);
- three at once (all_rules: the lamp lights all but the glass ball, the quad's shadows are
  the glass ball's alone, the slab casts no shadow).

A path restricted by ray visibility (a segment past the camera's meets a hidden surface or ends
on a hidden lamp) is pt's two techniques with pt's weights, the linking rules applying inside
them as pt applies them; an unrestricted one keeps the linking rules' techniques and weights
(docs/lvc_notes.md "Ray visibility by kind"). The control: the same scene without the linking
rule (the kinds kept) must fail against pt's image of the scene with it, so the comparison sees
the rule beside the kinds. In CI: cis on all_rules (auto's bidirectional integrator); the
rest is long. A rule broken on purpose, measured once (docs/lvc_notes.md): the non-caster ratio
taken before a restricted path's w_camera is dropped fails slab_no_shadow and all_rules."""
import sys
from pathlib import Path

import pytest

from lantern import metrics

sys.path.insert(0, str(Path(__file__).parent))
from test_linking_bidir import K, render  # noqa: E402  (the room's renders)
from test_ray_visibility_bidir import kinds_objects  # noqa: E402

SPP = 192  # (a 1 % image bias must show: tests/README.md)


def kinds_all():
    """kinds_objects with the lamp hidden from glossy rays too."""
    s = kinds_objects()
    s.lights[0]["visible_glossy"] = False
    return s


def light_linked(on=True):
    s = kinds_all()
    if on:
        s.meshes[2]["light_set"] = 1
        s.meshes[3]["light_set"] = 2
        s.lights[0]["receivers"] = [0, 1]  # the lamp: floor, wall, slab (set 0), ball A
        s.meshes[4]["receivers"] = [2]     # the quad: ball B alone
    return s


def shadow_linked(on=True):
    s = kinds_all()
    if on:
        s.meshes[3]["shadow_set"] = 1
        s.lights[0]["blockers"] = [1]      # shadows of the glass ball alone
        s.meshes[4]["blockers"] = [1]
    return s


def lamp_no_shadow(on=True):
    s = kinds_all()
    if on:
        s.lights[0]["cast_shadow"] = False
    return s


def slab_no_shadow(on=True):
    s = kinds_all()
    if on:
        s.meshes[5]["cast_shadow"] = False
    return s


def all_rules(on=True):
    """Three rules at once: the lamp lights all but the glass ball B, the quad's shadows are the
    glass ball's alone, the slab casts none (under the lamp, whose next events see that). (A
    lamp without shadows or shadow-linked would leave the slab's rule nothing to do there: its
    next event unoccluded, or next-event estimation's alone.)"""
    s = kinds_all()
    if on:
        s.meshes[2]["light_set"] = 1
        s.meshes[3]["light_set"] = 2
        s.meshes[3]["shadow_set"] = 1
        s.lights[0]["receivers"] = [0, 1]
        s.meshes[4]["blockers"] = [1]
        s.meshes[5]["cast_shadow"] = False
    return s


BUILDS = [light_linked, shadow_linked, lamp_no_shadow, slab_no_shadow]


def renders(build, integrator, seed0, on=True):
    out, warnings = [], []
    for k in range(K):
        img, warnings = render(build(on), integrator, seed0 + k, spp=SPP)
        out.append(img)
    return out, warnings


@pytest.fixture(scope="module")
def pt_refs(core):
    return {}


def pt_ref(pt_refs, build):
    if build.__name__ not in pt_refs:
        pt_refs[build.__name__] = renders(build, "pt", 1000)[0]
    return pt_refs[build.__name__]


def check(pt_refs, integrator, build):
    imgs, warnings = renders(build, integrator, 2000)
    assert not warnings, warnings  # rendered by the integrator itself
    ref = pt_ref(pt_refs, build)
    metrics.assert_agreement(f"kinds with {build.__name__}, {integrator} vs pt", imgs, ref,
                             block=4)
    # the control: the linking rule dropped (the kinds kept) is seen
    free, _ = renders(build, integrator, 3000, on=False)
    assert not metrics.compare_renders(free, ref, block=4).passed


def test_cis_all_rules_matches_pt(pt_refs):
    check(pt_refs, "cis", all_rules)


@pytest.mark.long
@pytest.mark.parametrize("build", BUILDS + [all_rules],
                         ids=[b.__name__ for b in BUILDS + [all_rules]])
@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_bidirectional_matches_pt(pt_refs, integrator, build):
    if integrator == "cis" and build is all_rules:
        pytest.skip("in CI: test_cis_all_rules_matches_pt")
    check(pt_refs, integrator, build)
