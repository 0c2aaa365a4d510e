"""Transform and deformation motion blur against Cycles through the add-on (docs/motion_blur.md), CI-sized:
small scenes built here in bpy, each rendered with K seeds by Cycles (CPU) and by Lantern (pt)
with tools/render_compare.py's settings, compared by lantern.metrics.assert_agreement (Welch t
per 8x8 block and channel, image and block-weighted means within the bias cap plus noise, and
the negative controls that must fail):

- slide: a cube sliding across the frame, 3.7 m over the shutter (about four 8x8 blocks: the
  blocks see a blur that stays within one block only as its mean);
- spin: a 2.4 x 0.4 m box spinning about its vertical axis, 132 degrees over the shutter;
- camera: the camera sliding sideways over the static stage, 2.9 m over the shutter;
- parented: a cube on an arc, its parent turning 176 degrees over the shutter, 5 steps;
- slide_start, slide_end: the slide with the shutter's Position Start and End (each against
  Cycles' own, and the two must differ from each other);
- shape_key: deformation, a shape key shearing the cube (its top 1 m along x over the shutter);
  shape_key_slide: the same while the cube slides 1.5 m along y (deformation and transform);
- negative controls: Lantern with motion blur off must not agree with Cycles' blurred slide,
  nor with the cube's Deformation off against Cycles' sheared one;
- the bidirectional integrators (issue 32): cis on the slide against the same Cycles renders
  (lvc and cis as SPP passes of one sample: they draw one shutter time per pass) in CI; bdpt on
  the sheared, sliding cube, lvc on the camera and cis on the spin marked long (measured
  2026-12-05: all four agree, detecting 0.42-0.51 %, every control caught).
Bad input (a singular or NaN matrix at a step) is tests/python/test_motion_blur.py's.

The transform keys (_keys) are Bezier: bpy 5.0.1's keyframe_insert leaves them Bezier whatever
keyframe_new_interpolation_type says (checked: a key pair -5 -> 5 over frames 0 -> 2 puts the
cube at -1.836 at frame 0.75, not a linear key's -2.5), so each motion eases in and out, and
over the 0.5-frame shutter around frame 1 it covers 0.367 of its keys' range, not 0.25 (the
distances above). Both renderers read the same evaluated matrices, so the comparison holds; the
shape key's own keys are set linear (sheared)."""

import math
import os
import sys
import time

import numpy as np
import pytest

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402
import render_compare as rc  # noqa: E402
from lantern import metrics  # noqa: E402

K = 6
SIZE = 32
SPP = 64          # per seed, both renderers
BOUNCES = 2       # Cycles max bounces (Lantern max_depth 4): a diffuse stage, direct light rules
SE_FLOOR = 1e-6


def _reset(position="CENTER", blur=True):
    bpy.context.preferences.edit.keyframe_new_interpolation_type = "LINEAR"
    scene = bpy_stage.reset(SIZE, world=(0.2, 0.2, 0.2))
    scene.render.use_motion_blur = blur
    scene.render.motion_blur_shutter = 0.5
    scene.render.motion_blur_position = position
    return scene


def _material(name, color):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (*color, 1)
    mat.node_tree.nodes["Principled BSDF"].inputs["Roughness"].default_value = 1.0
    return mat


def _stage(scene):
    bpy.ops.mesh.primitive_plane_add(size=12, location=(0, 0, 0))
    bpy.context.object.data.materials.append(_material("floor", (0.8, 0.8, 0.8)))
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0, 0, 0.5))
    cube = bpy.context.object
    cube.data.materials.append(_material("red", (0.8, 0.1, 0.05)))
    sun = bpy.data.lights.new("sun", "SUN")
    sun.energy = 3.0
    sun.angle = 0.05
    sun_obj = bpy.data.objects.new("sun", sun)
    sun_obj.rotation_euler = (math.radians(40), math.radians(20), 0)
    scene.collection.objects.link(sun_obj)
    cam = bpy.data.cameras.new("cam")
    cam.lens = 35
    cam_obj = bpy.data.objects.new("cam", cam)
    cam_obj.location = (0, -5, 2.5)
    cam_obj.rotation_euler = (math.radians(67), 0, 0)
    scene.collection.objects.link(cam_obj)
    scene.camera = cam_obj
    return cube, cam_obj


def _keys(obj, path, index, values):
    """Keys at frames 0 and 2 (the render is at frame 1, mid-motion); Bezier (module docstring)."""
    for frame, v in zip((0, 2), values):
        getattr(obj, path)[index] = v
        obj.keyframe_insert(path, index=index, frame=frame)


def slide(position="CENTER", blur=True):
    scene = _reset(position, blur)
    cube, _ = _stage(scene)
    _keys(cube, "location", 0, (-5.0, 5.0))   # Bezier: 3.7 m (~4 blocks) over the shutter
    scene.frame_set(1)


def spin():
    scene = _reset()
    cube, _ = _stage(scene)
    cube.scale = (2.4, 0.4, 1.0)
    _keys(cube, "rotation_euler", 2, (0.0, 2.0 * math.pi))  # 132 degrees over the shutter
    scene.frame_set(1)


def camera():
    scene = _reset()
    _, cam = _stage(scene)
    _keys(cam, "location", 0, (-4.0, 4.0))  # 2.9 m over the shutter
    scene.frame_set(1)


def parented():
    """A cube parented to an empty that turns 176 degrees over the shutter, 1.5 m off its axis
    (an arc: Cycles interpolates the child's world matrix, translation along the chords), with
    Motion Steps 2 (5 steps)."""
    scene = _reset()
    cube, _ = _stage(scene)
    pivot = bpy.data.objects.new("pivot", None)
    scene.collection.objects.link(pivot)
    pivot.location = (0, 0, 0)
    cube.parent = pivot
    cube.location = (1.5, 0, 0.5)
    cube.cycles.motion_steps = 2
    _keys(pivot, "rotation_euler", 2, (0.0, math.radians(480)))
    scene.frame_set(1)


def sheared(moves=False, deform=True):
    """Deformation: a shape key that shears the cube, its top face 4 m along x at value 1,
    keyed 0 -> 1 over frames 0 -> 2 (linear): the top slides 1 m over the shutter while the
    bottom stays; `moves`: the cube also slides 1.5 m along y over the shutter (Bezier keys);
    `deform` False: the object's Deformation blur off (the negative control)."""
    scene = _reset()
    cube, _ = _stage(scene)
    cube.shape_key_add(name="Basis")
    key = cube.shape_key_add(name="Shear")
    for v in key.data:
        if v.co.z > 0.0:
            v.co.x += 4.0
    for frame, value in ((0, 0.0), (2, 1.0)):
        key.value = value
        key.keyframe_insert("value", frame=frame)
    from bpy_extras import anim_utils  # linear: shape keys' keys ignore the preference
    ad = cube.data.shape_keys.animation_data
    for fc in anim_utils.action_get_channelbag_for_slot(ad.action, ad.action_slot).fcurves:
        for kp in fc.keyframe_points:
            kp.interpolation = "LINEAR"
    if moves:
        _keys(cube, "location", 1, (-2.0, 2.0))
    cube.cycles.use_deform_motion = deform
    cube.update_tag()
    scene.frame_set(1)


SCENES = {"slide": slide, "spin": spin, "camera": camera, "parented": parented,
          "slide_start": lambda: slide("START"), "slide_end": lambda: slide("END"),
          "shape_key": sheared, "shape_key_slide": lambda: sheared(moves=True)}


_bounces = bpy_stage.bounces(BOUNCES)


def _lantern():
    lan, warnings = [], []
    for k in range(K):
        img, warnings = rc.render_lantern(seed=1 + k, spp=SPP, threads=2)
        lan.append(img)
    return np.stack(lan).astype(np.float64), warnings


_CYCLES = {}


def _cycles_of(name):
    """Cycles' seeds 700.. of scene `name` as stored per-seed block means
    (bpy_stage.cycles_reference: rendered again when the export, this file or the settings
    change)."""
    if name not in _CYCLES:
        SCENES[name]()
        _CYCLES[name] = bpy_stage.cycles_reference(name, slide, SPP, 700, K)
    return _CYCLES[name]


@pytest.mark.parametrize("name", list(SCENES))
def test_motion_blur_matches_cycles(name):
    t0 = time.perf_counter()
    cyc = _cycles_of(name)
    SCENES[name]()
    lan, warnings = _lantern()
    assert not warnings, warnings
    assert np.isfinite(lan).all()
    res = metrics.compare_renders(lan, cyc, block=rc.BLOCK, se_floor=SE_FLOOR, name=name)
    line = f"{res}; mean ratio {lan.mean() / cyc.blocks.mean():.4f} ({time.perf_counter() - t0:.1f} s)"
    print(line)
    rc.REPORT.append(line)
    metrics.assert_agreement(name, lan, cyc, block=rc.BLOCK, se_floor=SE_FLOOR)


def test_motion_blur_off_differs():
    """Negative control: without motion blur the slide is a sharp cube at the frame, which the
    comparison must tell from Cycles' blurred one (and Start from End)."""
    cyc = _cycles_of("slide")
    slide(blur=False)
    sharp, _ = _lantern()
    res = metrics.compare_renders(sharp, cyc, block=rc.BLOCK, se_floor=SE_FLOOR, name="sharp")
    print(res)
    assert not res.passed, f"motion blur off agrees with Cycles' blurred slide: {res}"
    slide("START")
    start, _ = _lantern()
    slide("END")
    end, _ = _lantern()
    res = metrics.compare_renders(start, end, block=rc.BLOCK, se_floor=SE_FLOOR, name="start/end")
    print(res)
    assert not res.passed, f"shutter Start and End render alike: {res}"


def test_deformation_blur_off_differs():
    """Negative control: with the object's Deformation off the sheared cube is the frame's
    shape, which the comparison must tell from Cycles' deforming one."""
    cyc = _cycles_of("shape_key")
    sheared(deform=False)
    still, _ = _lantern()
    res = metrics.compare_renders(still, cyc, block=rc.BLOCK, se_floor=SE_FLOOR, name="still")
    print(res)
    assert not res.passed, f"deformation blur off agrees with Cycles' deforming cube: {res}"


def _lantern_bidir(integrator):
    """_lantern through `integrator`: lvc and cis one sample a pass (docs/motion_blur.md)."""
    import lantern
    rc.lantern_bpy.load_addon()
    from lantern_blender.export import export_scene
    scene, report = export_scene(bpy.context.evaluated_depsgraph_get())
    per = 1 if integrator in ("lvc", "cis") else SPP
    out = []
    for k in range(K):
        s = lantern.Session(scene, integrator=integrator, backend="cpu", threads=2, seed=1 + k,
                            max_depth=rc.lantern_depth(rc.BOUNCES), spp_per_iteration=per)
        while s.spp < SPP:
            s.step()
        assert not s.warnings, list(s.warnings)
        out.append(np.asarray(s.image(), np.float64)[..., :3])
    assert not report.messages, report.messages
    return np.stack(out)


@pytest.mark.parametrize("name, integrator", [
    ("slide", "cis"), pytest.param("shape_key_slide", "bdpt", marks=pytest.mark.long),
    pytest.param("camera", "lvc", marks=pytest.mark.long),
    pytest.param("spin", "cis", marks=pytest.mark.long)])
def test_motion_blur_bidirectional_matches_cycles(name, integrator):
    cyc = _cycles_of(name)
    SCENES[name]()
    lan = _lantern_bidir(integrator)
    assert np.isfinite(lan).all()
    metrics.assert_agreement(f"{name} {integrator}", lan, cyc, block=rc.BLOCK, se_floor=SE_FLOOR)
