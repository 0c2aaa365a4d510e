"""MIS for a shadow-linked light in pt (pt_light_linking.h pt_linked_mis, issue 32 item 4): a
direction from a vertex whose segment to the light meets no surface takes the usual power-
heuristic weights in next-event estimation and in the bounce ray that finds the light; one that
meets only surfaces outside the blocker sets next-event estimation alone (weight 1); a blocker
neither. Before, next-event estimation alone everywhere: unbiased but heavy-tailed on a sharp
Glossy (bench/results/2026-12-06-nee10022, -shmis).

- free segments: test_linking_shadow_redundant.py's Glossy floor under an ellipse lamp, the lamp
  shadow-linked by a ball behind it (set 1, outside the blockers; no floor-to-lamp segment meets
  it) renders the unlinked scene's image, the same random numbers, pixel for pixel up to
  rounding (rtol 1e-4; the old rule's image differs by its noise: the control, another seed of
  the same estimator, differs by > 10 % somewhere);
- a non-blocker between: a card of set 1 over part of a Glossy floor (Roughness 0.25), under the
  lamp, lit and shadowing nothing for the lamp; pt against bdpt (its own next-event and
  connection weights, bidir_linking.h) at 8 x 128 spp (measured at 8 x 512: -0.22 % of the image,
  allowed 0.98 %); the control: the card a blocker, its shadow (-11 % of the image), is seen."""
import numpy as np

import lantern
from lantern import metrics, scenes

from test_linking_shadow_redundant import glossy_under_lamp


def render(scene, seed, integrator="pt", spp=16, depth=2):
    s = lantern.Session(scene, integrator=integrator, seed=seed, backend="cpu", max_depth=depth,
                        spp_per_iteration=spp, threads=1)
    s.step()
    return np.asarray(s.image(), np.float64)[..., :3]


def test_free_segments_take_mis(core):
    """The ball behind the lamp keeps it shadow-linked; every floor-to-lamp segment is free of
    surfaces: the unlinked render's pixels (up to rounding: the weight applied after the shadow
    ray)."""
    for seed in (1, 2):
        linked = render(glossy_under_lamp(blockers=[0], ball=True), seed)
        free = render(glossy_under_lamp(ball=True), seed)
        np.testing.assert_allclose(linked, free, rtol=1e-4, atol=1e-7)
    # the control: another seed of the same estimator is far outside that tolerance
    other = render(glossy_under_lamp(ball=True), 3)
    assert np.abs(other - free).max() > 0.1 * free.max()


def card_scene(linked=True, size=24):
    """A Diffuse floor, a lamp 2 m up, a 1 m card 1 m up over the floor's left half: set 1,
    outside the lamp's blockers (linked) or a blocker (linked False: the lamp unlinked)."""
    sc = lantern.Scene()
    sc.film.update(width=size, height=size)
    sc.look_at((0.0, -3.0, 2.5), (0.0, 0.0, 0.3), up=(0.0, 0.0, 1.0), fov=50.0)
    floor = sc.add_material("floor", type="conductor", base_color=(0.8, 0.8, 0.8),
                            roughness=0.25)
    card = sc.add_material("card", type="diffuse", base_color=(0.5, 0.5, 0.5))
    sc.add_mesh(*scenes._quad((-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0)), material=floor,
                name="floor")
    sc.add_mesh(*scenes._quad((-1.2, -0.5, 1.0), (-0.2, -0.5, 1.0), (-0.2, 0.5, 1.0),
                              (-1.2, 0.5, 1.0)), material=card, name="card")
    sc.meshes[-1]["shadow_set"] = 1
    sc.add_light("area", to_world=scenes._aim((-0.3, 0.0, 2.0), (0.0, 0.0, -1.0)),
                 shape="ellipse", size=[0.8, 0.8], power=[80.0] * 3)
    if linked:
        sc.lights[0]["blockers"] = [0]
    sc.world = {"color": [0.0] * 3}
    return sc


def test_non_blocker_between_agrees_with_bdpt(core):
    K, spp = 8, 128  # (about 2 s of CPU)
    pt = [render(card_scene(), 100 + k, spp=spp, depth=3) for k in range(K)]
    bd = [render(card_scene(), 200 + k, "bdpt", spp=spp, depth=3) for k in range(K)]
    metrics.assert_agreement("shadow-linked lamp past a non-blocker, pt vs bdpt", pt, bd,
                             block=4, image_bias=0.03, block_bias=0.1)
    # the control: the card a blocker (the lamp unlinked), its shadow (-11 % of the image)
    shadowed = [render(card_scene(linked=False), 300 + k, spp=spp, depth=3) for k in range(K)]
    assert not metrics.compare_renders(shadowed, bd, block=4).passed
