"""Session.update_camera: a running session re-aimed (and resized) renders what a new session
of the moved camera renders, bit for bit on the CPU; bad input is refused, the session goes on."""
import copy

import numpy as np
import pytest

from lantern import scenes, session

pytestmark = pytest.mark.skipif(not session.native_available(),
                                reason=f"lantern._core not built ({session.native_error()})")


def _moved(scene, width, height):
    moved = copy.deepcopy(scene)
    moved.film = dict(scene.film, width=width, height=height)
    moved.look_at((0.3, -3.2, 1.2), (0.0, 0.0, 0.9), fov=45)
    return moved


@pytest.mark.parametrize("integrator", ["pt", "bdpt", "cis"])
def test_update_camera_renders_as_a_new_session(integrator):
    scene = scenes.cornell_box(width=16, height=12)
    s = session.Session(scene, integrator=integrator, backend="cpu", seed=3)
    s.step()
    s.step()
    moved = _moved(scene, 20, 10)
    assert s.update_camera(moved.film, moved.camera)
    assert s.spp == 0 and s.image().shape == (10, 20, 3)
    for _ in range(3):
        s.step()
    want = session.render(moved, spp=3, integrator=integrator, backend="cpu", seed=3)
    np.testing.assert_array_equal(s.image(), want)


def test_bad_camera_is_refused_and_the_session_goes_on():
    scene = scenes.cornell_box(width=8, height=8)
    s = session.Session(scene, backend="cpu", integrator="pt")
    s.step()
    before = s.image()
    with pytest.raises((ValueError, TypeError)):
        s.update_camera(dict(scene.film, width=0), scene.camera)
    assert s.spp == 1 and np.array_equal(s.image(), before)
    s.step()
    assert s.spp == 2


@pytest.mark.parametrize("integrator", ["pt", "cis"])
def test_update_materials_renders_as_a_new_session(integrator):
    scene = scenes.cornell_box(width=16, height=12)
    s = session.Session(scene, integrator=integrator, backend="cpu", seed=5)
    s.step()
    edited = copy.deepcopy(scene)
    wall = next(i for i, m in enumerate(edited.materials)
                if not any(m.get("emission", (0, 0, 0))))
    edited.materials[wall] = dict(edited.materials[wall], base_color=[0.1, 0.2, 0.9],
                                  roughness=0.3)
    _renders_as_a_new_session(s, scene, edited, integrator, 5, 3)


def _renders_as_a_new_session(s, scene, edited, integrator, seed, spp):
    """s, a running session of `scene`, takes edited's materials and renders `spp` samples
    bit for bit as a new session of `edited` does; the old materials' image differs (the update
    took effect)."""
    assert s.update_materials(edited.materials, edited.textures)
    assert s.spp == 0
    for _ in range(spp):
        s.step()
    want = session.render(edited, spp=spp, integrator=integrator, backend="cpu", seed=seed)
    np.testing.assert_array_equal(s.image(), want)
    assert not np.array_equal(want, session.render(scene, spp=spp, integrator=integrator,
                                                    backend="cpu", seed=seed))


def test_update_materials_refuses_what_reaches_further():
    scene = scenes.cornell_box(width=8, height=8)
    s = session.Session(scene, backend="cpu", integrator="pt")
    s.step()
    glowing = copy.deepcopy(scene.materials)
    glowing[0] = dict(glowing[0], emission=[5.0, 5.0, 5.0])  # the light list would change
    assert not s.update_materials(glowing, scene.textures)
    seethrough = copy.deepcopy(scene.materials)
    seethrough[0] = dict(seethrough[0], alpha=0.5)  # its triangles would be alpha-tested
    assert not s.update_materials(seethrough, scene.textures)
    assert not s.update_materials(scene.materials[:-1], scene.textures)  # fewer materials
    assert s.spp == 1  # refused: nothing changed
    s.step()
    assert s.spp == 2


@pytest.mark.parametrize("integrator", ["pt", "cis"])
def test_update_materials_renews_the_albedo_tables(integrator):
    """A rough conductor (energy-compensation tables, kept beside the materials since the
    tables left Material) re-roughened in a running session: its tables are the new ones, bit
    for bit what a new session renders."""
    scene = scenes.features_box(16, 12)
    metal = next(i for i, m in enumerate(scene.materials) if m.get("type") == "conductor")
    s = session.Session(scene, integrator=integrator, backend="cpu", seed=7)
    s.step()
    edited = copy.deepcopy(scene)
    edited.materials[metal] = dict(edited.materials[metal], roughness=0.8)
    _renders_as_a_new_session(s, scene, edited, integrator, 7, 2)
