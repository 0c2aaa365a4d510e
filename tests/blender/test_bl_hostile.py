"""Hostile scenes through F12 in bpy (issue 12): a camera 2e19 m away (Embree asserted on its
rays and took Blender down), a triangle with 1e10 m edges (dropped as "degenerate" by a float
overflow), a light 2e19 m away. Each: a warning naming what and why, an image with the exact
value where one is known, and Blender goes on rendering."""

import math

import bpy
import numpy as np
import pytest

import lantern
from blender_helpers import add_camera, add_plane, emission_material, render_exr

pytestmark = pytest.mark.skipif(not lantern.session.native_available(),
                                reason="lantern native module not built")


def warnings_of(errors):
    assert not [c for c in errors if c[0] == "ERROR"], errors
    return " ".join(msg for kind, msg in errors if kind == "WARNING")


def grey_world(scene, value):
    world = bpy.data.worlds.new("W")
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (value,) * 3 + (1,)
    scene.world = world


def still_renders(scene, tmp_path):
    """Blender survived: an ordinary render afterwards in the same process is right."""
    for obj in list(scene.objects):
        bpy.data.objects.remove(obj)
    add_camera(scene, location=(0, 0, 5), name="After")
    add_plane(scene, size=100.0, material=emission_material(1.5), name="AfterPlane")
    scene.lantern.samples = 1
    px = render_exr(scene, tmp_path, "after.exr")
    np.testing.assert_allclose(px[..., :3], 1.5, rtol=1e-5)


def test_camera_2e19_away_orthographic(empty, tmp_path, errors):
    """An orthographic camera 2e19 m above an emissive plane: its rays are moved to the scene's
    bounds, so every pixel is the plane's emission, 2, exactly; a warning names the camera."""
    cam = add_camera(empty, location=(0, 0, 2e19))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 10.0
    cam.data.clip_end = 1e30
    add_plane(empty, size=100.0, material=emission_material(2.0), name="Ground")
    empty.lantern.samples = 2
    px = render_exr(empty, tmp_path)
    assert np.isfinite(px).all()
    np.testing.assert_allclose(px[..., :3], 2.0, rtol=1e-6)
    assert "the camera is 2e+19 m from the origin" in warnings_of(errors)
    still_renders(empty, tmp_path)


def test_camera_2e19_away_perspective(empty, tmp_path, errors):
    """A perspective camera 2e19 m away with the default lens: the scene is far below a pixel
    (and past the clip range); the image is the world's grey, exactly, with the warning."""
    add_camera(empty, location=(0, -2e19, 0), rotation=(math.pi / 2, 0, 0))
    add_plane(empty, size=100.0, material=emission_material(2.0), name="Ground")
    grey_world(empty, 0.25)
    empty.lantern.samples = 2
    px = render_exr(empty, tmp_path)
    np.testing.assert_allclose(px[..., :3], 0.25, rtol=1e-6)
    assert "the camera is 2e+19 m from the origin" in warnings_of(errors)
    still_renders(empty, tmp_path)


@pytest.mark.parametrize("integrator", ["pt", "cis"])
def test_triangle_with_1e10_m_edges(empty, tmp_path, errors, integrator):
    """One triangle with edges of 1e10 m and more, emitting 3, seen from 1e9 m: every pixel 3
    exactly, and no "degenerate (zero-area)" warning (the area test overflowed in float)."""
    add_camera(empty, location=(0, 0, 1e9)).data.clip_end = 1e12
    mesh = bpy.data.meshes.new("Huge")
    mesh.from_pydata([(-1e10, -1e10, 0), (1e10, -1e10, 0), (0, 1e10, 0)], [], [(0, 1, 2)])
    mesh.materials.append(emission_material(3.0))
    obj = bpy.data.objects.new("Huge", mesh)
    empty.collection.objects.link(obj)
    empty.lantern.integrator = integrator
    empty.lantern.samples = 2
    px = render_exr(empty, tmp_path)
    np.testing.assert_allclose(px[..., :3], 3.0, rtol=1e-5)
    assert "degenerate" not in warnings_of(errors)
    still_renders(empty, tmp_path)


def test_light_2e19_away(empty, tmp_path, errors):
    """A point light 2e19 m away is left out with a warning naming it; the rest renders (an
    emissive plane: exactly its emission)."""
    add_camera(empty, location=(0, 0, 5))
    add_plane(empty, size=100.0, material=emission_material(2.0))
    light = bpy.data.lights.new("Far", "POINT")
    light.energy = 1000.0
    obj = bpy.data.objects.new("Far Lamp", light)
    obj.location = (2e19, 0, 0)
    empty.collection.objects.link(obj)
    empty.lantern.samples = 2
    px = render_exr(empty, tmp_path)
    np.testing.assert_allclose(px[..., :3], 2.0, rtol=1e-5)
    assert "light 'Far Lamp' is 2e+19 m from the origin" in warnings_of(errors)
