"""Deformation motion blur's export (docs/motion_blur.md, addon/export/motion.py): a shape key
animated over the shutter gives mesh["deform"], the corners' positions at the object's steps
placed by its matrix at the frame, checked here against the shape key's own linear
interpolation computed from the keyframes; no deform without motion (motion blur off,
Deformation off, a key that does not move); a vertex count that changes over the shutter
renders still with a warning naming the object (as Cycles)."""
import math

import bpy
import numpy as np
import pytest

from blender_helpers import add_camera, add_plane, diffuse_material


def export(addon):
    from lantern_blender.export import export_scene
    return export_scene(bpy.context.evaluated_depsgraph_get())


BUMP = 1.0  # the key lifts vertex 2 by 1 m (object space)


def _shape_keyed(scene, animate=True):
    """A 2 m plane, rotated 30 degrees about z, scaled 2 and lifted 1 m; its key 'Up' lifts
    one corner, its value 0 at frame 0 and 1 at frame 2 (linear), the scene at frame 1."""
    bpy.context.preferences.edit.keyframe_new_interpolation_type = "LINEAR"
    add_camera(scene, location=(0, 0, 8))
    plane = add_plane(scene, size=2.0, location=(0.3, 0.0, 1.0),
                      material=diffuse_material(0.8), name="Bender")
    plane.rotation_euler = (0, 0, math.radians(30))
    plane.scale = (2, 2, 2)
    plane.shape_key_add(name="Basis")
    key = plane.shape_key_add(name="Up")
    key.data[2].co.z += BUMP
    if animate:
        for frame, value in ((0, 0.0), (2, 1.0)):
            key.value = value
            key.keyframe_insert("value", frame=frame)
        from bpy_extras import anim_utils  # linear (shape keys' keys ignore the preference)
        ad = plane.data.shape_keys.animation_data
        for fc in anim_utils.action_get_channelbag_for_slot(ad.action, ad.action_slot).fcurves:
            for kp in fc.keyframe_points:
                kp.interpolation = "LINEAR"
    else:
        key.value = 0.5
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = 0.5
    scene.frame_set(1)
    return plane


def _expected(plane, mesh, value):
    """The corners' exported positions with key value `value`: the basis plus value times
    the key's offset, placed by the object's matrix at the frame (float64 here)."""
    basis = np.array([v.co for v in plane.data.vertices], np.float64)
    offset = np.zeros_like(basis)
    offset[2, 2] = BUMP
    local = basis + value * offset
    m = np.array(plane.matrix_world, np.float64)
    world = local @ m[:3, :3].T + m[:3, 3]
    # the exported corners: match each to its vertex by the frame's positions (value 0.5)
    at_frame = (basis + 0.5 * offset) @ m[:3, :3].T + m[:3, 3]
    p = np.asarray(mesh["positions"], np.float64)
    corner = np.argmin(((p[:, None, :] - at_frame[None]) ** 2).sum(-1), axis=1)
    assert np.allclose(p, at_frame[corner], atol=1e-5)
    return world[corner]


@pytest.mark.parametrize("position, values", [("CENTER", (0.375, 0.5, 0.625)),
                                              ("START", (0.5, 0.625, 0.75)),
                                              ("END", (0.25, 0.375, 0.5))])
def test_shape_key_deform_steps(empty, addon, position, values):
    plane = _shape_keyed(empty)
    empty.render.motion_blur_position = position
    scene, report = export(addon)
    (mesh,) = scene.meshes
    assert "motion" not in mesh  # the object itself does not move
    deform = np.asarray(mesh["deform"])
    assert deform.shape == (3, len(mesh["positions"]), 3) and deform.dtype == np.float32
    for k, value in enumerate(values):
        np.testing.assert_allclose(deform[k], _expected(plane, mesh, value), atol=2e-5)
    # the step at the frame is the exported positions, bit for bit (the same arithmetic)
    at_frame = values.index(0.5)
    assert np.array_equal(deform[at_frame], mesh["positions"])
    assert not np.array_equal(deform[0], deform[-1])  # (it can fail)
    assert empty.frame_current == 1 and empty.frame_subframe == 0.0
    assert not [m for m in report.messages if "deform" in m], report.messages


def test_motion_steps_give_more_deform_steps(empty, addon):
    plane = _shape_keyed(empty)
    plane.cycles.motion_steps = 2  # 5 steps
    plane.update_tag()  # (an add-on's property group set from Python tags nothing)
    scene, _ = export(addon)
    (mesh,) = scene.meshes
    deform = np.asarray(mesh["deform"])
    assert deform.shape[0] == 5
    for k, value in enumerate(np.linspace(0.375, 0.625, 5)):
        np.testing.assert_allclose(deform[k], _expected(plane, mesh, value), atol=2e-5)


@pytest.mark.parametrize("off", ["motion_blur", "deformation", "object_blur", "still_key"])
def test_no_deform_without_motion(empty, addon, off):
    plane = _shape_keyed(empty, animate=off != "still_key")
    if off == "motion_blur":
        empty.render.use_motion_blur = False
    elif off == "deformation":
        plane.cycles.use_deform_motion = False
    elif off == "object_blur":
        plane.cycles.use_motion_blur = False
    plane.update_tag()  # (an add-on's property group set from Python tags nothing)
    scene, report = export(addon)
    (mesh,) = scene.meshes
    assert mesh.get("deform") is None
    assert not [m for m in report.messages if "deform" in m], report.messages


def _growing_grid(scene):
    """A geometry-nodes grid whose vertex count follows the frame (3 + 4 x frame per side)."""
    ng = bpy.data.node_groups.new("Grow", "GeometryNodeTree")
    ng.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    ng.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    out = ng.nodes.new("NodeGroupOutput")
    ng.nodes.new("NodeGroupInput")
    grid = ng.nodes.new("GeometryNodeMeshGrid")
    time = ng.nodes.new("GeometryNodeInputSceneTime")
    mul = ng.nodes.new("ShaderNodeMath")
    mul.operation = "MULTIPLY_ADD"
    mul.inputs[1].default_value = 4.0
    mul.inputs[2].default_value = 3.0
    ng.links.new(time.outputs["Frame"], mul.inputs[0])
    ng.links.new(mul.outputs[0], grid.inputs["Vertices X"])
    ng.links.new(grid.outputs["Mesh"], out.inputs[0])
    plane = add_plane(scene, size=2.0, material=diffuse_material(0.8), name="Grower")
    plane.modifiers.new("Grow", "NODES").node_group = ng
    add_camera(scene, location=(0, 0, 5))
    scene.render.use_motion_blur = True
    scene.frame_set(1)
    return plane


def test_changing_vertex_count_renders_still_with_a_warning(empty, addon):
    _growing_grid(empty)
    scene, report = export(addon)
    (mesh,) = scene.meshes
    assert mesh.get("deform") is None
    hits = [m for m in report.messages if "vertex count changes" in m]
    assert len(hits) == 1 and "Object 'Grower'" in hits[0], report.messages
    # (the control: the same grid still over the shutter exports no warning)
    empty.render.use_motion_blur = False
    _, report = export(addon)
    assert not [m for m in report.messages if "vertex count" in m]


def test_changing_vertex_count_f12_is_finite(empty, tmp_path, errors):
    """Through F12: the growing grid renders (a finite image) with the warning, once."""
    from blender_helpers import render_exr
    _growing_grid(empty)
    empty.render.resolution_x, empty.render.resolution_y = 8, 8
    empty.lantern.samples = 1
    px = render_exr(empty, tmp_path)
    assert np.isfinite(px).all()
    hits = [m for kind, m in errors if kind == "WARNING" and "vertex count changes" in m]
    assert len(hits) == 1 and "Object 'Grower'" in hits[0], errors


def test_f12_renders_a_deforming_plane(empty, tmp_path, errors):
    """Through F12 (the engine's own frame_set): the shape-keyed plane renders deformed (the
    image differs from Deformation off) with no warning but auto's pt note."""
    from blender_helpers import render_exr
    plane = _shape_keyed(empty)
    sun = bpy.data.lights.new("Sun", "SUN")
    empty.collection.objects.link(bpy.data.objects.new("Sun", sun))
    empty.render.resolution_x, empty.render.resolution_y = 16, 16
    empty.lantern.samples = 16
    blurred = render_exr(empty, tmp_path, "deform.exr")
    plane.cycles.use_deform_motion = False
    plane.update_tag()
    still = render_exr(empty, tmp_path, "still.exr")
    assert np.isfinite(blurred).all()
    assert not np.array_equal(blurred, still)
    assert all("renders this scene with path tracing" in m or "which only pt renders" in m
               for kind, m in errors if kind == "WARNING"), errors
