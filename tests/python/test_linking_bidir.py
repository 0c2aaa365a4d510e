"""Light and shadow linking in the bidirectional integrators (integrator/bidir_linking.h) against
pt (integrator/pt_light_linking.h), statistically (compare_renders: block means, Student t).

A white floor and back wall, ball A (white), ball B (red or clear glass) and a slab, lit by a
1.6 m area lamp and a 1 m emissive quad (hidden from the camera) close above them, large
enough that BSDF sampling and light paths carry a good share of their light next to next-event
estimation's; max_depth 4 (indirect light):

- light linking: the lamp lights the floor, the wall and ball A (sets 0 and 1), the quad ball B
  alone (set 2). bdpt, lvc, cis and lt render it themselves (no hand-over), each technique
  applying the same zero; against pt. The negative control ignores the linking (the scene
  without it) and must fail; so must the 1 % / 5 % / channel-swap controls (lt: 2 % / 10 %).
- shadow linking: the lamp's and the quad's shadows are cast by the glass ball alone, not by the
  slab (a red square over the floor's left). Next-event estimation is the only technique for
  paths whose vertex next to the light scatters off a non-delta lobe; through the glass (a
  delta lobe) the usual weights stay. bdpt, lvc, cis against pt (lt: its first segment walks
  past the slab, integrator/lt_linking.h; against pt: test_lt_linking.py).
- Cast Shadow off on the lamp instead (the slab shadows it as usual): Cycles' mix of next-event
  estimation, unoccluded, and BSDF sampling, occluded, by pt's weights; bdpt, lvc, cis against
  pt, the lamp with shadows the control."""
import numpy as np
import pytest

import lantern
from lantern import metrics, scenes

K, SPP = 16, 48  # seeds x samples per pixel (tests/README.md: Welch dof >= 15)


def quad(z, half, cx=0.0, cy=0.0):
    v = np.array([[cx - half, cy - half, z], [cx + half, cy - half, z],
                  [cx + half, cy + half, z], [cx - half, cy + half, z]], np.float32)
    return v, np.array([[0, 1, 2], [0, 2, 3]], np.uint32)


def room(ball_b, slab=False, size=16):
    """Meshes: 0 floor, 1 wall, 2 ball A, 3 ball B, 4 emitter (5 slab, when asked); light 0 the
    lamp."""
    s = lantern.Scene()
    s.film.update(width=size, height=size)
    s.look_at((0.0, -3.0, 2.2), (0.0, 0.0, 0.3), fov=45.0)
    white = s.add_material("white", type="diffuse", base_color=(0.8, 0.8, 0.8))
    red = s.add_material("red", type="diffuse", base_color=(0.8, 0.3, 0.2))
    glass = s.add_material("glass", type="dielectric", base_color=(1.0, 1.0, 1.0),
                           roughness=0.0)
    emit = s.add_material("emit", type="diffuse", base_color=(0.0, 0.0, 0.0),
                          emission=(6.0, 6.0, 6.0))
    s.add_mesh(*quad(0.0, 3.0), material=white, name="floor")
    wall = np.array([[-3, 1.5, 0], [3, 1.5, 0], [3, 1.5, 3], [-3, 1.5, 3]], np.float32)
    s.add_mesh(wall, np.array([[0, 2, 1], [0, 3, 2]], np.uint32), material=white, name="wall")
    for name, x, m in (("A", -0.6, white), ("B", 0.6, glass if ball_b == "glass" else red)):
        pos, idx = scenes.icosphere(2, 0.4, center=(x, 0.0, 0.4))
        s.add_mesh(pos, idx, material=m, name=name)
    v, t = quad(1.6, 0.5, 0.8, 0.3)
    s.add_mesh(v, t[:, ::-1].copy(), material=emit, name="emitter", visible_camera=False)
    if slab:
        s.add_mesh(*quad(1.1, 0.45, -0.6, -0.1), material=red, name="slab")
    to_world = [[1, 0, 0, -0.6], [0, 1, 0, 0], [0, 0, 1, 1.8], [0, 0, 0, 1]]
    s.add_light("area", to_world=to_world, shape="square", size=[1.6, 1.6],
                power=[100.0] * 3, name="lamp")
    s.world = {"color": [0.0] * 3}
    return s


def light_linked(linked=True):
    s = room("red")
    if linked:
        s.meshes[2]["light_set"] = 1
        s.meshes[3]["light_set"] = 2
        s.lights[0]["receivers"] = [0, 1]  # the lamp: floor, wall, ball A
        s.meshes[4]["receivers"] = [2]     # the quad: ball B alone
    return s


def shadow_linked(linked=True):
    s = room("glass", slab=True)
    if linked:
        s.meshes[3]["shadow_set"] = 1
        s.lights[0]["blockers"] = [1]      # the lamp: shadows of the glass ball alone
        s.meshes[4]["blockers"] = [1]      # the quad: the same
    return s


def no_shadow(linked=True):
    """The shadow-linking room with the lamp's Cast Shadow off instead (the quad casts its
    shadows): pt's two weights, next-event estimation unoccluded (bidir_linking.h)."""
    s = room("glass", slab=True)
    if linked:
        s.lights[0]["cast_shadow"] = False
    return s


def render(scene, integrator, seed, spp=SPP):
    s = lantern.Session(scene, integrator=integrator, seed=seed, backend="cpu", max_depth=4,
                        spp_per_iteration=spp, threads=1)
    s.step()
    return np.asarray(s.image(), np.float64), s.warnings


def renders(build, integrator, seed0, linked=True):
    out, warnings = [], []
    for k in range(K):
        img, warnings = render(build(linked), integrator, seed0 + k)
        out.append(img)
    return out, warnings


@pytest.fixture(scope="module")
def pt_refs(core):
    return {b.__name__: renders(b, "pt", 1000)[0] for b in (light_linked, shadow_linked,
                                                             no_shadow)}


@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis", "lt"])
def test_light_linking_matches_pt(pt_refs, integrator):
    imgs, warnings = renders(light_linked, integrator, 2000)
    assert not warnings, warnings  # rendered by the integrator itself
    lt = integrator == "lt"  # (lt's noise here: it resolves 1.6 %, the others 0.9 %)
    metrics.assert_agreement(f"light linking, {integrator} vs pt", imgs,
                             pt_refs["light_linked"], block=4, image_bias=0.02 if lt else 0.01,
                             block_bias=0.1 if lt else 0.05)
    # the control: linking ignored (the scene without it) is seen
    free, _ = renders(light_linked, integrator, 3000, linked=False)
    assert not metrics.compare_renders(free, pt_refs["light_linked"], block=4).passed


@pytest.mark.parametrize("build", [shadow_linked, no_shadow], ids=["linked", "no_shadow"])
@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_shadow_linking_matches_pt(pt_refs, integrator, build):
    imgs, warnings = renders(build, integrator, 2000)
    assert not warnings, warnings
    metrics.assert_agreement(f"{build.__name__}, {integrator} vs pt", imgs,
                             pt_refs[build.__name__], block=4)
    free, _ = renders(build, integrator, 3000, linked=False)
    assert not metrics.compare_renders(free, pt_refs[build.__name__], block=4).passed

