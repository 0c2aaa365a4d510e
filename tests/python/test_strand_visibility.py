"""Strands take their object's ray visibility (Cycles: particle hair its emitter's flags, a
Curves object its own; D58): a bounce ray of a kind passes the strands hidden from that kind
(pt_ray_visibility.h pt_pass_hidden_strand: on from the same origin past the strand's entry),
as it passes a mesh hidden from it (test_object_visibility.py).

A ball under a constant world of 0.5 inside a cage of black strands (latitude rings, radius 2,
overlapping) that the camera does not see and that casts no shadow: where the cage is hidden
from the ball's kind of scattering, every bounce ray passes it, so the image is the one without
the cage, bit for bit (the pass draws no random number; the constant world is no next-event
light); where it is not (the control), the cage's black ends most bounce rays and the ball
darkens. bdpt, lvc and cis render it themselves (against pt without the cage; more in
test_strand_visibility_bidir.py); lt hands strands hidden from some kind to pt with a warning
(allocation.cpp bidir_visibility_reason), and auto keeps pt: their images are pt's, bit for
bit."""
import numpy as np
import pytest

import lantern
from test_object_visibility import BALL, MATERIALS, WORLD, hidden, render
from lantern import metrics, scenes


def cage(scene, material, rings=40, keys=48, radius=2.0, **flags):
    """Latitude rings of strands around the origin (the ball), each a closed polyline."""
    lat = np.linspace(-np.pi / 2, np.pi / 2, rings + 2)[1:-1]
    lon = np.linspace(0.0, 2.0 * np.pi, keys + 1)
    pts = [np.stack([radius * np.cos(a) * np.cos(lon), radius * np.cos(a) * np.sin(lon),
                     np.full(keys + 1, radius * np.sin(a))], axis=-1) for a in lat]
    pts = np.concatenate(pts).astype(np.float32)
    scene.add_curves(pts, np.full(len(pts), 0.1, np.float32),
                     np.arange(0, len(pts) + 1, keys + 1), material=material, name="cage",
                     visible_camera=False, cast_shadow=False, **flags)
    return scene


def ball_scene(kind, flags=None, size=16):
    """The ball of `kind` under the world; flags: None (no cage) or the cage's kinds."""
    scene = lantern.Scene()
    scene.film.update(width=size, height=size)
    scene.look_at((0.0, -3.0, 0.0), (0.0, 0.0, 0.0), fov=50.0)
    m = scene.add_material(kind, **MATERIALS[kind])
    pos, idx = scenes.icosphere(2, 0.9)
    scene.add_mesh(pos, idx, material=m, name="ball")
    if flags is not None:
        flags = dict(flags)
        grey = flags.pop("grey", False)  # (the bidirectional test's: light paths meet it)
        c = scene.add_material("cage", type="diffuse", base_color=(0.8 if grey else 0.0,) * 3)
        cage(scene, c, **flags)
    scene.world = {"color": [WORLD] * 3}
    return scene


@pytest.mark.parametrize("kind,hide,control", [
    ("diffuse", ("diffuse",), ("glossy", "transmission")),
    ("metal", ("glossy",), ("diffuse", "transmission")),
    ("glass", ("glossy", "transmission"), ("diffuse",)),
    # Principled reflections are of both kinds (pt_scatter_kind): hidden only from both
    ("principled", ("diffuse", "glossy"), ("diffuse",)),
])
def test_hidden_strands_are_absent_for_their_kind(core, kind, hide, control):
    for seed in (1, 2):
        without, _ = render(ball_scene(kind), seed)
        through, warnings = render(ball_scene(kind, hidden(*hide)), seed)
        assert not warnings, warnings
        np.testing.assert_array_equal(through, without)
    assert without[BALL].min() > 0.05
    dark, _ = render(ball_scene(kind, hidden(*control)), 1)
    # the control: the cage seen by the ball's kind blocks most of the world
    assert dark[BALL].mean() < 0.5 * without[BALL].mean()
    assert dark[0, 0] == pytest.approx([WORLD] * 3)  # the camera sees past the cage


def test_kinds_reach_the_core(core, tmp_path):
    scene = ball_scene("diffuse", hidden("diffuse", "volume_scatter"))
    c = scene.curves[0]
    assert c["visible_diffuse"] is False and c["visible_volume_scatter"] is False
    assert "visible_glossy" not in c
    path = tmp_path / "c.lantern"
    scene.save(path)
    back = lantern.load_scene(path)
    assert back.curves[0]["visible_diffuse"] is False
    with pytest.raises(TypeError):
        cage(lantern.Scene(), 0, visible_difuse=False)


@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_bidirectional_cage_hidden(core, integrator):
    """bdpt, lvc, cis render strands hidden from some kind themselves (bidir_ray_visibility.h:
    a bounce ray passing a strand makes the path restricted, a light vertex on one is splatted
    only): the grey cage (0.8, lit by the world: the light pass meets it first) hidden from
    diffuse rays around the white ball is the image without it, against pt's (8 seeds; the
    ball reads 0.5 with little noise). The control, the cage seen by diffuse rays, must fail."""
    ref = [render(ball_scene("diffuse"), 100 + k)[0] for k in range(8)]
    imgs = []
    for k in range(8):
        img, warnings = render(ball_scene("diffuse", dict(hidden("diffuse"), grey=True)),
                               200 + k, integrator=integrator)
        assert not warnings, warnings
        imgs.append(img)
    metrics.assert_agreement(f"cage hidden from diffuse, {integrator} vs pt without it", imgs,
                             ref, block=4, controls=False)
    seen = [render(ball_scene("diffuse", dict(hidden("glossy", "transmission"), grey=True)),
                   300 + k, integrator=integrator)[0] for k in range(8)]
    assert not metrics.compare_renders(seen, ref, block=4).passed


@pytest.mark.parametrize("integrator", ["lt", "auto"])
def test_others_hand_over_to_pt(core, integrator):
    scene = ball_scene("diffuse", hidden("diffuse"))
    img, warnings = render(scene, 3, integrator=integrator)
    if integrator == "lt":  # (the cage's Cast Shadow off is named first)
        assert any("rendering with pt" in w for w in warnings), warnings
        scene = ball_scene("diffuse", hidden("diffuse"))
        scene.curves[0]["cast_shadow"] = True
        _, warnings = render(scene, 3, integrator=integrator)
        assert any("rendering with pt" in w and "strands hidden" in w for w in warnings), \
            warnings
    np.testing.assert_array_equal(img, render(ball_scene("diffuse"), 3)[0])
