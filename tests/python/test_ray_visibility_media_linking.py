"""Object and lamp ray visibility by kind beside media *together with* light linking, shadow
linking and Cast Shadow off (a lamp's, an object's, a volume's mesh) in the bidirectional
integrators (bdpt, lvc, cis) against pt, statistically (compare_renders: block means, Student t).
Handed to pt before medmix (allocation.cpp bidir_visibility_reason: "object or lamp ray
visibility with linking or Cast Shadow off beside ..."); docs/lvc_notes.md "Ray visibility by
kind", "Beside media".

Each rule composes as on surfaces (test_ray_visibility_linking.py): ray visibility splits the
paths first; a restricted path (a segment past the camera's meets a surface hidden from its
kind, or ends on a hidden lamp) is pt's two techniques with pt's weights, which carry the
linking rules pt has (in media without flight factors: the restricted next event queued with
both factor parts 0, so a non-caster's ratio is 1 there); an unrestricted one keeps the linking
rules' techniques and weights in media (bidir_linking_medium.h, bidir_no_shadow.h,
bidir_no_shadow_medium.h).

test_linking_bidir.py's room (floor, wall, ball A, ball B, the emissive quad, the slab over the
floor's left under the 1.6 m area lamp), max_depth 4, 16 seeds x 64 spp, 16 x 16, in
test_linking_media.py's fog; the kinds: the slab hidden from Volume Scatter and Diffuse rays
(the fog and the floor under it see the lamp through it by pt's bounce alone; its shadow still
darkens next-event estimation), and where named the lamp hidden from Glossy rays beside a rough
metal ball B (an R light: pt's weights on every path ending on it):

- lamp_world / lamp_box: the lamp's Cast Shadow off, world fog / a fog box under the lamp;
- slab_world: the slab's Cast Shadow off too (where the two rules meet on one segment: pt's
  next event passes the slab, its bounce ray too);
- light_world: light linking (the lamp lights floor, wall, slab and ball A; the quad ball B);
- shadow_world: shadow linking (the quad's shadows cast by ball B alone);
- glossy_world: the lamp hidden from Glossy too, beside a metal ball B in its blocker set alone;
- lamp_glossy_world: glossy_world with the lamp the only thing hidden (pt's split MIS in world
  fog, pt_linked_mis_fog, against the bidirectional next event alone);
- rules_box: the fog box, light linking, the quad shadow-linked, the slab casting no shadow;
- volume_box: the fog box's mesh casting no shadow (T' V' - T V at pt's weight).

The control: the same scene with the kinds cleared (the linking rule kept) must fail against
pt's image of the scene with both. Exact, in CI: fog lit only by a lamp or an emissive floor
hidden from Volume Scatter, casting no shadow, is black (test_hidden_from_volume_scatter_...).
In CI: cis on rules_box and the exact test; the rest is long."""
import numpy as np
import pytest

from lantern import metrics

from test_linking_bidir import room
from test_linking_media import FOG
from test_linking_shadow_media import render
from test_volume_bidir import _volume_box

# seeds (tests/README.md: Welch dof >= 15) x samples per pixel: the long runs (at 32 light_world's
# noise let a 2.5 % image bias pass), CI's case (rules_box resolves it at 32)
K, SPP, SPP_CI = 16, 64, 32

BOX = ((-2.5, -2.5, -0.1), (2.5, 1.4, 1.3))  # under the slab (z 1.1), the quad and the lamp


def _scene(fog, kinds, glossy=False):
    s = room("red", slab=True)
    if glossy:
        metal = s.add_material("metal", type="conductor", base_color=(0.9, 0.9, 0.9),
                               roughness=0.3)
        s.meshes[3]["material_ids"] = np.full(len(s.meshes[3]["indices"]), metal, np.uint32)
    if fog == "world":
        s.world = {"color": [0.0] * 3, "volume": dict(FOG)}
    else:
        _volume_box(s, "fog", dict(FOG), *BOX)
    if kinds:
        s.meshes[5]["visible_volume_scatter"] = False  # the slab
        s.meshes[5]["visible_diffuse"] = False
        if glossy:
            s.lights[0]["visible_glossy"] = False
    return s


def lamp_no_shadow(fog):
    def build(kinds=True):
        s = _scene(fog, kinds)
        s.lights[0]["cast_shadow"] = False
        return s
    return build


def slab_world(kinds=True):
    s = _scene("world", kinds)
    s.meshes[5]["cast_shadow"] = False
    return s


def _light_links(s):
    s.meshes[2]["light_set"] = 1
    s.meshes[3]["light_set"] = 2
    s.lights[0]["receivers"] = [0, 1]  # the lamp: floor, wall, slab (set 0), ball A
    s.meshes[4]["receivers"] = [2]     # the quad: ball B alone
    return s


def light_world(kinds=True):
    return _light_links(_scene("world", kinds))


def shadow_world(kinds=True):
    """The quad shadow-linked, the lamp not (with every light shadow-linked no light sub-path
    leaves y1 and bdpt, lvc, cis render the same bits; glossy_world links the lamp)."""
    s = _scene("world", kinds)
    s.meshes[3]["shadow_set"] = 1
    s.meshes[4]["blockers"] = [1]  # shadows of ball B alone
    return s


def glossy_world(kinds=True):
    s = _scene("world", kinds, glossy=True)
    s.meshes[3]["shadow_set"] = 1
    s.lights[0]["blockers"] = [1]
    return s


def lamp_glossy_world(kinds=True):
    """glossy_world with the lamp the only thing hidden (no mesh: pt splits a shadow-linked
    light's two techniques in world fog, pt_linked_mis_fog; bdpt, lvc, cis keep next-event
    estimation alone, class A: the same mean)."""
    s = _scene("world", False, glossy=True)
    s.meshes[3]["shadow_set"] = 1
    s.lights[0]["blockers"] = [1]
    if kinds:
        s.lights[0]["visible_glossy"] = False
    return s


def rules_box(kinds=True):
    s = _light_links(_scene("box", kinds))
    s.meshes[3]["shadow_set"] = 1
    s.meshes[4]["blockers"] = [1]
    s.meshes[5]["cast_shadow"] = False
    return s


def volume_box(kinds=True):
    s = _scene("box", kinds)
    s.meshes[-1]["cast_shadow"] = False  # the fog box
    return s


CASES = {"lamp_world": lamp_no_shadow("world"), "lamp_box": lamp_no_shadow("box"),
         "slab_world": slab_world, "light_world": light_world, "shadow_world": shadow_world,
         "glossy_world": glossy_world, "lamp_glossy_world": lamp_glossy_world,
         "rules_box": rules_box, "volume_box": volume_box}


def renders(name, integrator, seed0, kinds=True, spp=SPP):
    out, warnings = [], []
    for k in range(K):
        img, warnings = render(CASES[name](kinds), integrator, seed0 + k, spp=spp)
        out.append(img)
    return out, warnings


@pytest.fixture(scope="module")
def pt_refs(core):
    return {}


def pt_ref(pt_refs, name, spp):
    if (name, spp) not in pt_refs:
        pt_refs[name, spp] = renders(name, "pt", 1000, spp=spp)[0]
    return pt_refs[name, spp]


def check(pt_refs, integrator, case, spp=SPP):
    ref = pt_ref(pt_refs, case, spp)
    imgs, warnings = renders(case, integrator, 2000, spp=spp)
    assert not warnings, warnings  # rendered by the integrator itself
    metrics.assert_agreement(f"{case}, {integrator} vs pt", imgs, ref, block=4,
                             image_bias=0.025, block_bias=0.1)
    # the control: the kinds cleared (the linking rule kept) is seen
    free, _ = renders(case, integrator, 3000, kinds=False, spp=spp)
    control = metrics.compare_renders(free, ref, block=4)
    print("control (the kinds cleared):", control)
    assert not control.passed


def test_cis_rules_box_matches_pt(pt_refs):
    """CI's case: cis, the fog box with light linking, shadow linking and the slab (hidden from
    Volume Scatter and Diffuse) casting no shadow."""
    check(pt_refs, "cis", "rules_box", SPP_CI)


LONG = [(i, c) for c in CASES for i in ("bdpt", "lvc", "cis") if (i, c) != ("cis", "rules_box")]


@pytest.mark.long
@pytest.mark.parametrize("integrator,case", LONG)
def test_matches_pt(pt_refs, integrator, case):
    check(pt_refs, integrator, case)


@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_hidden_from_volume_scatter_without_shadows_lights_no_fog(core, integrator):
    """Exact: world fog lit only by a lamp hidden from Volume Scatter rays with its Cast Shadow
    off (its next event unoccluded, pt's weight) or by an emissive floor hidden from Volume
    Scatter that casts no shadow (test_fog_object_visibility.py's) is black in every technique;
    the controls, hidden from the surface kinds instead, light it."""
    import test_fog_object_visibility as fo
    import test_lamp_visibility as la

    def lamp(kinds):
        s = la.fog_scene(la.hidden(*kinds))
        s.lights[0]["cast_shadow"] = False
        return s

    def floor(kinds):  # (fog_scene's floor casts no shadow)
        return fo.fog_scene(fo.hidden(*kinds), emission=1.0, lamp=False)
    for dark_scene, lit_scene in ((lamp(["volume_scatter"]), lamp(["diffuse"])),
                                  (floor(["volume_scatter"]), floor(fo.SURFACE_KINDS))):
        dark, warnings = la.render(dark_scene, spp=4, integrator=integrator)
        assert not warnings, warnings  # rendered by the integrator itself
        assert dark.max() == 0.0
        lit, _ = la.render(lit_scene, spp=4, integrator=integrator)
        assert lit[..., :3].mean() > 1e-3
