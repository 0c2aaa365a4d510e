"""The viewport camera from a region's view and window matrices: looking through the scene
camera must give the same view window and transform as the final-render camera."""

import math
from types import SimpleNamespace

import bpy
import numpy as np

from blender_helpers import add_camera


def fake_context(scene, view_matrix, window_matrix, width, height, perspective=True):
    return SimpleNamespace(
        region=SimpleNamespace(width=width, height=height),
        region_data=SimpleNamespace(view_matrix=view_matrix, window_matrix=window_matrix,
                                    is_perspective=perspective),
        scene=scene)


def _through_camera(empty, addon, ortho):
    from lantern_blender.export.camera import ViewportView, export_camera, export_film
    from lantern_blender.export import ExportReport
    cam = add_camera(empty, location=(1, -2, 3), rotation=(1.0, 0.2, 0.5), lens=30)
    cam.data.shift_x, cam.data.shift_y = 0.05, -0.1
    cam.data.clip_start, cam.data.clip_end = 0.2, 80
    if ortho:
        cam.data.type, cam.data.ortho_scale = "ORTHO", 5.0
    empty.render.resolution_x, empty.render.resolution_y = 64, 40
    depsgraph = bpy.context.evaluated_depsgraph_get()
    window = cam.calc_matrix_camera(depsgraph, x=64, y=40)
    ctx = fake_context(empty, cam.matrix_world.inverted(), window, 64, 40, not ortho)
    view = ViewportView(ctx)
    film = export_film(empty)
    ref = export_camera(empty, cam, film, ExportReport())
    got = view.camera()
    assert view.film()["width"] == 64 and view.film()["height"] == 40
    np.testing.assert_allclose(got["screen"], ref["screen"], rtol=1e-4, atol=1e-6)
    np.testing.assert_allclose(np.asarray(got["to_world"])[:3, :3],
                               np.asarray(ref["to_world"])[:3, :3], atol=1e-5)
    return got, ref


def test_viewport_through_perspective_camera(empty, addon):
    got, ref = _through_camera(empty, addon, ortho=False)
    np.testing.assert_allclose(got["clip"], ref["clip"], rtol=1e-3)
    np.testing.assert_allclose(np.asarray(got["to_world"])[:3, 3],
                               np.asarray(ref["to_world"])[:3, 3], atol=1e-5)


def test_viewport_through_ortho_camera(empty, addon):
    got, ref = _through_camera(empty, addon, ortho=True)
    # the rays start at the near plane's position along the view axis (never behind it)
    assert got["clip"][0] >= 0
