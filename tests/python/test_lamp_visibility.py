"""A lamp's own ray visibility (a light object's Ray Visibility: Diffuse, Glossy, Transmission,
Volume Scatter; pt: integrator/pt_ray_visibility.h): a lamp hidden from a kind of scattering
lights nothing through it, neither by next-event estimation nor by a bounce ray that finds it,
so the two strategies' MIS weights still cover the same integral.

A floor under an area lamp facing down, lit by nothing else: a diffuse floor with the lamp
hidden from diffuse rays is black (exactly: both strategies skip it); a rough metal floor with
the lamp hidden from glossy rays too; the controls, the lamp hidden from the other kinds, light
each floor. A lamp hidden from one kind renders as its scene without that lamp wherever only
that kind sees it (the diffuse floor with a second lamp: pt agrees with the scene without the
hidden one within the noise, and differs with it visible). The bidirectional integrators render
it themselves (integrator/bidir_ray_visibility.h: no light path leaves the hidden lamp, and
their s = 1 and s = 0 follow pt's kind rules): the floors are black there too, exactly, and lit
in the controls (against pt statistically: tests/python/test_ray_visibility_bidir.py)."""
import numpy as np
import pytest

import lantern
from lantern import metrics

FLOOR = {"diffuse": dict(type="diffuse", base_color=(1.0, 1.0, 1.0)),
         "metal": dict(type="conductor", base_color=(1.0, 1.0, 1.0), roughness=0.3)}
LAMP = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 1.0], [0, 0, 0, 1]]  # at z = 1, emitting along -Z


def hidden(*kinds):
    return {f"visible_{k}": False for k in kinds}


def floor_scene(floor, lamp=None, second=False, size=16):
    """A floor (z = 0) of `floor` under an area lamp at z = 1 facing down (its ray visibility
    `lamp`, a dict; None: no lamp), and with `second` a point lamp beside it."""
    scene = lantern.Scene()
    scene.film.update(width=size, height=size)
    scene.look_at((0.0, -2.0, 1.5), (0.0, 0.0, 0.0), fov=40.0)
    m = scene.add_material("floor", **FLOOR[floor])
    quad = np.array([[-4, -4, 0], [4, -4, 0], [4, 4, 0], [-4, 4, 0]], np.float32)
    scene.add_mesh(quad, np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=m, name="floor")
    if lamp is not None:
        scene.add_light("area", to_world=LAMP, shape="rectangle", size=[1.0, 1.0],
                        power=[20.0] * 3, name="lamp", **lamp)
    if second:
        scene.add_light("point", position=[1.0, 0.5, 0.8], radius=0.05, power=[10.0] * 3,
                        name="second")
    scene.world = {"color": [0.0] * 3}
    return scene


def render(scene, seed=1, spp=16, integrator="pt"):
    s = lantern.Session(scene, integrator=integrator, seed=seed, backend="cpu", max_depth=6,
                        spp_per_iteration=spp, threads=1)
    s.step()
    return np.asarray(s.image(), np.float64), s.warnings


@pytest.mark.parametrize("floor,kind,others", [
    ("diffuse", "diffuse", ("glossy", "transmission", "volume_scatter")),
    ("metal", "glossy", ("diffuse", "transmission", "volume_scatter")),
])
def test_hidden_lamp_lights_nothing_of_its_kind(core, floor, kind, others):
    dark, warnings = render(floor_scene(floor, hidden(kind)))
    assert not warnings, warnings
    assert dark.max() == 0.0  # neither next-event estimation nor a bounce finds it
    lit, _ = render(floor_scene(floor, hidden(*others)))
    assert lit.mean() > 0.01  # the control: seen by the floor's kind, it lights the floor


def test_hidden_lamp_is_the_scene_without_it(core):
    k, spp = 16, 128
    def stack(scene):
        return np.stack([render(scene, seed=1 + s, spp=spp)[0] for s in range(k)])
    without = stack(floor_scene("diffuse", None, second=True))
    through = stack(floor_scene("diffuse", hidden("diffuse"), second=True))
    metrics.assert_agreement("lamp hidden from diffuse vs no lamp", through, without, block=4,
                             se_floor=1e-6)
    seen = stack(floor_scene("diffuse", {}, second=True))
    res = metrics.compare_renders(seen, without, block=4, se_floor=1e-6, name="lamp seen")
    assert not res.passed, res


@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis", "lt"])
@pytest.mark.parametrize("floor,kind,others", [
    ("diffuse", "diffuse", ("glossy", "transmission", "volume_scatter")),
    ("metal", "glossy", ("diffuse", "transmission", "volume_scatter")),
])
def test_bidirectional_hidden_lamp_lights_nothing(core, integrator, floor, kind, others):
    dark, warnings = render(floor_scene(floor, hidden(kind)), spp=4, integrator=integrator)
    assert not warnings, warnings  # rendered by the integrator itself
    assert dark.max() == 0.0  # no technique finds it
    lit, _ = render(floor_scene(floor, hidden(*others)), spp=4, integrator=integrator)
    assert lit.mean() > 0.01  # the control


def test_schema_round_trip(core, tmp_path):
    scene = floor_scene("diffuse", hidden("diffuse", "volume_scatter"))
    assert scene.lights[0]["visible_diffuse"] is False
    path = tmp_path / "l.lantern"
    scene.save(path)
    back = lantern.load_scene(path)
    assert back.lights[0]["visible_diffuse"] is False
    assert back.lights[0]["visible_volume_scatter"] is False
    assert "visible_glossy" not in back.lights[0]


def fog_scene(lamp, size=16):
    """World fog (scattering only) and no surface, lit only by the area lamp (its ray
    visibility `lamp`); the camera sees the fog, not the lamp."""
    scene = floor_scene("diffuse", lamp, size=size)
    scene.meshes.clear()
    scene.world = {"color": [0.0] * 3, "volume": {"sigma_s": [0.5] * 3, "sigma_a": [0.0] * 3}}
    return scene


def test_volume_scattering_reads_its_own_kind(core):
    """Cycles' volume-scatter rays carry no diffuse flag: a lamp hidden from diffuse rays still
    lights fog; hidden from volume scatter, it lights none of it (both strategies)."""
    lit, _ = render(fog_scene(hidden("diffuse")))
    assert lit.mean() > 1e-3
    dark, _ = render(fog_scene(hidden("volume_scatter")))
    assert dark.max() == 0.0
