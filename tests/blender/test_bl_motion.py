"""Motion blur through F12 (docs/motion_blur.md): the engine reads the steps with its own
frame_set and leaves the scene at its frame; a sliding diffuse plane under a sun blurs (the
image differs from motion blur off, and its edge has values between the plane's and the
background's); the viewport renders the frame (no steps). Agreement with Cycles:
tests/cycles/test_motion_blur.py."""

import math

import bpy
import numpy as np
import pytest

import lantern
from blender_helpers import add_camera, add_plane, diffuse_material, render_exr

pytestmark = pytest.mark.skipif(not lantern.session.native_available(),
                                reason="lantern native module not built")


def _stage(scene):
    bpy.context.preferences.edit.keyframe_new_interpolation_type = "LINEAR"
    add_camera(scene, location=(0, 0, 5))
    plane = add_plane(scene, size=1.0, material=diffuse_material(0.8), name="Slider")
    for frame, x in ((0, -3.0), (2, 3.0)):  # 3 m a frame: 1.5 m over a 0.5-frame shutter
        plane.location.x = x
        plane.keyframe_insert("location", index=0, frame=frame)
    sun = bpy.data.lights.new("Sun", "SUN")
    sun.energy = 2.0
    sun.angle = 0.0
    scene.collection.objects.link(bpy.data.objects.new("Sun", sun))
    scene.frame_set(1)
    scene.lantern.samples = 64
    return plane


def test_f12_blurs_a_sliding_plane(empty, tmp_path, errors):
    _stage(empty)
    empty.render.use_motion_blur = False
    sharp = render_exr(empty, tmp_path, "sharp.exr")[..., :3]
    empty.render.use_motion_blur = True
    blurred = render_exr(empty, tmp_path, "blur.exr")[..., :3]
    assert empty.frame_current == 1 and empty.frame_subframe == 0.0
    assert not [c for c in errors if c[0] == "ERROR"], errors
    # the only warning: 'auto' takes pt for motion blur, as it does for volumes
    assert all("which only pt renders" in m for kind, m in errors if kind == "WARNING"), errors
    row = sharp.shape[0] // 2
    lit = sharp[row].max()  # the plane under the sun, head-on (Principled: diffuse + specular)
    assert lit > 0.8 * 2.0 / math.pi
    # blurred: the same light spread wider at a lower peak (energy kept, as the shutter average)
    assert blurred[row].max() < 0.9 * lit
    assert (blurred[row, :, 0] > 0.05 * lit).sum() > (sharp[row, :, 0] > 0.05 * lit).sum() + 4
    np.testing.assert_allclose(blurred[row].sum(), sharp[row].sum(), rtol=0.05)
