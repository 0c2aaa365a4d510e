"""Shadow linking on a lamp without Cast Shadow (difftest4's 9008: an area lamp with Cast Shadow
off and a Blocker collection read +4-7 % against Cycles, pt and bdpt alike). Cycles traces no
shadow ray for such a lamp, so its Blocker collection changes nothing: the image is the one
without it (next-event estimation unoccluded and BSDF-sampled hits occluded, each with its MIS
weight: pt_lamp_unshadowed). Before the fix the lamp was also shadow-linked (next-event
estimation alone at weight 1, bounce hits 0), so a ball's shadow read fully lit.

The reference is the same scene without the blocker set: the same bits. The control: the
shadow-linked branch's image (the same lamp casting shadows, its blockers excluding the ball)
differs from it where the ball's shadow is."""
import numpy as np

import lantern
from lantern import scenes


def _render(scene, seed):
    s = lantern.Session(scene, integrator="pt", seed=seed, backend="cpu", max_depth=3,
                        spp_per_iteration=16, threads=1)
    s.step()
    return np.asarray(s.image(), np.float64)


def _scene(blockers, cast_shadow=False, size=16):
    """A white floor under a square area lamp (Cast Shadow off), a ball between them."""
    scene = lantern.Scene()
    scene.film.update(width=size, height=size)
    scene.look_at((0.0, 0.0, 4.0), (0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0), fov=30.0)
    m = scene.add_material("white", type="diffuse", base_color=(0.8, 0.8, 0.8))
    quad = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32) * 4
    scene.add_mesh(quad, np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=m, name="floor")
    pos, idx = scenes.icosphere(2, 0.8, center=(0.0, 0.0, 1.2))
    scene.add_mesh(pos, idx, material=m, name="ball", visible_camera=False)
    to_world = np.eye(4)
    to_world[2, 3] = 2.5
    scene.add_light("area", to_world=to_world.tolist(), shape="square", size=[3.0, 3.0],
                    power=[100.0] * 3, cast_shadow=cast_shadow, visible_camera=False)
    if blockers:
        scene.meshes[0]["shadow_set"] = 1      # the floor: set 1; the ball: set 0
        scene.lights[0]["blockers"] = [1]      # only the floor would shadow it
    scene.world = {"color": [0.0] * 3}
    return scene


MID = (slice(6, 10), slice(6, 10))


def test_blocker_set_of_a_lamp_without_shadow_changes_nothing(core):
    for seed in (1, 2):
        np.testing.assert_array_equal(_render(_scene(True), seed), _render(_scene(False), seed))
    # the control: a shadow-linked lamp that casts shadows (next-event estimation alone, the
    # ball passed) reads brighter in the ball's shadow than the Cast Shadow off image, whose
    # bounce hits there are blocked
    free = np.mean([_render(_scene(False), s)[MID].mean() for s in (1, 2, 3, 4)])
    linked = np.mean([_render(_scene(True, cast_shadow=True), s)[MID].mean() for s in (1, 2, 3, 4)])
    assert linked > free * 1.02, (linked, free)
