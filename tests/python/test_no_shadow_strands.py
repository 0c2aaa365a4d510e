"""Strands that cast no shadow (a curves object's Cast Shadow off) in the bidirectional
integrators (bdpt, lvc, cis) against pt, statistically (compare_renders: block means, Student
t). Handed to pt before nocast3 (allocation.cpp bidir_visibility_reason).

pt's rule: the shadow query skips the non-casting segments as it skips non-casting triangles
(curve_query_build.cpp: kind 2 takes kCastShadow strands alone), every other ray hits them.
bdpt, lvc and cis take the rule of integrator/bidir_no_shadow.h unchanged: s = 1 traces the
shadow query and, where it passes, the ordinary one, scaling the contribution by pt's weight's
ratio where only a non-caster blocks (a strand is no volume boundary: bidir_medium_blocked
stops at it in fog); connections trace the ordinary query.

test_linking_bidir.py's room (red ball B, max_depth 4) with a mat of 16 strands (radius 1.5 cm,
4.5 cm apart, red) over the floor's left at z 1.1 in place of the slab, seen by the camera:

- surface: no fog; the mat casts no shadow;
- fog: the same in test_linking_media.py's world fog;
- linked: no fog, the quad shadow-linked (its blockers set 0: every object but ball B, set 1),
  the mat (set 0) casting no shadow: the quad's class A is its next event's alone (ratio 1), its
  shadow ray pt_occluded_linked on the shadow query, which passes the strands.

The control, the mat casting its shadows, must fail. lt keeps handing non-casting strands over
(its first segment's walk past a strand is not done): same bits as pt."""
import numpy as np
import pytest

from no_shadow_compare import assert_matches_pt  # (16 seeds x 32 spp a side)
from test_linking_bidir import room
from test_linking_media import FOG
from test_linking_shadow_media import render  # (32 spp at max_depth 4, the first 3 channels)


def mat(s, on):
    """16 strands along x (-1.0 .. -0.2) at z 1.1, y -0.5 .. 0.2; cast no shadow where on."""
    n, keys = 16, 4
    ys = np.linspace(-0.5, 0.2, n)
    xs = np.linspace(-1.0, -0.2, keys)
    pts = np.stack([np.tile(xs, n), np.repeat(ys, keys), np.full(n * keys, 1.1)], axis=-1)
    s.add_curves(pts.astype(np.float32), np.full(n * keys, 0.015, np.float32),
                 np.arange(0, n * keys + 1, keys), material="red", name="mat",
                 cast_shadow=not on)
    return s


def surface(on=True):
    return mat(room("red"), on)


def fog(on=True):
    s = mat(room("red"), on)
    s.world = {"color": [0.0] * 3, "volume": dict(FOG)}
    return s


def linked(on=True):
    s = mat(room("red"), on)
    s.meshes[3]["shadow_set"] = 1
    s.meshes[4]["blockers"] = [0]
    return s


CASES = {"surface": surface, "fog": fog, "linked": linked}


@pytest.fixture(scope="module")
def pt_refs(core):
    return {}


@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_matches_pt(pt_refs, integrator, case):
    # (the control: the mat casting its shadows is told apart)
    assert_matches_pt(f"strands without shadows ({case})", pt_refs, CASES, case, integrator)


def test_lt_hands_over(core):
    img, warnings = render(surface(), "lt", 7, spp=2)
    assert any("rendering with pt" in w for w in warnings), warnings
    np.testing.assert_array_equal(img, render(surface(), "pt", 7, spp=2)[0])
