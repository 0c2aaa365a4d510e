"""Object ray visibility in fog (pt: integrator/pt_ray_visibility.h, kRayKindVolume): a ray a
medium vertex scatters is of the Volume Scatter kind alone, as in Cycles since Blender 4.4
(its "volume scatter counts as diffuse" rule dropped: Cycles d1f1923, Fix #135145; difftest
D54, a floor hidden from Volume Scatter rays only, was +3..+6 % brighter than Cycles where pt
kept the diffuse bit).

World fog (scattering only), the camera looking up into it, and a floor below that neither the
camera nor a shadow ray sees (visible_camera and cast_shadow off): only medium vertices' rays
(the phase-sampled ray and next-event estimation) can meet it. An emissive floor hidden from
Volume Scatter rays alone lights none of the fog (exactly black: both strategies skip it); the
control, hidden from Diffuse, Glossy and Transmission rays instead, lights it. A black floor
under fog lit by a point lamp, hidden from Volume Scatter rays alone, is passed by every phase
ray (the fog beneath scatters on) and the image agrees with the scene without the floor within
the noise; the control, seen by them, ends those paths (the comparison fails)."""
import numpy as np

import lantern
from lantern import metrics

SEEDS = range(1, 17)
SURFACE_KINDS = ("diffuse", "glossy", "transmission")


def fog_scene(floor=None, emission=0.0, lamp=True, size=16):
    """World fog seen from z = 0.15 upwards, lit by a point lamp at z = 0.4 (with `lamp`);
    floor: None (no floor) or the floor's ray visibility (a dict) at z = 0, black or emitting
    `emission`."""
    scene = lantern.Scene()
    scene.film.update(width=size, height=size)
    scene.look_at((0.0, 0.0, 0.15), (0.0, 3.0, 3.15), fov=40.0)  # every camera ray rises
    if floor is not None:
        m = scene.add_material("floor", type="diffuse", base_color=(0.0, 0.0, 0.0),
                               emission=(emission,) * 3)
        quad = np.array([[-50, -50, 0], [50, -50, 0], [50, 50, 0], [-50, 50, 0]], np.float32)
        scene.add_mesh(quad, np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=m,
                       name="floor", visible_camera=False, cast_shadow=False, **floor)
    if lamp:
        scene.add_light("point", position=[0.0, 1.5, 0.4], radius=0.3, power=[20.0] * 3,
                        name="lamp")
    scene.world = {"color": [0.0] * 3, "volume": {"sigma_s": [2.5] * 3, "sigma_a": [0.0] * 3}}
    return scene


def renders(scene, spp=16):
    out = []
    for seed in SEEDS:
        s = lantern.Session(scene, integrator="pt", seed=seed, backend="cpu", max_depth=6,
                            spp_per_iteration=spp, threads=1)
        s.step()
        out.append(np.asarray(s.image(), np.float64)[..., :3])
    return out


def hidden(*kinds):
    return {f"visible_{k}": False for k in kinds}


def test_emitter_hidden_from_volume_scatter_lights_no_fog(core):
    dark = renders(fog_scene(hidden("volume_scatter"), emission=1.0, lamp=False), spp=4)[:2]
    assert max(x.max() for x in dark) == 0.0
    lit = renders(fog_scene(hidden(*SURFACE_KINDS), emission=1.0, lamp=False), spp=4)[:2]
    assert min(x.mean() for x in lit) > 1e-2


def test_floor_hidden_from_volume_scatter_is_passed_in_fog(core):
    ref = renders(fog_scene())
    # multiple scattering near a lamp: noisy; the comparison sees a 10 % image bias (the
    # control's effect is -8 %, caught by the image mean and its worst block)
    metrics.assert_agreement("floor hidden from Volume Scatter vs no floor",
                             renders(fog_scene(hidden("volume_scatter"))), ref,
                             image_bias=0.1, block_bias=0.2)
    # the control: seen by volume-scatter rays (hidden from the surface kinds), it darkens
    seen = renders(fog_scene(hidden(*SURFACE_KINDS)))
    assert not metrics.compare_renders(seen, ref).passed
    assert np.mean(seen) < 0.96 * np.mean(ref)
