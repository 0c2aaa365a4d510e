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

from lantern import metrics
from no_shadow_compare import assert_matches_pt, renders  # (16 seeds x 32 spp a side)
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


DENSE = {"sigma_s": [1.0, 1.0, 1.0], "sigma_a": [0.05, 0.1, 0.15], "g": 0.3}


def fog_box(where, on=True):
    """A fog box whose mesh casts no shadow (on; on False: it casts its shadows) in the room
    with the slab: pt's shadow ray skips the box's volume, crossing it or from inside (D61,
    fixd61: Cycles' rule; bidir_no_shadow_medium.h). where: "box", test_no_shadow_media's box
    under the lamp (the camera and the lamp outside: a shadow ray from inside passes no fog,
    T' > T); "light", a dense box around the lamp and the quad alone (the camera outside: a
    shadow ray from the floor passes no fog, T' > T); "camera", a box around the camera, the
    lamp and the room but the wall (no shadow ray passes fog); "world", the box of dense fog in
    world fog (a shadow ray passes the world's fog alone)."""
    s = room("red", slab=True)
    if where == "box":
        _volume_box(s, "fog", dict(FOG), (-2.5, -2.5, -0.1), (2.5, 1.4, 1.3))
    elif where == "light":
        _volume_box(s, "fog", dict(DENSE), (-1.5, -0.9, 1.45), (1.4, 0.9, 2.0))
    elif where == "camera":
        _volume_box(s, "fog", dict(FOG), (-4.0, -4.0, -0.1), (4.0, 1.4, 3.0))
    else:
        s.world = {"color": [0.0] * 3, "volume": dict(FOG)}
        _volume_box(s, "fog", dict(DENSE), (-2.5, -2.5, -0.1), (2.5, 1.4, 1.3))
    if on:
        s.meshes[-1]["cast_shadow"] = False  # the fog box
    return s


BOX_CASES = {f"volume_{w}": (lambda w: lambda on: fog_box(w, on))(w)
             for w in ("box", "light", "camera", "world")}


@pytest.mark.parametrize("case", [
    pytest.param(c, marks=() if c == "volume_box" else pytest.mark.long) for c in BOX_CASES])
@pytest.mark.parametrize("integrator", [
    "bdpt", pytest.param("lvc", marks=pytest.mark.long), pytest.param("cis", marks=pytest.mark.long)])
def test_volume_mesh_matches_pt(pt_refs, integrator, case):
    """A volume's mesh that casts no shadow in media: s = 1 traces both queries, c T V at the
    usual weight plus c (T' V' - T V) at pt's (bidir_no_shadow_medium.h). The control: the box
    casting its shadows."""
    if case not in pt_refs:
        pt_refs[case] = renders(BOX_CASES[case], "pt", 1000)[0]
    ref = pt_refs[case]
    imgs, warnings = renders(BOX_CASES[case], integrator, 2000)
    assert not warnings, warnings  # rendered by the integrator itself
    # (the dense box in world fog resolves a whole-image bias of 3.3-4.0 %, a block's of about
    # 12 %, at 16 x 32 spp)
    wide = case == "volume_world"
    metrics.assert_agreement(f"{case}, {integrator} vs pt", imgs, ref, block=4,
                             image_bias=0.045 if wide else 0.025,
                             block_bias=0.15 if wide else 0.1)
    free, _ = renders(BOX_CASES[case], integrator, 3000, on=False)
    control = metrics.compare_renders(free, ref, block=4)
    print("control (the box casting):", control)
    assert not control.passed


@pytest.mark.parametrize("integrator", ["bdpt", "lt", "surface"])
def test_volume_mesh_without_shadow_hands_over(core, integrator):
    """lt's Cast Shadow off in media stays pt's, as does bdpt's volume's mesh that casts no
    shadow beside a soft-falloff light (its light paths' first segment takes the shadow query,
    soft_light_medium.h; allocation.cpp) and a glass surface with fog inside that casts no
    shadow ("surface", untested): same bits."""
    s = obj("box", on=False)
    s.meshes[-1]["cast_shadow"] = False  # the fog box
    if integrator == "surface":
        glass = s.add_material("glass_fog", type="dielectric", base_color=(1.0, 1.0, 1.0),
                               roughness=0.0)
        s.materials[glass]["volume"] = dict(FOG)  # ball B: glass with fog inside
        s.meshes[3]["material_ids"][:] = glass
        s.meshes[3]["cast_shadow"] = False
        s.meshes[-1]["cast_shadow"] = True
        img, warnings = render(s, "bdpt", 7, spp=2)
        assert any("a surface with a volume that casts no shadow" in w for w in warnings), warnings
        np.testing.assert_array_equal(img, render(s, "pt", 7, spp=2)[0])
        return
    if integrator == "bdpt":
        s.add_light("point", to_world=[[1, 0, 0, 0.5], [0, 1, 0, 0], [0, 0, 1, 1.5],
                                       [0, 0, 0, 1]], power=[20.0] * 3, radius=0.1,
                    soft_falloff=True, name="soft")
    img, warnings = render(s, integrator, 7, spp=2)
    assert any("rendering with pt" in w for w in warnings), warnings
    if integrator == "bdpt":
        assert any("a volume's mesh that casts no shadow" in w for w in warnings), warnings
    np.testing.assert_array_equal(img, render(s, "pt", 7, spp=2)[0])
