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
  (integrator/lt_linking.h; against pt: test_lt_linking.py); auto chooses between pt and cis
  there (branch autowide; test_auto_wide.py).
- ray visibility by kind (Diffuse, Glossy, Transmission; integrator/bidir_ray_visibility.h):
  the wall a rough metal; ball A hidden from glossy rays (absent from the wall's reflection,
  still lit and casting shadows), the slab hidden from diffuse rays (the floor's bounce light
  passes it, its shadow stays), the wall hidden from transmission (the glass ball B shows
  what lies past it, the black world); and, in a second scene, the lamp hidden from glossy
  rays beside the visible emissive quad (the wall does not reflect it; light paths never
  leave it). bdpt, lvc
  and cis render both themselves: paths that meet a hidden object past the camera's segment,
  or end on the hidden lamp, take pt's two techniques. The control (every object and the lamp
  seen by every kind) must fail. Beside media: test_ray_visibility_media.py; beside light and
  shadow linking and Cast Shadow off: test_ray_visibility_linking.py; beside subsurface walks:
  test_ray_visibility_subsurface.py (auto keeps pt there); lt renders ray
  visibility on surfaces itself (integrator/lt_ray_visibility.h; against pt:
  test_lt_ray_visibility.py), beside a lamp's Cast Shadow off it hands over."""
import sys
from pathlib import Path

import numpy as np
import pytest

import lantern
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


def glossy_wall(s):
    """The room's wall as a rough metal (mesh 1)."""
    metal = s.add_material("metal", type="conductor", base_color=(0.9, 0.9, 0.9),
                           roughness=0.4)
    s.meshes[1]["material_ids"] = np.full(len(s.meshes[1]["indices"]), metal, np.uint32)
    return s


def kinds_objects(on=True):
    """Ball A hidden from glossy rays, the slab from diffuse ones, the wall from transmission."""
    s = glossy_wall(room("glass", slab=True))
    if on:
        s.meshes[2]["visible_glossy"] = False
        s.meshes[5]["visible_diffuse"] = False
        s.meshes[1]["visible_transmission"] = False
    return s


def kinds_lamp(on=True):
    """The lamp hidden from glossy rays (the emissive quad seen by all)."""
    s = glossy_wall(room("glass", slab=True))
    if on:
        s.lights[0]["visible_glossy"] = False
    return s


# samples per pixel: the ray-kind scenes' rough metal wall is noisier than the room's
SPP_OF = {"kinds_objects": 256, "kinds_lamp": 128}


def renders(build, integrator, seed0, on=True):
    out, warnings = [], []
    spp = SPP_OF.get(build.__name__, 48)
    for k in range(K):
        img, warnings = render(build(on), integrator, seed0 + k, spp=spp)
        out.append(img)
    return out, warnings


@pytest.fixture(scope="module")
def pt_refs(core):
    return {b.__name__: renders(b, "pt", 1000)[0]
            for b in (camera_hidden, slab_no_shadow, kinds_objects, kinds_lamp)}


@pytest.mark.parametrize("build", [camera_hidden, slab_no_shadow, kinds_objects, kinds_lamp],
                         ids=["camera", "no_shadow", "kinds_objects", "kinds_lamp"])
@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_bidirectional_matches_pt(pt_refs, integrator, build):
    imgs, warnings = renders(build, integrator, 2000)
    assert not warnings, warnings  # rendered by the integrator itself
    metrics.assert_agreement(f"{build.__name__}, {integrator} vs pt", imgs,
                             pt_refs[build.__name__], block=4)
    # the control: the visibility ignored (the scene without it) is seen
    free, _ = renders(build, integrator, 3000, on=False)
    assert not metrics.compare_renders(free, pt_refs[build.__name__], block=4).passed


def test_no_shadow_object_auto_chooses_itself(core):
    """auto no longer hands an object without shadows to pt (branch autowide): cis renders it
    (above), and auto's pilot weighs the two (its image against pt's: test_auto_wide.py)."""
    s = lantern.Session(slab_no_shadow(), integrator="auto", seed=7, backend="cpu", threads=1)
    s.step()
    assert not any("casts no shadow" in w for w in s.warnings), s.warnings
    assert s.stats["auto_cis_iterations"] > 0  # its pilot's cis trials


def test_kinds_auto_chooses_itself(core):
    """auto no longer hands object or lamp ray visibility on surfaces to pt (branch automis):
    cis renders it (above), its moment channels are pt's (test_auto_wide.py), and auto's pilot
    weighs the two."""
    s = lantern.Session(kinds_lamp(), integrator="auto", seed=7, backend="cpu", threads=1)
    s.step()
    assert not any("path tracing" in w or "with pt" in w for w in s.warnings), s.warnings
    assert s.stats["auto_cis_iterations"] > 0  # its pilot's cis trials


def kinds_subsurface(on=True):
    """kinds_objects with ball A a Random Walk subsurface material: bdpt, lvc and cis render it
    (test_ray_visibility_subsurface.py), and auto weighs it since branch autotidy (its moment
    channels checked there: test_auto_kinds.py). (Beside linking and Cast Shadow off:
    test_ray_visibility_linking.py.)"""
    s = kinds_objects(on)
    m = s.add_material("skin", type="principled", base_color=(0.8, 0.6, 0.4), roughness=0.5,
                       subsurface={"weight": 1.0, "radius": [0.1, 0.05, 0.02],
                                   "method": "random_walk"})
    s.meshes[2]["material_ids"] = np.full(len(s.meshes[2]["indices"]), m, np.uint32)
    return s


# (lt renders the kinds beside a lamp's Cast Shadow off since ltmix: test_lt_ray_visibility.py;
# its hand-over beside subsurface walks: test_ray_visibility_subsurface.py)
def test_kinds_beside_subsurface_auto_chooses_itself(core):
    """auto no longer hands the kinds beside subsurface walks to pt (branch autotidy): its
    pilot weighs cis."""
    s = lantern.Session(kinds_subsurface(), integrator="auto", seed=7, backend="cpu", threads=1)
    s.step()
    assert not any("path tracing" in w or "with pt" in w for w in s.warnings), s.warnings
    assert s.stats["auto_cis_iterations"] > 0  # its pilot's cis trials
