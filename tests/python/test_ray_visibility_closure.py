"""Ray visibility by kind per closure, as Cycles (branch closure; docs/lvc_notes.md "Ray
visibility by kind"): a Mix Shader's bounce ray takes the kind of the leaf it sampled (Cycles'
path_state_next reads the sampled closure's label), and next-event estimation leaves out the
leaves whose closure class cannot see the lamp, its MIS weight keeping the whole mixture's pdf
(surface_shader.h _surface_shader_exclude, surface_shader_bsdf_eval).

The scene: a floor of Mix(Diffuse, sharp mirror), an area lamp above it whose mirror image the
camera sees, a black world. With the lamp (or an emissive quad in its place) hidden from
Glossy, the mirror leaf never sees it and the diffuse leaf sees it by both techniques: the
mirror's pdf is zero off its delta direction, so the mixture's pdf there is the diffuse leaf's
times its pick probability, and the weights of the two techniques still sum to one. The image
is then exactly (in expectation) that of a Lambert floor of albedo (1 - fac) x the diffuse
leaf's: rendered independently (a plain diffuse material, its own sampler), by pt, and compared
with compare_renders (statistical, K seeds). Controls: the same Mix with every kind seen (the
lamp's mirror image adds light) must fail that comparison. Broken on purpose (measured once,
docs): the Mix of one kind diffuse | glossy (the rule before: a lamp hidden from either hides
it from the whole Mix) renders the floor black; the objects reading the Mix's kind unmasked let
the mirror see the quad.

lt keeps one kind per material (lt_ray_visibility.h): a scene with a Mix and hidden kinds goes
to pt with a warning naming it (allocation.cpp bidir_visibility_reason)."""
import numpy as np
import pytest

import lantern
from lantern import metrics

pytestmark = pytest.mark.usefixtures("core")

K, SPP = 12, 32
FAC = 0.4  # the mirror leaf's weight
QUAD = np.array([[0, 1, 2], [0, 2, 3]], np.uint32)


def floor_scene(mix=True, lamp_off=(), emitter_off=None, mirror_roughness=0.0):
    """The floor (z = 0) seen from (0, -3, 1.5), a 1 m lamp facing down at (0, 1, 1) with kinds
    `lamp_off` hidden; or, with `emitter_off`, an emissive quad there hidden from the camera and
    from those kinds. mix False: a Lambert floor of the Mix's diffuse share."""
    s = lantern.Scene()
    s.film.update(width=16, height=16)
    s.look_at((0.0, -3.0, 1.5), (0.0, 0.0, 0.0), fov=45.0)
    if mix:
        d = s.add_material("diffuse", type="diffuse", base_color=(0.8, 0.8, 0.8))
        g = s.add_material("mirror", type="conductor", base_color=(0.9, 0.9, 0.9),
                           roughness=mirror_roughness)
        m = s.add_material("floor", type="mix", mix=[[d, 1.0 - FAC], [g, FAC]])
    else:
        m = s.add_material("floor", type="diffuse", base_color=(0.8 * (1.0 - FAC),) * 3)
    v = np.array([[-3, -3, 0], [3, -3, 0], [3, 3, 0], [-3, 3, 0]], np.float32)
    s.add_mesh(v, QUAD, material=m, name="floor")
    if emitter_off is not None:
        e = s.add_material("emit", type="diffuse", base_color=(0, 0, 0), emission=(5.0,) * 3)
        v = np.array([[-0.5, 0.5, 1], [-0.5, 1.5, 1], [0.5, 1.5, 1], [0.5, 0.5, 1]], np.float32)
        s.add_mesh(v, QUAD, material=e, name="emitter", visible_camera=False,
                   **{f"visible_{k}": False for k in emitter_off})
    else:
        s.add_light("area", to_world=[[1, 0, 0, 0], [0, 1, 0, 1.0], [0, 0, 1, 1.0], [0, 0, 0, 1]],
                    shape="square", size=[1.0, 1.0], power=[30.0] * 3, name="lamp")
        for k in lamp_off:
            s.lights[0][f"visible_{k}"] = False
    s.world = {"color": [0.0] * 3}
    return s


def render(scene, integrator, seed, spp=SPP):
    s = lantern.Session(scene, integrator=integrator, seed=seed, backend="cpu", max_depth=4,
                        spp_per_iteration=spp, threads=1)
    s.step()
    assert not s.warnings, s.warnings  # rendered by the integrator itself
    return np.asarray(s.image(), np.float64)


@pytest.fixture(scope="module")
def lambert():
    """pt's images of the Lambert floor (the Mix's diffuse share), lamp and quad."""
    return {e: [render(floor_scene(False, emitter_off=() if e else None), "pt", 1000 + k)
                for k in range(K)] for e in (False, True)}


@pytest.mark.parametrize("integrator", ["pt", "bdpt", "lvc", "cis"])
@pytest.mark.parametrize("emitter", [False, True], ids=["lamp", "emitter"])
def test_mix_hidden_from_glossy_is_its_diffuse_leaf(lambert, integrator, emitter):
    build = (lambda: floor_scene(emitter_off=("glossy",))) if emitter else (
        lambda: floor_scene(lamp_off=("glossy",)))
    imgs = [render(build(), integrator, 2000 + k) for k in range(K)]
    metrics.assert_agreement(f"{integrator}: Mix, {'quad' if emitter else 'lamp'} hidden from "
                             "Glossy vs a Lambert of its diffuse share", imgs, lambert[emitter],
                             block=4)


@pytest.mark.parametrize("emitter", [False, True], ids=["lamp", "emitter"])
def test_control_every_kind_seen_differs(lambert, emitter):
    """The Mix with every kind seen: its mirror shows the lamp (the quad), not the Lambert's."""
    imgs = [render(floor_scene(emitter_off=() if emitter else None), "pt", 2000 + k)
            for k in range(K)]
    res = metrics.compare_renders(imgs, lambert[emitter], 4)
    print(res)
    assert not res.passed


@pytest.mark.parametrize("integrator", ["pt", "cis"])
def test_rough_mix_leaf_shares_sum_to_the_seen_lamp(integrator):
    """A rough metal leaf: hidden from Glossy, the lamp lights the diffuse leaf (next event: its
    value, the whole mixture's pdf in the weight; bounce hits: the rays the diffuse leaf drew);
    hidden from Diffuse, the metal leaf likewise. Cycles' two images are not the leaves'
    images (a bounce hit carries the whole mixture's value), but their sum (independent seeds)
    is the lamp seen by every kind, exactly when each technique's weight keeps the whole
    mixture's pdf."""
    def build(off=()):
        return floor_scene(lamp_off=off, mirror_roughness=0.3)
    seen = [render(build(), "pt", 7000 + k) for k in range(K)]
    no_glossy = [render(build(("glossy",)), integrator, 8000 + k) for k in range(K)]
    no_diffuse = [render(build(("diffuse",)), integrator, 9000 + k) for k in range(K)]
    for part in (no_glossy, no_diffuse):
        assert 0.02 * np.mean(seen) < np.mean(part) < 0.98 * np.mean(seen)
    metrics.assert_agreement(f"{integrator}: rough Mix, lamp hidden from Glossy + from Diffuse "
                             "vs seen (pt)", [a + b for a, b in zip(no_glossy, no_diffuse)],
                             seen, block=4)


def test_lt_hands_the_mix_over():
    s = lantern.Session(floor_scene(lamp_off=("glossy",)), integrator="lt", seed=1,
                        backend="cpu", max_depth=4, spp_per_iteration=1, threads=1)
    s.step()
    assert any("Mix Shader" in w and "'floor'" in w for w in s.warnings), s.warnings
