"""Cast Shadow off beside media and shadow linking in the bidirectional integrators (bdpt, lvc,
cis) against pt, statistically (compare_renders: block means, Student t). Each scene was
handed to pt before (allocation.cpp bidir_visibility_reason); docs/lvc_notes.md "Linking".

test_linking_bidir.py's room (a floor, a wall, two balls, the slab over the floor's left, the
1.6 m area lamp and the emissive quad above them), max_depth 4:

- lamp: the lamp's Cast Shadow off (the slab and the balls do not shadow it) in world fog and in
  a fog box (a mesh volume around the floor, the balls and the slab, its top under the lamp and
  the quad): pt's next-event estimation of the lamp traces no shadow ray and no medium
  (pt_volume.h pt_medium_nee, pt.h), with pt's MIS weight, the emission BSDF and phase sampling
  find is occluded and attenuated, with pt's weight. bdpt, lvc and cis take pt's weights for
  paths whose vertex next to the lamp scatters off a non-delta lobe (a medium vertex's phase
  function too): s = 1 there without a ray or transmittance, s = 0 with pt's weight, no light
  sub-path through such a y1 (bidir_linking.h, bdpt_medium_stages.h, bdpt_medium_light.h).
  The control, the lamp with its shadows, must fail.

The fog is test_linking_media.py's."""
import numpy as np
import pytest

from no_shadow_compare import assert_matches_pt  # (16 seeds x 32 spp a side)
from test_linking_bidir import no_shadow, room
from test_linking_media import FOG
from test_linking_shadow_media import render
from test_volume_bidir import _volume_box


def fogged(s, case):
    if case == "world":
        s.world = {"color": [0.0] * 3, "volume": dict(FOG)}
    else:  # under the slab (z 1.1), the quad (1.6) and the lamp (1.8)
        _volume_box(s, "fog", dict(FOG), (-2.5, -2.5, -0.1), (2.5, 1.4, 1.3))
    return s


def lamp(case, on=True):
    """The lamp's Cast Shadow off (on) in fog `case`; on False: the lamp casts its shadows."""
    return fogged(no_shadow(on), case)


def slab_off(s, on):
    if on:
        s.meshes[5]["cast_shadow"] = False  # the slab
    return s


def obj(case, on=True):
    """The slab's Cast Shadow off (on) in fog `case`; on False: it casts its shadows."""
    return fogged(slab_off(room("red", slab=True), on), case)


def obj_linked(on=True):
    """No fog: the quad shadow-linked (blockers: set 0, every object but the glass ball, set 1)
    and the slab (set 0) casting no shadow; the lamp over the slab is not linked."""
    s = room("glass", slab=True)
    s.meshes[3]["shadow_set"] = 1
    s.meshes[4]["blockers"] = [0]
    return slab_off(s, on)


def obj_linked_fog(on=True):
    """obj_linked in world fog: shadow linking and a non-caster beside media at once (handed to
    pt before nocast3). The quad's class A is its next event's alone (weights 0: the
    non-caster's ratio 1), its shadow ray through the fog with its blocker sets and the shadow
    query (bdpt_medium_shadow); the lamp's past the slab takes pt's weight (bidir_medium_blocked,
    bidir_no_shadow_medium_c)."""
    return fogged(obj_linked(on), "world")


CASES = {"lamp_world": lambda on: lamp("world", on), "lamp_box": lambda on: lamp("box", on),
         "object_world": lambda on: obj("world", on), "object_box": lambda on: obj("box", on),
         "object_linked": obj_linked, "object_linked_fog": obj_linked_fog}


@pytest.fixture(scope="module")
def pt_refs(core):
    return {}


@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_matches_pt(pt_refs, integrator, case):
    assert_matches_pt(case, pt_refs, CASES, case, integrator)


@pytest.mark.parametrize("integrator", ["bdpt", "lt"])
def test_volume_mesh_without_shadow_hands_over(core, integrator):
    """A fog box that casts no shadow (its volume would be skipped by the shadow rays alone)
    stays pt's, as does lt's Cast Shadow off in media (allocation.cpp): same bits."""
    s = obj("box", on=False)
    s.meshes[-1]["cast_shadow"] = False  # the fog box
    img, warnings = render(s, integrator, 7, spp=2)
    assert any("rendering with pt" in w for w in warnings), warnings
    np.testing.assert_array_equal(img, render(s, "pt", 7, spp=2)[0])
