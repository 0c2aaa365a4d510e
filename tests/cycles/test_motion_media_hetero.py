"""A moving heterogeneous volume against Cycles through the add-on (docs/motion_blur.md
"Volumes"), CI-sized: a smoke cube whose Principled Volume Density is a Noise Texture of its
Generated coordinates (test_volumes_hetero.py's graph: the noise moves with the cube) slides
1.2 m and turns 30 degrees over the shutter above a floor, lit by a sun from the side and a dim
world. Cycles sets a volume's object transforms at the ray's time (docs/motion_blur.md, "What
Cycles does"), so the density moves with the cube; Lantern reads it through the cube's matrix at
the ray's time (scene/motion.h's medium_ray_exported). K seeds by Cycles (CPU, stored) and by
Lantern (pt) with tools/render_compare.py's settings, lantern.metrics.assert_agreement with its
negative controls; control of the change: Lantern with motion blur off (the cube kept where it
is at the frame, as Lantern rendered a moving heterogeneous volume before) must fail.
tests/python/test_motion_media_hetero.py checks the same kind against an independent shutter
integral, and bdpt, cis and lt against pt."""

import math
import os
import sys

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402
from bpy_stage import camera as _camera, cube as _cube, light as _light  # noqa: E402
from bpy_stage import rough_material as _material  # noqa: E402

K = 6
SIZE = 32
SE_FLOOR = 1e-6
SPP = (128, 128)  # per seed (Cycles', Lantern's)
CONTROLS = (0.02, 0.10)


def _smoke_material():
    """Principled Volume (no Surface) of Density 12 x clamp(Noise Fac - 0.45, 0, 1)."""
    m = bpy.data.materials.new("smoke")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Color"].default_value = (0.85, 0.8, 0.7, 1.0)
    v.inputs["Absorption Color"].default_value = (0.3, 0.3, 0.3, 1.0)
    noise = nt.nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = 3.0
    noise.inputs["Detail"].default_value = 2.0
    sub = nt.nodes.new("ShaderNodeMath")
    sub.operation, sub.use_clamp = "SUBTRACT", True
    sub.inputs[1].default_value = 0.45
    mul = nt.nodes.new("ShaderNodeMath")
    mul.operation = "MULTIPLY"
    mul.inputs[1].default_value = 12.0
    nt.links.new(noise.outputs["Fac"], sub.inputs[0])
    nt.links.new(sub.outputs[0], mul.inputs[0])
    nt.links.new(mul.outputs[0], v.inputs["Density"])
    nt.links.new(v.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    return m


def smoke():
    bpy.context.preferences.edit.keyframe_new_interpolation_type = "LINEAR"
    scene = bpy_stage.reset(SIZE, world=(0.05, 0.06, 0.08))
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = 0.5
    scene.render.motion_blur_position = "CENTER"
    _cube("floor", (0, 0, -0.05), 1.0, _material("floor", (0.7, 0.7, 0.7)), scale=(6, 6, 0.1))
    box = _cube("smoke", (0, 0, 0.75), 1.3, _smoke_material())  # apart from the floor
    for frame, x, a in ((0, -2.4, -60.0), (2, 2.4, 60.0)):  # over the shutter: 1.2 m, 30 deg
        box.location[0] = x
        box.rotation_euler[2] = math.radians(a)
        box.keyframe_insert("location", index=0, frame=frame)
        box.keyframe_insert("rotation_euler", index=2, frame=frame)
    _light(scene, "SUN", (0, 0, 3), 3.0, rotation=(50, 0, 40), angle=0.05)
    _camera(scene, (0, -3.5, 1.8), (70, 0, 0), lens=30.0)
    scene.frame_set(1)


def test_moving_hetero_volume_matches_cycles():
    cyc = bpy_stage.compare_with_cycles("moving smoke", smoke, SPP, CONTROLS, cycles_seed0=1300,
                                        k_seeds=K, se_floor=SE_FLOOR)
    bpy.context.scene.render.use_motion_blur = False
    bpy_stage.control_differs("moving smoke, motion blur off", cyc, K, SPP[1], SE_FLOOR)
