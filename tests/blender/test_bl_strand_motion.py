"""Hair under motion blur, the export (addon/export/motion.py, docs/motion_blur.md "Strands"):
particle hair on a sphere and a Curves object, each sliding along x with linear keys, export
curves["deform"], their points at the shutter's steps (3 with Motion Steps 1, 5 with 2), each
step the frame's points moved by the object's translation at that step, computed here from the
keys; no steps with Render > Motion Blur or the object's Motion Blur off, or when it does not
move; a strand or key count that changes over the shutter leaves the strands still with a
warning naming the object (write_strand_steps). The same objects turning export the object's
matrices at the steps instead ("Strands of a turning object"), their points as at the frame."""

import bpy
import numpy as np
import pytest

from blender_helpers import add_camera


def _export():
    from lantern_blender.export import export_scene
    return export_scene(bpy.context.evaluated_depsgraph_get())


def _linear(obj):
    from bpy_extras import anim_utils
    ad = obj.animation_data
    for fc in anim_utils.action_get_channelbag_for_slot(ad.action, ad.action_slot).fcurves:
        for kp in fc.keyframe_points:
            kp.interpolation = "LINEAR"


def _slide(obj):
    for frame, x in ((0, -1.0), (2, 1.0)):  # 1 m a frame
        obj.location[0] = x
        obj.keyframe_insert("location", index=0, frame=frame)
    _linear(obj)


def _furry_ball(scene):
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, segments=16, ring_count=8)
    ball = bpy.context.active_object
    ps = ball.modifiers.new("Fur", "PARTICLE_SYSTEM").particle_system.settings
    ps.type, ps.count, ps.hair_length, ps.child_type = "HAIR", 50, 0.3, "NONE"
    ps.render_step = ps.display_step = 2
    return ball


def _hair_curves(scene):
    data = bpy.data.hair_curves.new("Hair")
    data.add_curves([4] * 5)
    pts = np.random.default_rng(1).uniform(-0.5, 0.5, (20, 3)).astype(np.float32)
    data.attributes["position"].data.foreach_set("vector", pts.ravel())
    obj = bpy.data.objects.new("Hair", data)
    scene.collection.objects.link(obj)
    return obj


@pytest.mark.parametrize("kind,steps", [("particles", 1), ("particles", 2), ("curves", 1)])
def test_sliding_hair_exports_its_steps(empty, kind, steps):
    scene = empty
    add_camera(scene)
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = 0.5
    obj = _furry_ball(scene) if kind == "particles" else _hair_curves(scene)
    obj.cycles.motion_steps = steps
    _slide(obj)
    scene.frame_set(1)
    sc, report = _export()
    assert len(sc.curves) == 1, report.messages
    c = sc.curves[0]
    n = 2 * steps + 1 if steps < 2 else 5
    assert c["deform"].shape == (n,) + c["points"].shape and c["deform"].dtype == np.float32
    assert "deform_radius" not in c  # a slide keeps the radii
    assert "motion" not in c  # a slide keeps its world points (exact: the same bits as before)
    for k, off in enumerate(np.linspace(-0.25, 0.25, n)):  # 1 m a frame x 0.5 frame
        moved = c["deform"][k] - c["points"]
        np.testing.assert_allclose(moved[:, 0], off, atol=2e-5)
        np.testing.assert_allclose(moved[:, 1:], 0.0, atol=2e-5)
    # Render > Motion Blur off, the object's off: no steps
    scene.render.use_motion_blur = False
    assert "deform" not in _export()[0].curves[0]
    scene.render.use_motion_blur = True
    obj.cycles.use_motion_blur = False
    obj.update_tag()  # (an add-on's property group set from Python tags nothing)
    assert "deform" not in _export()[0].curves[0]


def _turn(obj):
    for frame, a in ((0, -np.pi), (2, np.pi)):  # half a turn a frame about z
        obj.rotation_euler[2] = a
        obj.keyframe_insert("rotation_euler", index=2, frame=frame)
    _linear(obj)


@pytest.mark.parametrize("kind", ["particles", "curves"])
def test_turning_hair_exports_its_matrices(empty, kind):
    """docs/motion_blur.md "Strands of a turning object": the object's matrices at the steps
    (a quarter turn over the shutter, computed here from the keys), the points as exported at
    the frame, no deform (a rigid turn)."""
    scene = empty
    add_camera(scene)
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = 0.5
    obj = _furry_ball(scene) if kind == "particles" else _hair_curves(scene)
    _turn(obj)
    scene.frame_set(1)
    sc, report = _export()
    assert len(sc.curves) == 1, report.messages
    c = sc.curves[0]
    assert "deform" not in c and "deform_radius" not in c
    motion = np.asarray(c["motion"])
    assert motion.shape == (3, 4, 4)
    for m, a in zip(motion, np.linspace(-0.25, 0.25, 3) * np.pi):
        want = np.eye(4)
        want[:2, :2] = [[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]
        np.testing.assert_allclose(m, want, atol=1e-5)
    np.testing.assert_allclose(np.asarray(c["motion_base"]), np.eye(4), atol=1e-5)
    scene.render.use_motion_blur = False  # (the test can fail: no steps without motion blur)
    assert "motion" not in _export()[0].curves[0]


def test_still_hair_has_no_steps(empty):
    add_camera(empty)
    empty.render.use_motion_blur = True
    _furry_ball(empty)
    empty.frame_set(1)
    assert "deform" not in _export()[0].curves[0]


def test_changing_counts_warn_and_stay_still(addon):
    from lantern_blender.export.motion import write_strand_steps

    class Report:
        messages = []

        def warn(self, m):
            self.messages.append(m)

    def strand_set(n, dx=0.0):
        pts = np.zeros((3 * n, 3), np.float32)
        pts[:, 0] = dx
        return {"points": pts, "radius": np.full(3 * n, 0.01, np.float32),
                "offsets": np.arange(n + 1, dtype=np.uint32) * 3}
    frame = strand_set(4)
    r = Report()
    write_strand_steps("Fur", [frame], [[strand_set(4, -1)], [strand_set(3)], [strand_set(4, 1)]],
                       r)
    assert "deform" not in frame
    assert len(r.messages) == 1 and "Object 'Fur'" in r.messages[0] and \
        "count changes over the shutter" in r.messages[0], r.messages
    write_strand_steps("Fur", [frame], [[strand_set(4, -1)], [strand_set(4)], [strand_set(4, 1)]],
                       r)
    assert frame["deform"].shape == (3, 12, 3) and len(r.messages) == 1
