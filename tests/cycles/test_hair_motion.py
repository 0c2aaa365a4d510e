"""Hair under motion blur against Cycles through the add-on (docs/motion_blur.md "Strands",
docs/curves.md): a sphere with particle hair (300 strands, 9 keys, Principled Hair, Cycles'
Linear 3D Curves shape) sliding 1 m a frame along x (linear keys) under a 0.5-frame shutter
centred on the frame, 3 steps: the add-on exports the ball's matrices and the fur's points at
the steps, the core lerps them per ray. K seeds of each renderer (Cycles' stored as per-seed
block means, tools/render_compare.py stored_cycles), lantern.metrics.assert_agreement with its
negative controls (2 % on the image, 10 % on a block), and controls of its own kind: Lantern
with Render > Motion Blur off (the sharp furry ball at the frame), and with the fur's steps
taken out of the export (the ball blurred, its fur sharp at the frame), must not agree with
Cycles' blurred one. Long (bench/long_tests.sh): about a minute of Lantern renders; Cycles' are stored.
Measured numbers: docs/motion_blur.md "Strands"."""

import os
import sys

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402
from bpy_stage import camera as _camera, light as _light  # noqa: E402
from mesh_canon import canonical_faces  # noqa: E402

K = 8
SIZE = 32
SPP = (256, 256)  # (Cycles', Lantern's) per seed
SE_FLOOR = 1e-6


def _principled(name, color, roughness=0.5):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    p = m.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (*color, 1.0)
    p.inputs["Roughness"].default_value = roughness
    return m


def _hair_material(name, melanin):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    h = nt.nodes.new("ShaderNodeBsdfHairPrincipled")
    h.parametrization = "MELANIN"
    h.inputs["Melanin"].default_value = melanin
    nt.links.new(h.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    return m


def sliding_fur():
    scene = bpy_stage.reset(SIZE, world=(0.1, 0.1, 0.12))
    scene.cycles_curves.shape = "THICK_LINEAR"
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = 0.5
    scene.render.motion_blur_position = "CENTER"
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(0, 0, 0), segments=32,
                                         ring_count=16)
    ball = bpy.context.active_object
    canonical_faces(ball)  # the same fur in every process (mesh_canon.py)
    ball.data.materials.append(_principled("skin", (0.6, 0.6, 0.6)))
    ball.data.materials.append(_hair_material("fur", 0.3))
    mod = ball.modifiers.new("Fur", "PARTICLE_SYSTEM")
    ps = mod.particle_system.settings
    ps.type = "HAIR"
    ps.count = 300
    ps.hair_length = 0.35
    ps.render_step = ps.display_step = 3  # 9 keys (the export reads the evaluated cache)
    ps.material = 2
    ps.root_radius, ps.tip_radius, ps.radius_scale = 1.0, 0.3, 0.02
    ps.child_type = "NONE"
    for frame, x in ((0, -1.0), (2, 1.0)):  # 1 m a frame: 0.5 m over the shutter
        ball.location[0] = x
        ball.keyframe_insert("location", index=0, frame=frame)
    from bpy_extras import anim_utils  # linear keys (the preference is not read here)
    ad = ball.animation_data
    for fc in anim_utils.action_get_channelbag_for_slot(ad.action, ad.action_slot).fcurves:
        for kp in fc.keyframe_points:
            kp.interpolation = "LINEAR"
    _light(scene, "AREA", (1.5, -1.5, 2.0), 300.0, rotation=(45, 0, 45), size=1.0)
    _camera(scene, (0, -3.0, 0.3), (84, 0, 0), lens=40.0)
    scene.frame_set(1)


@pytest.mark.long
def test_sliding_fur_matches_cycles():
    cyc = bpy_stage.compare_with_cycles("sliding fur, motion blur", sliding_fur, SPP,
                                        (0.02, 0.10), cycles_seed0=1400, k_seeds=K,
                                        se_floor=SE_FLOOR)
    # the fur's steps taken out: the ball slides, its hair stays at the frame
    import lantern
    import numpy as np
    import render_compare as rc
    from lantern import metrics
    scene = rc.export_current()
    assert scene.curves and scene.curves[0].get("deform") is not None
    scene.curves[0].pop("deform")
    still = []
    for k in range(K):
        s = lantern.Session(scene, integrator="pt", backend="cpu",
                            max_depth=rc.lantern_depth(rc.BOUNCES), seed=1 + k,
                            spp_per_iteration=SPP[1])
        s.step()
        still.append(np.asarray(s.image(), np.float64)[..., :3])
    ctl = metrics.compare_renders(np.stack(still), cyc, block=rc.BLOCK, se_floor=SE_FLOOR,
                                  name="fur still")
    print(f"control: sliding fur, the fur's steps taken out: {ctl}")
    assert not ctl.passed, f"the still fur passed against Cycles' sliding fur: {ctl}"
    bpy.context.scene.render.use_motion_blur = False
    bpy_stage.control_differs("sliding fur, motion blur off", cyc, K, SPP[1], SE_FLOOR)
