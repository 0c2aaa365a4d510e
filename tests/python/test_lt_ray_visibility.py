"""The light tracer renders object and lamp ray visibility by kind (Diffuse, Glossy,
Transmission) itself on surfaces (integrator/lt_ray_visibility.h), against pt (compare_renders:
block means, Student t; tests/README.md).

A white floor, a rough metal wall behind, a white ball A, a rough glass ball B, a red slab
over the floor's left under a 1 m area lamp, a point light off to the side; 12 x 12,
max_depth 4. lt's segments walk past the surfaces hidden from some kind, each vertex reached
past them counting only for the scatterings whose kind none of them is seen by (pt's bounce
ray from that vertex passes them), at the vertex the segment left seen by that kind:

- objects: ball A hidden from glossy rays (absent from the wall's reflection, still lit, still
  casting shadows), the slab hidden from diffuse rays (the floor's bounce light passes it to
  the lamp: the first segment's vertices past it take pt's bounce-ray share, 1 - w_nee), the
  wall hidden from transmission (glass ball B shows the black world past it);
- lamp: the area lamp hidden from glossy rays (absent from the wall's reflection, still
  lighting the floor), the point light hidden from diffuse ones (only the metal wall and the
  glass ball take its light).

Each against pt; the negative control, the flags off (the scene without them), must fail.

Beside the rules of the first segment (lt_linking.h), the objects scene with one more: both
lights without shadows, the slab and ball A without shadows, light linking (the lamp lights all
but glass ball B, the point light B alone), shadow linking (the lamp's shadows are glass ball
B's alone); under a veil hidden from the camera and from diffuse rays, lit by a grey world
too (the veil without shadows; the veil casting them, ball A not: every light walks); the slab
hidden from every kind. lt's first segment walks one walk for both rules (lt_rays_step): a
vertex past what it passed takes pt's next event's share where all of it casts the light no
shadow, pt's bounce ray's where all of it is hidden from the vertex's kind (lt_rays_weight).
Each against pt; the control, the scene without the other rule (the kinds kept; the veil's
walk: the kinds dropped), must fail. CI runs the objects' Cast Shadow off; the rest is long.

lt still hands ray visibility with strands, and beside a soft-falloff light, to pt (past
subsurface walks and in media it renders it: test_ray_visibility_lt_sss.py,
test_ray_visibility_lt_media.py)."""
import numpy as np
import pytest

import lantern
from lantern import metrics, scenes

K, SPP = 16, 256  # seeds x samples per pixel (tests/README.md: Welch dof >= 15)
SIZE = 12


def quad(z, half, cx=0.0, cy=0.0):
    v = np.array([[cx - half, cy - half, z], [cx + half, cy - half, z],
                  [cx + half, cy + half, z], [cx - half, cy + half, z]], np.float32)
    return v, np.array([[0, 1, 2], [0, 2, 3]], np.uint32)


def build(kind, on=True):
    """Meshes: 0 floor, 1 wall, 2 ball A, 3 ball B, 4 slab; light 0 the lamp, 1 the point."""
    s = lantern.Scene()
    s.film.update(width=SIZE, height=SIZE)
    s.look_at((0.0, -2.6, 2.2), (0.0, 0.2, 0.4), fov=50.0)
    white = s.add_material("white", type="diffuse", base_color=(0.8, 0.8, 0.8))
    red = s.add_material("red", type="diffuse", base_color=(0.8, 0.3, 0.2))
    metal = s.add_material("metal", type="conductor", base_color=(0.9, 0.9, 0.9),
                           roughness=0.4)
    glass = s.add_material("glass", type="dielectric", base_color=(1.0, 1.0, 1.0),
                           roughness=0.3)
    s.add_mesh(*quad(0.0, 2.5), material=white, name="floor")
    wall = np.array([[-2.5, 1.2, 0], [2.5, 1.2, 0], [2.5, 1.2, 2.5], [-2.5, 1.2, 2.5]],
                    np.float32)
    s.add_mesh(wall, np.array([[0, 2, 1], [0, 3, 2]], np.uint32), material=metal, name="wall")
    for name, x, m in (("A", -0.55, white), ("B", 0.6, glass)):
        pos, idx = scenes.icosphere(2, 0.35, center=(x, 0.1, 0.35))
        s.add_mesh(pos, idx, material=m, name=name)
    s.add_mesh(*quad(1.0, 0.35, -0.5, -0.3), material=red, name="slab")
    to_world = [[1, 0, 0, -0.4], [0, 1, 0, -0.2], [0, 0, 1, 1.7], [0, 0, 0, 1]]
    s.add_light("area", to_world=to_world, shape="square", size=[1.0, 1.0],
                power=[60.0] * 3, name="lamp")
    s.add_light("point", position=[1.4, -1.2, 1.8], power=[25.0] * 3, name="point")
    s.world = {"color": [0.0] * 3}
    if on and kind == "objects":
        s.meshes[2]["visible_glossy"] = False
        s.meshes[4]["visible_diffuse"] = False
        s.meshes[1]["visible_transmission"] = False
    elif on and kind == "lamp":
        s.lights[0]["visible_glossy"] = False
        s.lights[1]["visible_diffuse"] = False
    return s


def render(scene, integrator, seed, spp=SPP):
    s = lantern.Session(scene, integrator=integrator, seed=seed, backend="cpu", max_depth=4,
                        spp_per_iteration=spp, threads=1)
    s.step()
    return np.asarray(s.image(), np.float64)[..., :3], s.warnings


def renders(kind, integrator, seed0, on=True, spp=SPP):
    out, warnings = [], []
    for k in range(K):
        img, warnings = render(build(kind, on), integrator, seed0 + k, spp)
        out.append(img)
    return out, warnings


@pytest.mark.parametrize("kind", ["objects", "lamp"])
def test_lt_matches_pt(core, kind):
    ref, _ = renders(kind, "pt", 1000)
    imgs, warnings = renders(kind, "lt", 2000, spp=4 * SPP)  # (lt: the noisier here)
    assert not warnings, warnings  # rendered by lt itself
    metrics.assert_agreement(f"{kind}, lt vs pt", imgs, ref, block=3, image_bias=0.03,
                             block_bias=0.15)
    # the control: the flags off (the scene without them) is seen
    free, _ = renders(kind, "lt", 3000, on=False, spp=2 * SPP)
    res = metrics.compare_renders(free, ref, block=3, name=f"{kind} off")
    print(res)
    assert not res.passed, res


def _lamps_no_shadow(s):
    """Both lights cast no shadow (the point light: next-event estimation alone past anything)."""
    s.lights[0]["cast_shadow"] = False
    s.lights[1]["cast_shadow"] = False


def _objects_no_shadow(s):
    """The slab (hidden from diffuse rays) and ball A (from glossy ones) cast no shadow."""
    s.meshes[4]["cast_shadow"] = False
    s.meshes[2]["cast_shadow"] = False


def _light_linked(s):
    """The lamp lights all but glass ball B, the point light B alone."""
    s.meshes[2]["light_set"] = 1
    s.meshes[3]["light_set"] = 2
    s.lights[0]["receivers"] = [0, 1]
    s.lights[1]["receivers"] = [2]


def _shadow_linked(s):
    """The lamp's shadows are glass ball B's alone (ball A and the slab cast it none)."""
    s.meshes[3]["shadow_set"] = 1
    s.lights[0]["blockers"] = [1]


def _grey_world(s):
    """A constant grey world, lighting the room but unseen by the camera (lt has no splat of a
    directly seen world); next-event estimation leaves it out (scene_lights.cpp): pt's bounce
    ray alone finds it."""
    s.world = {"color": [0.4] * 3, "visible_camera": False}




def _veil(s):
    """A veil over the whole room under the lights (z 1.2), hidden from the camera and from
    diffuse rays, under a grey world: the floor's light is the lights' seen past it."""
    s.add_mesh(*quad(1.2, 2.5), material=0, name="veil")
    s.meshes[5]["visible_diffuse"] = False
    s.meshes[5]["visible_camera"] = False
    _grey_world(s)


def _veil_no_shadow(s):
    """The veil casts no shadow: the floor takes both shares past it (w_nee + w_bsdf = 1);
    the world's w_nee is small, so the bounce ray's share shows."""
    s.meshes[5]["cast_shadow"] = False


def _veil_walk(s):
    """Ball A casts no shadow, so every light's first segment walks the one walk: past the veil
    (which casts shadows) the floor takes the bounce ray's share alone, the world's large."""
    s.meshes[2]["cast_shadow"] = False


def _veil_seen(s):
    """_veil_walk's control: the veil seen by diffuse rays (the kinds dropped: A's shadow is
    too faint under the veil to tell the rule dropped)."""
    s.meshes[5]["visible_diffuse"] = True


_veil_no_shadow.base = _veil_walk.base = _veil
_veil_walk.off = _veil_seen
for _r in (_veil_no_shadow, _veil_walk):  # (lt: noisy past the veil)
    _r.image_bias, _r.block_bias = 0.06, 0.3


def _slab_hidden(s):
    """The slab hidden from every kind (diffuse, glossy, transmission), casting shadows: the
    floor under it takes pt's bounce ray's share alone (1 - w_nee)."""
    s.meshes[4]["visible_glossy"] = False
    s.meshes[4]["visible_transmission"] = False


RULES = [_lamps_no_shadow, _objects_no_shadow, _light_linked, _shadow_linked, _veil_no_shadow,
         _veil_walk, _slab_hidden]


def mixed(rule, rule_on=True):
    s = build("objects")
    if hasattr(rule, "base"):
        rule.base(s)
    if rule_on or hasattr(rule, "off"):
        rule(s)
    if not rule_on and hasattr(rule, "off"):
        rule.off(s)
    return s


def mixed_renders(rule, integrator, seed0, rule_on=True, spp=SPP):
    out, warnings = [], []
    for k in range(K):
        img, warnings = render(mixed(rule, rule_on), integrator, seed0 + k, spp)
        out.append(img)
    return out, warnings


def check_mixed(rule):
    ref, _ = mixed_renders(rule, "pt", 1000)
    imgs, warnings = mixed_renders(rule, "lt", 2000, spp=4 * SPP)
    assert not warnings, warnings  # rendered by lt itself
    metrics.assert_agreement(f"objects with {rule.__name__}, lt vs pt", imgs, ref, block=3,
                             image_bias=getattr(rule, "image_bias", 0.03),
                             block_bias=getattr(rule, "block_bias", 0.15))
    # the control: the other rule dropped (the kinds kept; _veil_walk: the kinds dropped)
    free, _ = mixed_renders(rule, "lt", 3000, rule_on=False, spp=2 * SPP)
    res = metrics.compare_renders(free, ref, block=3, name=f"{rule.__name__} off")
    print(res)
    assert not res.passed, res


def test_lt_kinds_with_objects_no_shadow(core):
    check_mixed(_objects_no_shadow)


@pytest.mark.long
@pytest.mark.parametrize("rule", RULES[2:] + [_lamps_no_shadow],
                         ids=lambda r: r.__name__.lstrip("_"))
def test_lt_kinds_with_rule(core, rule):
    check_mixed(rule)


def _soft(s):
    """A soft-falloff light beside an object hidden from some kind: its lines' first segment
    (soft_light_path.h) does not walk."""
    s.add_light("point", position=[0.0, -0.5, 1.2], power=[20.0] * 3, radius=0.1,
                soft_falloff=True, name="soft")


def _strands(s):
    pts = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.5]], np.float32)
    s.add_curves(pts, np.full(2, 0.01, np.float32), np.array([0, 2]), material=0, name="hair")


@pytest.mark.parametrize("extra", [_soft, _strands], ids=["soft", "strands"])
def test_lt_hands_kinds_over_to_pt(core, extra):
    scene = build("objects")
    extra(scene)
    img, warnings = render(scene, "lt", 7, spp=2)
    assert any("ray visibility" in w and "rendering with pt" in w for w in warnings), warnings
    np.testing.assert_array_equal(img, render(scene, "pt", 7, spp=2)[0])
