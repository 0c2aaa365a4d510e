"""Object camera visibility and an object's Cast Shadow off in the bidirectional integrators
(bdpt, lvc, cis) against pt, statistically (compare_renders: block means, Student t), in
test_linking_bidir.py's room (a white floor and wall, a white ball A, a clear glass ball B, a
red slab over the floor's left, a 1.6 m area lamp and a 1 m emissive quad hidden from the
camera; max_depth 4).

- camera visibility: ball A and the slab hidden from the camera, the lamp seen by it. Camera
  rays (the camera's first segment x0 x1: its primary ray, light tracing's t = 1 connection)
  pass through a hidden object; every other segment sees it (reflections, refractions, shadows).
  bdpt, lvc and cis render it themselves; the control (every object seen, the lamp not) must
  fail.
- Cast Shadow off on the slab: pt's shadow rays pass through it, its BSDF rays hit it. The
  bidirectional integrators split pt's image into the physical one (the usual weights, the
  connections tracing the ordinary query) and the paths only the slab blocks, which next-event
  estimation alone makes, with pt's weight (integrator/bidir_no_shadow.h). Before that rule they
  read -6.2 % (bdpt), -7.0 % (lvc), -3.2 % (cis) against pt here (16 x 48 spp, worst block
  |z| 67, 69, 20). The control (the slab casting shadows) must fail. lt renders it too
  (integrator/lt_linking.h; against pt: test_lt_linking.py); auto hands the scene to pt (the
  same bits)."""
import sys
from pathlib import Path

import numpy as np
import pytest

from lantern import metrics

sys.path.insert(0, str(Path(__file__).parent))
from test_linking_bidir import K, render, room  # noqa: E402  (the room and its renders)


def camera_hidden(on=True):
    """Meshes 2 (ball A) and 5 (the slab) hidden from the camera, the lamp seen by it."""
    s = room("glass", slab=True)
    if on:
        s.meshes[2]["visible_camera"] = False
        s.meshes[5]["visible_camera"] = False
        s.lights[0]["visible_camera"] = True
    return s


def slab_no_shadow(on=True):
    s = room("glass", slab=True)
    if on:
        s.meshes[5]["cast_shadow"] = False
    return s


def renders(build, integrator, seed0, on=True):
    out, warnings = [], []
    for k in range(K):
        img, warnings = render(build(on), integrator, seed0 + k)
        out.append(img)
    return out, warnings


@pytest.fixture(scope="module")
def pt_refs(core):
    return {b.__name__: renders(b, "pt", 1000)[0] for b in (camera_hidden, slab_no_shadow)}


@pytest.mark.parametrize("build", [camera_hidden, slab_no_shadow],
                         ids=["camera", "no_shadow"])
@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_bidirectional_matches_pt(pt_refs, integrator, build):
    imgs, warnings = renders(build, integrator, 2000)
    assert not warnings, warnings  # rendered by the integrator itself
    metrics.assert_agreement(f"{build.__name__}, {integrator} vs pt", imgs,
                             pt_refs[build.__name__], block=4)
    # the control: the visibility ignored (the scene without it) is seen
    free, _ = renders(build, integrator, 3000, on=False)
    assert not metrics.compare_renders(free, pt_refs[build.__name__], block=4).passed


@pytest.mark.parametrize("integrator", ["auto"])
def test_no_shadow_object_hands_over_to_pt(core, integrator):
    img, warnings = render(slab_no_shadow(), integrator, 7, spp=4)
    assert any("casts no shadow" in w and ("with pt" in w or "path tracing" in w)
               for w in warnings), warnings
    np.testing.assert_array_equal(img, render(slab_no_shadow(), "pt", 7, spp=4)[0])
