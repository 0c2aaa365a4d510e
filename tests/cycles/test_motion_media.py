"""Volumes under motion blur against Cycles through the add-on (docs/motion_blur.md, "Subsurface
and volumes"), CI-sized: K seeds by Cycles (CPU) and by Lantern (pt) with
tools/render_compare.py's settings, compared by lantern.metrics.assert_agreement (Welch t per
8x8 block and channel, image and block-weighted means within the bias cap plus noise, and the
negative controls that must fail):

- cloud: a homogeneous cloud cube (Principled Volume, no surface) sliding 1.5 m over the
  shutter above a floor, lit from behind by an area light (a moving mesh volume: its boundary
  where it is at the ray's time, as Cycles);
- world_fog: test_volumes.py's world fog (Volume Scatter + Volume Absorption) around a sphere
  sliding 1.2 m over the shutter (still media, timed shadow rays through them);
- negative control for each: Lantern with motion blur off (the still frame, as Lantern rendered
  any scene with volumes before) against Cycles' blurred renders must fail.
tests/python/test_motion_media.py checks the same kinds against an independent shutter
integral."""

import os
import sys

import pytest

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402
from bpy_stage import camera as _camera, cube as _cube, light as _light  # noqa: E402

K = 6
SIZE = 32
SE_FLOOR = 1e-6
SPP = (128, 128)  # per seed (Cycles', Lantern's)
CONTROLS = (0.02, 0.10)


def _reset():
    bpy.context.preferences.edit.keyframe_new_interpolation_type = "LINEAR"
    scene = bpy_stage.reset(SIZE)
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = 0.5
    scene.render.motion_blur_position = "CENTER"
    return scene


def _material(name, color):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    m.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (*color, 1.0)
    m.node_tree.nodes["Principled BSDF"].inputs["Roughness"].default_value = 1.0
    return m


def _keys(obj, values):
    """Linear keys of location x at frames 0 and 2 (the render is at frame 1, mid-motion)."""
    for frame, v in zip((0, 2), values):
        obj.location[0] = v
        obj.keyframe_insert("location", index=0, frame=frame)


def cloud():
    scene = _reset()
    _cube("floor", (0, 0, -0.05), 1.0, _material("floor", (0.5, 0.5, 0.5)), scale=(6, 6, 0.1))
    m = bpy.data.materials.new("cloud")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Density"].default_value = 1.2
    v.inputs["Color"].default_value = (0.9, 0.9, 0.9, 1.0)
    nt.links.new(v.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    box = _cube("cloud", (0, 0, 0.8), 1.4, m)
    _keys(box, (-3.0, 3.0))  # 1.5 m over the shutter
    _light(scene, "AREA", (0, 2.5, 1.2), 300.0, rotation=(-90, 0, 0), size=1.0)
    _camera(scene, (0, -3.5, 1.2), (85, 0, 0), lens=30.0)
    scene.frame_set(1)


def world_fog():
    scene = _reset()
    nt = scene.world.node_tree
    out = nt.nodes["World Output"]
    sc = nt.nodes.new("ShaderNodeVolumeScatter")
    sc.inputs["Density"].default_value = 0.06
    sc.inputs["Color"].default_value = (0.9, 0.8, 0.7, 1)
    ab = nt.nodes.new("ShaderNodeVolumeAbsorption")
    ab.inputs["Density"].default_value = 0.04
    ab.inputs["Color"].default_value = (0.5, 0.6, 0.9, 1)
    add = nt.nodes.new("ShaderNodeAddShader")
    nt.links.new(sc.outputs[0], add.inputs[0])
    nt.links.new(ab.outputs[0], add.inputs[1])
    nt.links.new(add.outputs[0], out.inputs["Volume"])
    _cube("floor", (0, 0, -0.05), 1.0, _material("floor", (0.6, 0.6, 0.6)), scale=(8, 8, 0.1))
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.6, location=(0, 0, 0.6), segments=24,
                                         ring_count=12)
    ball = bpy.context.active_object
    ball.data.materials.append(_material("ball", (0.8, 0.3, 0.2)))
    _keys(ball, (-2.4, 2.4))  # 1.2 m over the shutter
    _light(scene, "POINT", (1.0, -1.0, 2.5), 300.0, shadow_soft_size=0.1)
    _camera(scene, (0, -5, 1.6), (78, 0, 0), lens=30.0)
    scene.frame_set(1)


SCENES = {"cloud": cloud, "world_fog": world_fog}


@pytest.mark.parametrize("name", list(SCENES))
def test_media_motion_matches_cycles(name):
    cyc = bpy_stage.compare_with_cycles(f"motion {name}", SCENES[name], SPP, CONTROLS,
                                        cycles_seed0=1200, k_seeds=K, se_floor=SE_FLOOR)
    bpy.context.scene.render.use_motion_blur = False
    bpy_stage.control_differs(f"motion {name}, motion blur off", cyc, K, SPP[1], SE_FLOOR)
