"""Light linking, shadow linking and Cast Shadow off (a lamp's, an object's) with subsurface
scattering in the bidirectional integrators (bdpt, lvc, cis) against pt, statistically
(compare_renders: block means, Student t). Until sssbidir2 they handed such scenes to pt.

pt's rule (pt_sss.h pt_sss_exit): a walk's exit is a surface vertex of the object it leaves
(its receiver set is that surface's, for its next event and for the emission its continuation
finds), the walk's interior receives nothing, and the exit's shadow rays and connections follow
the blocker and non-caster rules of any surface vertex (integrator/bidir_linking.h,
bidir_no_shadow.h). The camera side's exit (bdpt_sss.h) and the light side's entry (y1 at x_o,
bdpt_sss_light.h) are such vertices; the light paths' walks (Skin) take part.

The scene: a white floor and back wall, a Skin ball (radius 0.4 m, Radius x Scale 0.3 / 0.15 /
0.08 m) under a red slab, a 1.6 m area lamp above and a 1 m emissive quad (hidden from the
camera) to the side, close enough that BSDF sampling and light paths carry a good share next to
next-event estimation's; max_depth 4. lt against pt too (its own light pass: lt_linking.h).

- light: the lamp lights the ball alone (set 1), the quad (here larger and just above the
  ball's right side) everything else (set 0) but the ball. An exit's continuation that finds the
  lamp counts (the exit receives as the ball); one that finds the quad does not. Before the exit
  recorded its set (pt_set_receiver in bdpt_sss_exit) the continuation read the set of the
  vertex before the walk (0 after a camera ray): bdpt read +3.5 % red on the image, a block
  +36 % (|z| 20) against pt here, and failed.
- shadow: the lamp's shadows are cast by the ball alone (its blocker set), not by the slab.
- lamp: the lamp's Cast Shadow off (pt's two weights, next-event estimation unoccluded).
- object: the slab's Cast Shadow off (pt's shadow rays pass it, every other ray hits it).
- linked_slab: both at once: the quad shadowed by set 0 alone (not the ball), the slab (set 0)
  casting no shadow; the lamp unlinked (the slab passed by its shadow rays, the ball not).

Each control is the same scene without the linking or with its shadows (it must fail)."""
import numpy as np
import pytest

import lantern
from lantern import metrics, scenes

K, SPP, SIZE = 16, 64, 16  # seeds x samples per pixel (tests/README.md: Welch dof >= 15)


def _quad(z, half, cx=0.0, cy=0.0):
    v = np.array([[cx - half, cy - half, z], [cx + half, cy - half, z],
                  [cx + half, cy + half, z], [cx - half, cy + half, z]], np.float32)
    return v, np.array([[0, 1, 2], [0, 2, 3]], np.uint32)


def room(near=False):
    """Meshes: 0 floor, 1 wall, 2 the Skin ball, 3 the emissive quad (near: 1.2 m, just above
    the ball's right side), 4 the slab; light 0 the lamp."""
    s = lantern.Scene()
    s.film.update(width=SIZE, height=SIZE)
    s.look_at((0.0, -2.6, 1.6), (0.0, 0.0, 0.35), fov=45.0)
    white = s.add_material("white", type="diffuse", base_color=(0.8, 0.8, 0.8))
    red = s.add_material("red", type="diffuse", base_color=(0.8, 0.3, 0.2))
    skin = s.add_material("skin", type="principled", base_color=(0.9, 0.6, 0.5), roughness=0.5,
                          subsurface={"weight": 1.0, "radius": [0.3, 0.15, 0.08],
                                      "method": "random_walk_skin"})
    emit = s.add_material("emit", type="diffuse", base_color=(0.0, 0.0, 0.0),
                          emission=(6.0, 6.0, 6.0))
    s.add_mesh(*_quad(0.0, 3.0), material=white, name="floor")
    wall = np.array([[-3, 1.5, 0], [3, 1.5, 0], [3, 1.5, 3], [-3, 1.5, 3]], np.float32)
    s.add_mesh(wall, np.array([[0, 2, 1], [0, 3, 2]], np.uint32), material=white, name="wall")
    pos, idx = scenes.icosphere(2, 0.4, center=(0.0, 0.0, 0.4))
    s.add_mesh(pos, idx, material=skin, name="ball")
    v, t = _quad(0.9, 0.6, 0.8) if near else _quad(1.4, 0.5, 0.9, 0.3)
    s.add_mesh(v, t[:, ::-1].copy(), material=emit, name="emitter", visible_camera=False)
    s.add_mesh(*_quad(1.1, 0.3, -0.25, -0.1), material=red, name="slab")
    to_world = [[1, 0, 0, -0.3], [0, 1, 0, 0], [0, 0, 1, 1.8], [0, 0, 0, 1]]
    s.add_light("area", to_world=to_world, shape="square", size=[1.6, 1.6],
                power=[80.0] * 3, name="lamp")
    s.world = {"color": [0.0] * 3}
    return s


def light(on=True):
    s = room(near=True)
    if on:
        s.meshes[2]["light_set"] = 1
        s.lights[0]["receivers"] = [1]  # the lamp: the ball alone
        s.meshes[3]["receivers"] = [0]  # the quad: all but the ball
    return s


def shadow(on=True):
    s = room()
    if on:
        s.meshes[2]["shadow_set"] = 1
        s.lights[0]["blockers"] = [1]  # the lamp's shadows: the ball's alone, not the slab's
    return s


def lamp(on=True):
    s = room()
    if on:
        s.lights[0]["cast_shadow"] = False
    return s


def _slab_casts_none(s, on):
    if on:
        s.meshes[4]["cast_shadow"] = False
    return s


def slab(on=True):
    return _slab_casts_none(room(), on)


def linked_slab(on=True):
    """Shadow linking and the slab's Cast Shadow off at once (handed to pt before nocast3): the
    quad's shadows cast by set 0 (the slab among them, casting no shadow; not the ball, set 1),
    the lamp's (not linked) by every surface but the slab. The quad's class A is its next
    event's alone (the non-caster's ratio 1, at an exit too), its shadow ray the shadow query
    with its blockers; the lamp's past the slab takes pt's weight (the ratio)."""
    s = room()
    s.meshes[2]["shadow_set"] = 1
    s.meshes[3]["blockers"] = [0]
    return _slab_casts_none(s, on)


BUILDS = [light, shadow, lamp, slab, linked_slab]


def render(scene, integrator, seed, spp=SPP):
    s = lantern.Session(scene, integrator=integrator, seed=seed, backend="cpu", max_depth=4,
                        spp_per_iteration=spp, threads=1)
    s.step()
    return np.asarray(s.image(), np.float64)[..., :3], s.warnings


def renders(build, integrator, seed0, on=True, spp=SPP):
    out, warnings = [], []
    for k in range(K):
        img, warnings = render(build(on), integrator, seed0 + k, spp)
        out.append(img)
    return out, warnings


@pytest.fixture(scope="module")
def pt_refs(core):
    # pt is the cheaper side: more samples a seed (tests/README.md)
    return {b.__name__: renders(b, "pt", 1000, spp=2 * SPP)[0] for b in BUILDS}


@pytest.mark.parametrize("build", BUILDS, ids=[b.__name__ for b in BUILDS])
@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_bidirectional_matches_pt(pt_refs, integrator, build):
    imgs, warnings = renders(build, integrator, 2000)
    assert not warnings, warnings  # rendered by the integrator itself, no hand-over
    ref = pt_refs[build.__name__]
    # (light: the lamp lights the ball alone, the quad the rest, an image about 3 x darker and
    # noisier; it resolves about 2 %, so its controls are 3 % / 15 %)
    dim = build is light
    metrics.assert_agreement(f"{build.__name__} with subsurface, {integrator} vs pt", imgs, ref,
                             block=4, image_bias=0.03 if dim else 0.01,
                             block_bias=0.15 if dim else 0.05)
    # the control: the scene without the linking / with its shadows must be told apart
    free, _ = renders(build, integrator, 3000, on=False)
    assert not metrics.compare_renders(free, ref, block=4).passed


@pytest.mark.parametrize("build", BUILDS, ids=[b.__name__ for b in BUILDS])
def test_lt_matches_pt(pt_refs, build):
    """lt's linking past a walk (lt_linking.h): its walk starts at y1 = x_o, whose set it
    checks as any y1's; from a y1 past a surface that casts the light no shadow it takes pt's
    next-event weight at a walk's exit (lt_sss_nee_weight)."""
    imgs, warnings = renders(build, "lt", 2000, spp=4 * SPP)  # (lt: noisier, cheaper)
    assert not warnings, warnings
    ref = pt_refs[build.__name__]
    # (lt resolves about 2.5 % here: its controls 4 % / 15 %)
    metrics.assert_agreement(f"{build.__name__} with subsurface, lt vs pt", imgs, ref,
                             block=4, image_bias=0.04, block_bias=0.15)
    free, _ = renders(build, "lt", 3000, on=False)
    assert not metrics.compare_renders(free, ref, block=4).passed
