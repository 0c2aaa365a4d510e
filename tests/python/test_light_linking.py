"""Light linking (Cycles' Receiver collection; pt: integrator/pt_light_linking.h): a light lights
only the meshes of the receiver sets in its mask, through both next-event estimation and
emission that bounce rays find; light it scattered off a lit surface still reaches the rest.

With max_depth 2 (direct light only): a ball outside the light's sets is exactly black, the
ball inside renders the same bits as with no linking at all (the picks are the same); a white
floor outside an emissive quad's sets is exactly black, though BSDF sampling finds the quad
(the emission is dropped for the floor's set); the controls, unlinked, are lit."""
import numpy as np
import pytest

import lantern
from lantern import scenes


def render(scene, seed=1, spp=8, integrator="pt", max_depth=2):
    s = lantern.Session(scene, integrator=integrator, seed=seed, backend="cpu",
                        max_depth=max_depth, spp_per_iteration=spp, threads=1)
    s.step()
    return np.asarray(s.image(), np.float64), s.warnings


def two_balls(linked, size=24):
    """Ball A (left, set 1 when linked) and ball B (right, set 0) under a point light and an
    area light that light everything; linked: the point light lights set 1 only."""
    scene = lantern.Scene()
    scene.film.update(width=size, height=size)
    scene.look_at((0.0, -4.0, 0.0), (0.0, 0.0, 0.0), fov=50.0)
    m = scene.add_material("white", type="diffuse", base_color=(0.8, 0.8, 0.8))
    for name, x in (("A", -0.9), ("B", 0.9)):
        pos, idx = scenes.icosphere(2, 0.7, center=(x, 0.0, 0.0))
        scene.add_mesh(pos, idx, material=m, name=name)
    scene.add_light("point", position=[0.0, -2.0, 2.0], power=[300.0] * 3)
    if linked:
        scene.meshes[0]["light_set"] = 1
        scene.lights[0]["receivers"] = [1]
    scene.world = {"color": [0.0] * 3}
    return scene


LEFT, RIGHT = (slice(9, 15), slice(3, 9)), (slice(9, 15), slice(15, 21))


def test_point_light_lights_its_receivers_only(core):
    for seed in (1, 2):
        linked, _ = render(two_balls(True), seed)
        free, _ = render(two_balls(False), seed)
        np.testing.assert_array_equal(linked[:, :12], free[:, :12])  # ball A: the same bits
        assert linked[RIGHT].max() == 0.0                              # ball B: unlit
        assert free[RIGHT].min() > 0.01                                # the control: lit
    # bounces off lit A still reach B (linking is about the light's own illumination)
    bounced, _ = render(two_balls(True), max_depth=4, spp=32)
    assert bounced[RIGHT].mean() > 0.0


def floor_and_quad(linked, size=16):
    """A white floor lit only by an emissive quad above it (unseen by the camera); linked: the
    quad lights set 1, where nothing is."""
    scene = lantern.Scene()
    scene.film.update(width=size, height=size)
    scene.look_at((0.0, -2.0, 1.5), (0.0, 0.0, 0.0), fov=40.0)
    m = scene.add_material("floor", type="diffuse", base_color=(1.0, 1.0, 1.0))
    e = scene.add_material("emit", type="diffuse", base_color=(0.0, 0.0, 0.0),
                           emission=(2.0, 2.0, 2.0))
    quad = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
    tris = np.array([[0, 1, 2], [0, 2, 3]], np.uint32)
    scene.add_mesh(quad * np.float32(4.0), tris, material=m, name="floor")
    scene.add_mesh(quad * np.float32(0.5) + np.float32([0, 0, 1]), tris[:, ::-1].copy(),
                   material=e, name="emitter", visible_camera=False)
    if linked:
        scene.meshes[1]["receivers"] = [1]
    scene.world = {"color": [0.0] * 3}
    return scene


def test_emissive_mesh_lights_its_receivers_only(core):
    dark, _ = render(floor_and_quad(True), spp=16)
    assert dark.max() == 0.0
    lit, _ = render(floor_and_quad(False), spp=16)
    assert lit.mean() > 0.01


@pytest.mark.parametrize("integrator", ["bdpt", "cis", "lt"])
def test_bidirectional_render_light_linking(core, integrator):
    """The bidirectional integrators render light linking themselves (bidir_linking.h; against
    pt: test_linking_bidir.py): ball B, outside the point light's sets, is exactly black there
    too. In a scene with a volume they render it themselves too (bidir_linking_medium.h,
    lt_linking.h; against pt: test_linking_media.py, test_lt_linking.py)."""
    img, warnings = render(two_balls(True), integrator=integrator)
    assert not warnings, warnings
    assert img[RIGHT].max() == 0.0 and img[LEFT].mean() > 0.01
    fog = two_balls(True)
    fog.world["volume"] = {"sigma_s": [0.05] * 3, "sigma_a": [0.0] * 3}
    img, warnings = render(fog, integrator=integrator)
    assert not warnings, warnings
    assert np.isfinite(img).all() and img[LEFT].mean() > 0.01


def test_schema(core, tmp_path):
    scene = two_balls(True)
    path = tmp_path / "l.lantern"
    scene.save(path)
    back = lantern.load_scene(path)
    assert back.meshes[0]["light_set"] == 1 and back.lights[0]["receivers"] == 2
    with pytest.raises(ValueError):
        bad = two_balls(False)
        bad.meshes[0]["light_set"] = 64
        bad.save(tmp_path / "bad.lantern")
        lantern.load_scene(tmp_path / "bad.lantern")


def shadow_scene(linked, size=16):
    """A white floor under a point light, a ball between them casting its shadow onto the
    middle of the image; linked: the light's blockers are set 1, where the ball is not."""
    scene = lantern.Scene()
    scene.film.update(width=size, height=size)
    scene.look_at((0.0, 0.0, 4.0), (0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0), fov=30.0)
    m = scene.add_material("white", type="diffuse", base_color=(0.8, 0.8, 0.8))
    quad = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32) * 4
    scene.add_mesh(quad, np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=m, name="floor")
    pos, idx = scenes.icosphere(2, 0.3, center=(0.0, 0.0, 1.0))
    scene.add_mesh(pos, idx, material=m, name="ball", visible_camera=False)
    scene.add_light("point", position=[0.0, 0.0, 3.0], power=[100.0] * 3)
    if linked:
        scene.lights[0]["blockers"] = [1]
    scene.world = {"color": [0.0] * 3}
    return scene


def no_ball(size=16):
    scene = shadow_scene(False, size)
    scene.meshes.pop(1)
    return scene


MID = (slice(6, 10), slice(6, 10))


def test_shadow_linked_light_is_not_shadowed_by_others(core):
    """Direct light only: the ball casts the light no shadow, so the floor renders as without
    the ball (bit for bit: next-event estimation of a point light, the only strategy); the
    control, unlinked, has the shadow."""
    for seed in (1, 2):
        linked, _ = render(shadow_scene(True), seed)
        free, _ = render(no_ball(), seed)
        np.testing.assert_array_equal(linked, free)
    shadowed, _ = render(shadow_scene(False), 1)
    assert shadowed[MID].max() == 0.0 and free[MID].min() > 0.01
