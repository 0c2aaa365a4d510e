"""A moving emitter against Cycles through the add-on (docs/motion_blur.md "A moving emitter",
issue 32), CI-sized: an emissive quad (Emission, strength 12; 0.8 x 0.4 m) 1.4 m over a diffuse
floor, seen only through its light on the floor (the camera looks down past it; black world),
K seeds of each renderer, compared by lantern.metrics.assert_agreement with its negative
controls (tools/render_compare.py's settings, Cycles' max bounces 2):

- slide: the quad sliding 2.5 m over the shutter (5 m a frame, shutter 0.5, Center);
- spin: the quad turning 180 degrees about its vertical axis over the shutter, 1 m off the
  axis (an arc), Motion Steps 2 (5 steps);
- negative control: Lantern with the quad kept still (motion blur off: where it is at the
  frame, which is what the core rendered before, with a warning) must not agree with Cycles'
  blurred slide;
- bdpt on the slide (its light paths start on the quad at their time).
Cycles' side is stored (bpy_stage.cycles_reference)."""

import math
import os
import sys

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
SPP = 64
BOUNCES = 2
SE_FLOOR = 1e-6

_bounces = bpy_stage.bounces(BOUNCES)


def _emission(name, strength):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    for n in list(nodes):
        if n.type != "OUTPUT_MATERIAL":
            nodes.remove(n)
    em = nodes.new("ShaderNodeEmission")
    em.inputs["Color"].default_value = (1.0, 0.85, 0.7, 1.0)
    em.inputs["Strength"].default_value = strength
    links.new(em.outputs[0], nodes["Material Output"].inputs["Surface"])
    return mat


def _keys(obj, path, index, values):
    """Linear keys at frames 0 and 2 (the render is at frame 1, mid-motion): set on the keys
    themselves (keyframe_insert here leaves them Bezier whatever the preference says)."""
    for frame, v in zip((0, 2), values):
        getattr(obj, path)[index] = v
        obj.keyframe_insert(path, index=index, frame=frame)
    from bpy_extras import anim_utils
    ad = obj.animation_data
    for fc in anim_utils.action_get_channelbag_for_slot(ad.action, ad.action_slot).fcurves:
        for kp in fc.keyframe_points:
            kp.interpolation = "LINEAR"


def _stage(blur=True):
    scene = bpy_stage.reset(SIZE)
    scene.render.use_motion_blur = blur
    scene.render.motion_blur_shutter = 0.5
    scene.render.motion_blur_position = "CENTER"
    bpy.ops.mesh.primitive_plane_add(size=12, location=(0, 0, 0))
    bpy.context.object.data.materials.append(bpy_stage.rough_material("floor", (0.8, 0.8, 0.8)))
    bpy.ops.mesh.primitive_plane_add(size=1, location=(0, 0.3, 1.4))
    lamp = bpy.context.object
    lamp.name = "lamp"
    lamp.scale = (0.8, 0.4, 1.0)
    lamp.data.materials.append(_emission("lamp", 12.0))
    # 50 mm: the top of the frame 7 degrees above the horizon, under the quad's height
    bpy_stage.camera(scene, (0, -3.0, 0.8), (77.1, 0, 0), lens=50.0)
    return scene, lamp


def slide(blur=True):
    scene, lamp = _stage(blur)
    _keys(lamp, "location", 0, (-5.0, 5.0))  # 2.5 m over the shutter
    scene.frame_set(1)


def spin():
    """The quad on an arc: parented to an empty turning 360 degrees a frame (180 over the
    shutter), 1 m off its axis, Motion Steps 2."""
    scene, lamp = _stage()
    pivot = bpy.data.objects.new("pivot", None)
    scene.collection.objects.link(pivot)
    pivot.location = (0, 0.3, 1.4)
    lamp.parent = pivot
    lamp.location = (1.0, 0, 0)
    lamp.cycles.motion_steps = 2
    _keys(pivot, "rotation_euler", 2, (0.0, math.radians(720)))
    scene.frame_set(1)


SCENES = {"slide": slide, "spin": spin}
_CYCLES = {}


def _cycles_of(name):
    if name not in _CYCLES:
        SCENES[name]()
        _CYCLES[name] = bpy_stage.cycles_reference(name, slide, SPP, 700, K)
    return _CYCLES[name]


def _lantern(integrator="pt", spp=SPP):
    """K seeds through the add-on's export; no export or session warning."""
    import lantern
    rc.lantern_bpy.load_addon()
    from lantern_blender.export import export_scene
    scene, report = export_scene(bpy.context.evaluated_depsgraph_get())
    assert not report.messages, report.messages
    out = []
    for k in range(K):
        s = lantern.Session(scene, integrator=integrator, backend="cpu", threads=2, seed=1 + k,
                            max_depth=rc.lantern_depth(rc.BOUNCES), spp_per_iteration=spp)
        s.step()
        assert not s.warnings, list(s.warnings)
        out.append(np.asarray(s.image(), np.float64)[..., :3])
    return np.stack(out)


@pytest.mark.parametrize("name", list(SCENES))
def test_moving_emitter_matches_cycles(name):
    cyc = _cycles_of(name)
    assert cyc.blocks.mean() > 1e-3, "the scene is black in Cycles"
    SCENES[name]()
    lan = _lantern()
    assert np.isfinite(lan).all()
    res = metrics.compare_renders(lan, cyc, block=rc.BLOCK, se_floor=SE_FLOOR, name=name)
    line = f"{res}; mean ratio {lan.mean() / cyc.blocks.mean():.4f}"
    print(line)
    rc.REPORT.append(line)
    metrics.assert_agreement(f"{name} emitter", lan, cyc, block=rc.BLOCK, se_floor=SE_FLOOR)


def test_still_emitter_differs():
    """Negative control: the quad where it is at the frame (motion blur off) against Cycles'
    blurred slide."""
    cyc = _cycles_of("slide")
    slide(blur=False)
    still = _lantern()
    res = metrics.compare_renders(still, cyc, block=rc.BLOCK, se_floor=SE_FLOOR, name="still")
    print(f"{res}; mean ratio {still.mean() / cyc.blocks.mean():.4f}")
    assert not res.passed, f"the still emitter agrees with Cycles' moving one: {res}"


def test_moving_emitter_bdpt_matches_cycles():
    cyc = _cycles_of("slide")
    slide()
    lan = _lantern("bdpt", 4 * SPP)  # (its noise over Cycles': the +-1 % controls resolved)
    assert np.isfinite(lan).all()
    metrics.assert_agreement("slide emitter bdpt", lan, cyc, block=rc.BLOCK, se_floor=SE_FLOOR)
