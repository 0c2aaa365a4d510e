"""Object ray visibility (Cycles' Object > Visibility > Ray Visibility: Diffuse, Glossy,
Transmission; pt: integrator/pt_ray_visibility.h): a bounce ray of a kind passes through the
objects hidden from that kind, and next-event estimation finds no emission on them for it.

A ball under a constant world of 0.5 inside a black shell that the camera does not see and
that casts no shadow: where the shell is hidden from the ball's kind of scattering, every bounce
ray passes through it, so the image is the one without the shell, bit for bit (the pass adds a
segment but no random number); where it is not, the shell's black ends every bounce ray (the
negative control: the ball goes black). A white diffuse floor lit only by an emitter hidden
from diffuse rays is black through both strategies; the same emitter visible renders it lit."""
import numpy as np
import pytest

import lantern
from lantern import metrics, scenes

WORLD = 0.5
MATERIALS = {"diffuse": dict(type="diffuse", base_color=(1.0, 1.0, 1.0)),
             "metal": dict(type="conductor", base_color=(1.0, 1.0, 1.0), roughness=0.3),
             "glass": dict(type="dielectric", base_color=(1.0, 1.0, 1.0), roughness=0.0),
             "principled": dict(type="principled", base_color=(0.8, 0.8, 0.8), roughness=0.4)}


def ball_scene(kind, shell=None, size=16):
    """The ball of `kind`; shell: None (no shell) or the shell's ray visibility (a dict)."""
    scene = lantern.Scene()
    scene.film.update(width=size, height=size)
    scene.look_at((0.0, -3.0, 0.0), (0.0, 0.0, 0.0), fov=50.0)
    m = scene.add_material(kind, **MATERIALS[kind])
    pos, idx = scenes.icosphere(2, 0.9)
    scene.add_mesh(pos, idx, material=m, name="ball")
    if shell is not None:
        black = scene.add_material("black", type="diffuse", base_color=(0.0, 0.0, 0.0))
        pos, idx = scenes.icosphere(2, 6.0)  # around the camera too
        scene.add_mesh(pos, idx, material=black, name="shell", visible_camera=False,
                       cast_shadow=False, **shell)
    scene.world = {"color": [WORLD] * 3}
    return scene


def render(scene, seed=1, spp=8, integrator="pt"):
    s = lantern.Session(scene, integrator=integrator, seed=seed, backend="cpu", max_depth=8,
                        spp_per_iteration=spp, threads=1)
    s.step()
    return np.asarray(s.image(), np.float64), s.warnings


BALL = (slice(6, 10), slice(6, 10))  # the middle of the ball


def hidden(*kinds):
    return {f"visible_{k}": False for k in kinds}


@pytest.mark.parametrize("kind,hide,control", [
    ("diffuse", ("diffuse",), ("glossy", "transmission")),
    ("metal", ("glossy",), ("diffuse", "transmission")),
    ("glass", ("glossy", "transmission"), ("transmission",)),
    # Principled reflections are of both kinds (pt_scatter_kind): hidden only from both
    ("principled", ("diffuse", "glossy"), ("diffuse",)),
])
def test_hidden_shell_is_absent_for_its_kind(core, kind, hide, control):
    for seed in (1, 2):
        without, _ = render(ball_scene(kind), seed)
        through, _ = render(ball_scene(kind, hidden(*hide)), seed)
        np.testing.assert_array_equal(through, without)
    assert without[BALL].min() > 0.05
    dark, _ = render(ball_scene(kind, hidden(*control)), 1)
    if kind == "glass":  # light through it passes the shell, its reflection finds it black
        assert 0.0 < dark[BALL].mean() < 0.95 * without[BALL].mean()
        black, _ = render(ball_scene(kind, hidden("diffuse")), 1)
        assert black[BALL].max() == 0.0
    else:
        assert dark[BALL].max() == 0.0
    assert dark[0, 0] == pytest.approx([WORLD] * 3)  # the camera sees past the shell


def emitter_scene(emitter_visibility, floor="diffuse", size=16):
    """A white floor (z = 0) lit only by an emissive quad above it, facing down; the camera
    sees the floor, not the quad (visible_camera off)."""
    scene = lantern.Scene()
    scene.film.update(width=size, height=size)
    scene.look_at((0.0, -2.0, 1.5), (0.0, 0.0, 0.0), fov=40.0)
    m = scene.add_material("floor", **MATERIALS["metal" if floor == "metal" else "diffuse"])
    e = scene.add_material("emit", type="diffuse", base_color=(0.0, 0.0, 0.0),
                           emission=(2.0, 2.0, 2.0))
    quad = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
    tris = np.array([[0, 1, 2], [0, 2, 3]], np.uint32)
    scene.add_mesh(quad * np.float32(4.0), tris, material=m, name="floor")
    scene.add_mesh(quad * np.float32(0.5) + np.float32([0, 0, 1]), tris[:, ::-1].copy(),
                   material=e, name="emitter", visible_camera=False, **emitter_visibility)
    scene.world = {"color": [0.0] * 3}
    return scene


def test_emitter_hidden_from_diffuse_lights_no_diffuse_floor(core):
    dark, _ = render(emitter_scene(hidden("diffuse")), spp=16)
    assert dark.max() == 0.0  # neither next-event estimation nor a bounce finds it
    lit, _ = render(emitter_scene(hidden("glossy", "transmission")), spp=16)
    assert lit.mean() > 0.01  # the control: visible to diffuse, it lights the floor
    # a glossy floor sees the emitter hidden from diffuse rays only
    glossy, _ = render(emitter_scene(hidden("diffuse"), floor="metal"), spp=16)
    assert glossy.max() > 0.0


@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_bidirectional_shell_hidden_and_without_shadow(core, integrator):
    """The shell hidden from diffuse rays and casting no shadow: bdpt, lvc, cis render it
    themselves (ray visibility beside an object's Cast Shadow off, docs/lvc_notes.md; before,
    a hand-over to pt): the image is the one without the shell, against pt's (8 seeds; the
    white ball under a constant world reads 0.5 with no noise here, so any difference shows).
    The control: the shell seen by diffuse rays (the ball black) must fail."""
    ref = [render(ball_scene("diffuse"), 100 + k)[0] for k in range(8)]
    imgs, warnings = [], []
    for k in range(8):
        img, warnings = render(ball_scene("diffuse", hidden("diffuse")), 200 + k,
                               integrator=integrator)
        imgs.append(img)
    assert not warnings, warnings
    metrics.assert_agreement(f"shell hidden from diffuse, {integrator} vs pt without it", imgs,
                             ref, block=4, controls=False)
    dark = [render(ball_scene("diffuse", hidden("glossy", "transmission")), 300 + k,
                   integrator=integrator)[0] for k in range(8)]
    assert not metrics.compare_renders(dark, ref, block=4).passed


def test_schema_round_trip(core, tmp_path):
    scene = ball_scene("diffuse", hidden("diffuse", "volume_scatter"))
    assert scene.meshes[1]["visible_diffuse"] is False
    path = tmp_path / "v.lantern"
    scene.save(path)
    back = lantern.load_scene(path)
    assert back.meshes[1]["visible_diffuse"] is False
    assert back.meshes[1]["visible_volume_scatter"] is False
    assert "visible_glossy" not in back.meshes[1]
    with pytest.raises(TypeError):
        lantern.Scene().add_mesh(np.zeros((3, 3), np.float32), [[0, 1, 2]], visible_difuse=False)


@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis", "lt"])
def test_bidirectional_emitter_hidden_from_diffuse(core, integrator):
    """bdpt, lvc, cis render an emitter hidden from diffuse rays themselves
    (integrator/bidir_ray_visibility.h): no light path leaves it, next-event estimation skips it
    for the diffuse floor and a bounce ray passes it: black, exactly; the control (hidden from
    glossy and transmission rays only) lit."""
    dark, warnings = render(emitter_scene(hidden("diffuse")), spp=4, integrator=integrator)
    assert not warnings, warnings
    assert dark.max() == 0.0
    lit, _ = render(emitter_scene(hidden("glossy", "transmission")), spp=4,
                    integrator=integrator)
    assert lit.mean() > 0.01
