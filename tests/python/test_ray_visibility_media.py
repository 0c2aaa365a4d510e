"""Object and lamp ray visibility by kind beside media in the bidirectional integrators (bdpt,
lvc, cis) against pt, statistically (compare_renders: block means, Student t). Handed to pt
before (allocation.cpp bidir_visibility_reason); docs/lvc_notes.md "Ray visibility by kind".

Cycles' rule (since Blender 4.4; pt: pt_ray_visibility.h kRayKindVolume): a ray a medium vertex
scatters is of kind Volume Scatter alone; it passes objects and lamps hidden from that kind,
and next-event estimation at a medium vertex skips a light hidden from it. Shadow rays see
every object (their own flag), so pt's image is f (w_nee V_shadow + w_bsdf V_kind): paths that
meet a surface hidden from some kind, or end on such a lamp, are made by pt's two techniques
with pt's weights (bidir_ray_visibility.h), which hold no flight factor in media.

test_linking_bidir.py's room (floor, wall, ball A, ball B red, the emissive quad, the slab over
the floor's left under the 1.6 m area lamp), max_depth 4, in test_linking_media.py's fog:

- world_volume: world fog, the slab hidden from Volume Scatter rays (the fog under it sees the
  lamp through it by phase sampling alone; it still shadows next-event estimation);
- world_diffuse: world fog, the slab hidden from Diffuse rays (surface vertices in fog);
- world_lamp: world fog, the lamp hidden from Volume Scatter rays (it lights no fog directly;
  light paths never leave it);
- world_lamp_glossy: world fog, ball B a rough metal, the lamp hidden from Glossy rays (pt's
  weights on every path ending on it, phase and diffuse vertices too: no flight factor);
- box_inside: a fog box (a mesh volume) around the floor, the balls and the slab, its top under
  the lamp, the slab inside it hidden from Volume Scatter rays;
- box_crossing: the fog box reaching past the wall (y 1.5 .. 2), which crosses its top and
  back, the wall hidden from Volume Scatter rays (a phase ray passes it into the fog behind,
  keeping its medium);
- grid: box_crossing with a density grid on the box (a heterogeneous volume).

The control, the scene with the kinds cleared, must fail."""
import numpy as np
import pytest

from lantern import metrics

from test_linking_bidir import room
from test_linking_media import FOG
from test_linking_shadow_media import render  # (16 x 32 as here)
from test_volume_bidir import _volume_box

K, SPP = 16, 32  # seeds x samples per pixel (tests/README.md: Welch dof >= 15)


def _world(s):
    s.world = {"color": [0.0] * 3, "volume": dict(FOG)}
    return s


def world_volume(on=True):
    s = _world(room("red", slab=True))
    if on:
        s.meshes[5]["visible_volume_scatter"] = False  # the slab
    return s


def world_diffuse(on=True):
    s = _world(room("red", slab=True))
    if on:
        s.meshes[5]["visible_diffuse"] = False
    return s


def world_lamp(on=True):
    s = _world(room("red", slab=True))
    if on:
        s.lights[0]["visible_volume_scatter"] = False
    return s


def world_lamp_glossy(on=True):
    """The lamp hidden from Glossy rays, ball B a rough metal: in fog every path ending on the
    lamp takes pt's weights (an R light), at medium vertices and diffuse ones too."""
    s = _world(room("red", slab=True))
    metal = s.add_material("metal", type="conductor", base_color=(0.9, 0.9, 0.9),
                           roughness=0.3)
    s.meshes[3]["material_ids"] = np.full(len(s.meshes[3]["indices"]), metal, np.uint32)
    if on:
        s.lights[0]["visible_glossy"] = False
    return s


def box_inside(on=True):
    s = room("red", slab=True)
    _volume_box(s, "fog", dict(FOG), (-2.5, -2.5, -0.1), (2.5, 1.4, 1.3))
    if on:
        s.meshes[5]["visible_volume_scatter"] = False
    return s


def box_crossing(on=True):
    s = room("red", slab=True)
    _volume_box(s, "fog", dict(FOG), (-2.5, -2.5, -0.1), (2.5, 2.0, 1.3))
    if on:
        s.meshes[1]["visible_volume_scatter"] = False  # the wall (y 1.5, z 0 .. 3)
    return s


def grid(on=True):
    """box_crossing with a density grid (0.5 .. 2 along x) on the box: a heterogeneous
    volume."""
    s = box_crossing(on)
    m4 = np.diag([5.0 / 4, 4.5 / 4, 1.4 / 4, 1.0])
    m4[:3, 3] = (-2.5, -2.5, -0.1)
    g = s.add_grid(np.broadcast_to(np.linspace(0.5, 2.0, 4, dtype=np.float32)[:, None, None],
                                   (4, 4, 4)).copy(), m4, name="fog:density")
    s.materials[s.meshes[-1]["material_ids"][0]]["density_grid"] = g
    return s


CASES = {f.__name__: f for f in (world_volume, world_diffuse, world_lamp, world_lamp_glossy,
                                 box_inside, box_crossing, grid)}


def renders(name, integrator, seed0, on=True):
    out, warnings = [], []
    for k in range(K):
        img, warnings = render(CASES[name](on), integrator, seed0 + k)
        out.append(img)
    return out, warnings


@pytest.fixture(scope="module")
def pt_refs(core):
    return {}


def pt_ref(pt_refs, name):
    if name not in pt_refs:
        pt_refs[name] = renders(name, "pt", 1000)[0]
    return pt_refs[name]


def check(pt_refs, integrator, case):
    ref = pt_ref(pt_refs, case)
    imgs, warnings = renders(case, integrator, 2000)
    assert not warnings, warnings  # rendered by the integrator itself
    metrics.assert_agreement(f"{case}, {integrator} vs pt", imgs, ref, block=4,
                             image_bias=0.025, block_bias=0.1)
    # the control: the kinds cleared (the scene without them) is seen
    free, _ = renders(case, integrator, 3000, on=False)
    assert not metrics.compare_renders(free, ref, block=4).passed


def test_cis_world_volume_matches_pt(pt_refs):
    """CI's case: cis, the slab hidden from Volume Scatter in world fog."""
    check(pt_refs, "cis", "world_volume")


LONG = [(i, c) for c in CASES for i in ("bdpt", "lvc", "cis")
        if (i, c) != ("cis", "world_volume")]


@pytest.mark.long
@pytest.mark.parametrize("integrator,case", LONG)
def test_matches_pt(pt_refs, integrator, case):
    check(pt_refs, integrator, case)


@pytest.mark.parametrize("integrator", ["lt", "auto"])
def test_renders_itself(core, integrator):
    """lt renders ray visibility beside media since ltkinds (test_ray_visibility_lt_media.py
    checks it against pt), auto weighs it since autotidy (test_auto_kinds.py): no hand-over."""
    _, warnings = render(world_volume(), integrator, 7, spp=2)
    assert not any("with pt" in w or "path tracing" in w for w in warnings), warnings


def test_lt_with_no_shadow_hands_over(core):
    """lt keeps the kinds beside media together with a lamp's Cast Shadow off pt's (not checked
    together: allocation.cpp bidir_visibility_reason); same bits as pt."""
    def scene():
        s = world_volume()
        s.lights[0]["cast_shadow"] = False
        return s
    img, warnings = render(scene(), "lt", 7, spp=2)
    assert any("with pt" in w or "path tracing" in w for w in warnings), warnings
    np.testing.assert_array_equal(img, render(scene(), "pt", 7, spp=2)[0])


def test_with_linking_renders(core):
    """Beside light or shadow linking or Cast Shadow off in media the bidirectional integrators
    render it themselves since medmix (test_ray_visibility_media_linking.py checks them
    against pt)."""
    s = world_volume()
    s.lights[0]["cast_shadow"] = False
    _, warnings = render(s, "bdpt", 7, spp=2)
    assert not warnings, warnings


@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_hidden_from_volume_scatter_lights_no_fog(core, integrator):
    """Exact: world fog lit only by a lamp (test_lamp_visibility.py) or an emissive floor
    (test_fog_object_visibility.py) hidden from Volume Scatter rays is black in every technique
    (the medium next event skips it, phase rays pass or do not see it, no light sub-path leaves
    an R light); the controls, hidden from the surface kinds instead, light it."""
    import test_fog_object_visibility as fo
    import test_lamp_visibility as la

    def floor(kinds):  # (casting shadows; without: test_ray_visibility_media_linking.py)
        s = fo.fog_scene(fo.hidden(*kinds), emission=1.0, lamp=False)
        s.meshes[0]["cast_shadow"] = True
        return s
    for dark_scene, lit_scene in (
            (la.fog_scene(la.hidden("volume_scatter")), la.fog_scene(la.hidden("diffuse"))),
            (floor(["volume_scatter"]), floor(fo.SURFACE_KINDS))):
        dark, warnings = la.render(dark_scene, spp=4, integrator=integrator)
        assert not warnings, warnings  # rendered by the integrator itself
        assert dark.max() == 0.0
        lit, _ = la.render(lit_scene, spp=4, integrator=integrator)
        assert lit[..., :3].mean() > 1e-3
