"""Subsurface scattering under motion blur against Cycles through the add-on (docs/motion_blur.md,
"Subsurface"), CI-sized: a cube of Principled BSDF with Subsurface Weight 1 (Random Walk, radius
50 / 30 / 20 cm) on a floor, a sun behind it (the side the camera sees is lit through the cube),
rendered with K seeds by Cycles (CPU) and by Lantern (pt) with tools/render_compare.py's
settings, compared by lantern.metrics.assert_agreement (Welch t per 8x8 block and channel, image
and block-weighted means within the bias cap plus noise, and the negative controls that must
fail):

- slide: the cube sliding 2.5 m across the frame over the shutter (linear keys);
- spin (long): a 2.4 x 0.4 x 1 m box of the same material spinning 90 degrees over the shutter
  (the walk's exit normals turned at the path's time);
- negative controls, each against Cycles' blurred renders: Lantern with motion blur off (the
  still frame: what Lantern rendered before, with a warning) and the subsurface taken out
  (Weight 0: the scene resolves the walk).
Measured 2026-12-06 (6 seeds x 64 spp, 32 x 32): slide image means -0.23 to -0.12 % of Cycles'
(allowed 0.74 %), spin -0.59 to +0.04 % (0.90 %); every control caught.
tests/python/test_motion_sss.py checks the same against an independent shutter integral."""

import math
import os
import sys

import pytest

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402

K = 6
SIZE = 32
SPP = (64, 64)    # per seed (Cycles', Lantern's)
BOUNCES = 4       # Cycles max bounces (Lantern max_depth 6)
SE_FLOOR = 1e-6
CONTROLS = (0.02, 0.10)  # (image, block) negative controls the noise affords

_bounces = bpy_stage.bounces(BOUNCES)


def _material(name, color, sss=0.0):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    p = m.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (*color, 1)
    p.inputs["Roughness"].default_value = 0.5 if sss > 0.0 else 1.0
    p.inputs["Subsurface Weight"].default_value = sss
    p.inputs["Subsurface Radius"].default_value = (1.0, 0.6, 0.4)
    p.inputs["Subsurface Scale"].default_value = 0.5
    p.subsurface_method = "RANDOM_WALK"
    return m


def _stage(scale=(1.0, 1.0, 1.0)):
    bpy.context.preferences.edit.keyframe_new_interpolation_type = "LINEAR"
    scene = bpy_stage.reset(SIZE, world=(0.1, 0.1, 0.1))
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = 0.5
    scene.render.motion_blur_position = "CENTER"
    bpy_stage.cube("floor", (0, 0, -0.05), 1.0, _material("floor", (0.8, 0.8, 0.8)),
                   scale=(12, 12, 0.1))
    cube = bpy_stage.cube("wax", (0, 0, 0.5), 1.0, _material("wax", (0.9, 0.6, 0.4), 1.0),
                          scale=scale)
    # behind the cube: its side towards the camera is lit through it
    bpy_stage.light(scene, "SUN", (0, 0, 5), 3.0, rotation=(-50, 20, 0), angle=0.05)
    bpy_stage.camera(scene, (0, -5, 2.5), (67, 0, 0))
    return cube


def _keys(obj, path, index, values):
    """Linear keys at frames 0 and 2 (the render is at frame 1, mid-motion)."""
    for frame, v in zip((0, 2), values):
        getattr(obj, path)[index] = v
        obj.keyframe_insert(path, index=index, frame=frame)


def slide():
    cube = _stage()
    _keys(cube, "location", 0, (-5.0, 5.0))   # 2.5 m over the shutter
    bpy.context.scene.frame_set(1)


def spin():
    cube = _stage(scale=(2.4, 0.4, 1.0))
    _keys(cube, "rotation_euler", 2, (0.0, 2.0 * math.pi))  # 90 degrees over the shutter
    bpy.context.scene.frame_set(1)


def _check(name, build):
    cyc = bpy_stage.compare_with_cycles(name, build, SPP, CONTROLS, cycles_seed0=1100,
                                        k_seeds=K, se_floor=SE_FLOOR)
    bpy.context.scene.render.use_motion_blur = False
    bpy_stage.control_differs(f"{name}, motion blur off", cyc, K, SPP[1], SE_FLOOR)
    bpy.context.scene.render.use_motion_blur = True
    p = bpy.data.materials["wax"].node_tree.nodes["Principled BSDF"]
    p.inputs["Subsurface Weight"].default_value = 0.0
    bpy_stage.control_differs(f"{name}, no subsurface", cyc, K, SPP[1], SE_FLOOR)


def test_sss_slide_matches_cycles():
    _check("sss slide", slide)


@pytest.mark.long
def test_sss_spin_matches_cycles():
    _check("sss spin", spin)
