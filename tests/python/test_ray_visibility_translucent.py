"""Ray visibility by kind at a Translucent surface (D57, docs/difftest.md), in every integrator:
a Translucent card between the camera and a lamp (or an emissive quad), a black world, so the
camera sees only light that crossed the card.

Cycles labels a diffuse transmission DIFFUSE | TRANSMIT. A lamp's exclusion reads those path
kinds (light/common.h is_light_shader_visible_to_path; next-event estimation excludes the
Translucent closure as a diffuse one): a lamp hidden from Diffuse rays, or from Transmission,
lights no Translucent surface, one hidden from Glossy alone lights it as if seen by all. An
object's visibility drops the diffuse for a transmission (path_state_ray_visibility): an
emissive mesh hidden from Diffuse is still seen through the card, hidden from Transmission it
is not. Lantern: pt_path_kind / pt_object_kind (integrator/pt_ray_visibility.h).

Exact where the answer is black (every pixel 0: nothing else lights the card); statistical
(compare_renders against pt's image of the scene with every kind seen) where it is lit. The
controls: the scene with every kind seen is not black. A rule broken on purpose, measured once
(docs/lvc_notes.md): a Translucent scattering of kind transmission alone for lamps too (the
rule before D57) lights the diffuse-hidden card in every integrator."""
import numpy as np
import pytest

import lantern
from lantern import metrics

pytestmark = pytest.mark.usefixtures("core")

K, SPP = 16, 8
SPP_LIT = 64  # the lit scenes' comparisons (a 1 % image bias must show: tests/README.md)
INTEGRATORS = ["pt", "bdpt", "lvc", "cis", "lt"]
QUAD = np.array([[0, 1, 2], [0, 2, 3]], np.uint32)


def card(lamp_off=(), emitter_off=None):
    """The card (y = 0, facing the camera at y = -3) and, behind it, a 1.2 m area lamp facing
    it with kinds `lamp_off` hidden; or, with `emitter_off` (a tuple of kinds), an emissive quad
    hidden from the camera and from those kinds instead of the lamp."""
    s = lantern.Scene()
    s.film.update(width=16, height=16)
    s.look_at((0.0, -3.0, 0.5), (0.0, 0.0, 0.5), fov=45.0)
    m = s.add_material("card", type="translucent", base_color=(0.8, 0.8, 0.8))
    v = np.array([[-1, 0, -0.5], [1, 0, -0.5], [1, 0, 1.5], [-1, 0, 1.5]], np.float32)
    s.add_mesh(v, QUAD, material=m, name="card")
    if emitter_off is not None:
        e = s.add_material("emit", type="diffuse", base_color=(0, 0, 0), emission=(4.0,) * 3)
        v = np.array([[-0.6, 1, 0], [0.6, 1, 0], [0.6, 1, 1], [-0.6, 1, 1]], np.float32)
        s.add_mesh(v, QUAD, material=e, name="emitter", visible_camera=False,
                   **{f"visible_{k}": False for k in emitter_off})
    else:
        to_world = [[-1, 0, 0, 0], [0, 0, 1, 1.0], [0, 1, 0, 0.5], [0, 0, 0, 1]]  # faces -y
        s.add_light("area", to_world=to_world, shape="square", size=[1.2, 1.2],
                    power=[60.0] * 3, name="lamp")
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


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("build", [
    lambda: card(lamp_off=("diffuse",)), lambda: card(lamp_off=("transmission",)),
    lambda: card(emitter_off=("transmission",))],
    ids=["lamp_no_diffuse", "lamp_no_transmission", "emitter_no_transmission"])
def test_hidden_from_the_translucent_kind_is_black(integrator, build):
    img = render(build(), integrator, 1)
    assert not img.any(), f"{integrator}: lit through the card (mean {img.mean():.4g})"


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_control_every_kind_seen_is_lit(integrator):
    assert render(card(), integrator, 1).mean() > 0.5
    assert render(card(emitter_off=()), integrator, 1).mean() > 0.1


@pytest.fixture(scope="module")
def pt_seen():
    return {e: [render(card(emitter_off=() if e else None), "pt", 1000 + k, SPP_LIT) for k in range(K)]
            for e in (False, True)}


@pytest.mark.parametrize("integrator", ["pt", "cis"])
@pytest.mark.parametrize("build,emitter", [
    (lambda: card(lamp_off=("glossy",)), False), (lambda: card(emitter_off=("diffuse",)), True)],
    ids=["lamp_no_glossy", "emitter_no_diffuse"])
def test_other_kinds_light_the_card_as_if_seen(pt_seen, integrator, build, emitter):
    imgs = [render(build(), integrator, 2000 + k, SPP_LIT) for k in range(K)]
    metrics.assert_agreement(f"{integrator} vs pt (every kind seen)", imgs, pt_seen[emitter],
                             block=4)
