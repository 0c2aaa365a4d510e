"""Hair export (addon/export/curves.py) against Blender's own data: Curves objects (positions,
radius attribute or Cycles' 0.005, material_index, the object transform), particle hair
(co_hair keys, 2^render_step + 1 per strand, radii from root/tip/shape/Close Tip computed here
from the exported points' arc length, children replacing parents), bad radii and the memory
budget: what export/strands.py hands to the scene (the render: tests/cycles/test_hair.py)."""

import bpy
import numpy as np
import pytest

from blender_helpers import empty_scene


@pytest.fixture
def curves_mod(addon):
    from lantern_blender.export import curves
    return curves


class Report:
    def __init__(self):
        self.messages = []

    def warn(self, m):
        self.messages.append(m)


def _curves_object(scene, points_per_curve, positions, radius=None, material_index=None):
    data = bpy.data.hair_curves.new("Hair")
    data.add_curves(points_per_curve)
    flat = np.asarray(positions, np.float32).ravel()
    data.attributes["position"].data.foreach_set("vector", flat)
    if radius is not None:
        attr = data.attributes.get("radius") or data.attributes.new("radius", "FLOAT", "POINT")
        attr.data.foreach_set("value", np.asarray(radius, np.float32))
    if material_index is not None:
        attr = data.attributes.new("material_index", "INT", "CURVE")
        attr.data.foreach_set("value", np.asarray(material_index, np.int32))
    obj = bpy.data.objects.new("Hair", data)
    scene.collection.objects.link(obj)
    return obj


def _evaluated(obj):
    dg = bpy.context.evaluated_depsgraph_get()
    return obj.evaluated_get(dg)


def test_curves_object(curves_mod):
    scene = empty_scene()
    pos = np.array([[0, 0, 0], [0, 0, 1], [0, 0, 2],
                    [1, 0, 0], [1, 0, 1], [1, 1, 1], [1, 1, 2]], np.float64)
    rad = np.array([0.1, 0.05, 0.02, 0.3, 0.2, 0.1, 0.0])
    obj = _curves_object(scene, [3, 4], pos, rad, material_index=[0, 1])
    obj.location = (0.5, -1.0, 2.0)
    obj.scale = (2.0, 2.0, 2.0)
    ev = _evaluated(obj)
    report = Report()
    st = curves_mod.curves_object_strands(ev, ev.matrix_world, report)
    assert report.messages == []
    np.testing.assert_array_equal(st.offsets, [0, 3, 7])
    np.testing.assert_allclose(st.points, pos * 2.0 + [0.5, -1.0, 2.0], atol=1e-6)
    np.testing.assert_allclose(st.radius, rad * 2.0, atol=1e-7)
    np.testing.assert_array_equal(st.material, [0, 1])


def test_curves_default_radius(curves_mod):
    scene = empty_scene()
    obj = _curves_object(scene, [2], [[0, 0, 0], [0, 0, 1]])
    ev = _evaluated(obj)
    if ev.data.attributes.get("radius") is not None:
        ev.data.attributes.remove(ev.data.attributes["radius"])
    assert ev.data.attributes.get("radius") is None  # the case under test: no radius at all
    st = curves_mod.curves_object_strands(ev, ev.matrix_world, Report())
    np.testing.assert_allclose(st.radius, [0.005, 0.005])


def test_curves_bad_radii(curves_mod):
    scene = empty_scene()
    pos = np.zeros((8, 3))
    pos[:, 2] = np.arange(8)
    rad = np.array([0.1, np.nan, 0.0, 0.0, 0.1, 0.1, -1.0, 0.1])
    obj = _curves_object(scene, [2, 2, 2, 2], pos, rad)
    ev = _evaluated(obj)
    report = Report()
    st = curves_mod.curves_object_strands(ev, ev.matrix_world, report)
    # NaN (strand 0) and negative (strand 3) dropped with a message; all-zero (strand 1) silently
    assert st.num_strands == 1
    np.testing.assert_allclose(st.radius, [0.1, 0.1])
    assert np.isfinite(st.points).all()
    assert len(report.messages) == 1 and "2 of 4 strands" in report.messages[0]


def _hair_sphere(scene, count=10, children=0, close_tip=True, shape=0.0, tip=0.0):
    mesh = bpy.data.meshes.new("Ball")
    import bmesh
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=16, v_segments=8, radius=1.0)
    bm.to_mesh(mesh)
    bm.free()
    obj = bpy.data.objects.new("Ball", mesh)
    scene.collection.objects.link(obj)
    obj.location = (0.0, 0.0, 0.5)
    mod = obj.modifiers.new("hair", "PARTICLE_SYSTEM")
    s = mod.particle_system.settings
    s.type = "HAIR"
    s.count = count
    s.hair_length = 0.4
    s.render_step = 3
    s.root_radius, s.tip_radius, s.radius_scale = 1.0, tip, 0.02
    s.shape, s.use_close_tip = shape, close_tip
    if children:
        s.child_type = "INTERPOLATED"
        s.rendered_child_count = children
        s.child_percent = children
    return obj


def test_particle_hair_keys_and_radii(curves_mod):
    scene = empty_scene()
    obj = _hair_sphere(scene, count=10, close_tip=False, shape=0.5, tip=0.25)
    # the viewport depsgraph's cache holds the Viewport Steps' keys (Blender's default 2: its
    # keys 5-8 read (0, 0, 0), which this test compared equal before difftest3)
    obj.particle_systems[0].settings.display_step = 3
    ev = _evaluated(obj)
    psys = ev.particle_systems[0]
    report = Report()
    st = curves_mod.particle_hair_strands(ev, psys, ev.matrix_world, report)
    assert report.messages == []
    assert np.linalg.norm(st.points - [0.0, 0.0, 0.5], axis=1).min() > 0.9   # none at 0
    assert st.num_strands == 10
    np.testing.assert_array_equal(np.diff(st.offsets), 9)  # 2^3 + 1 keys
    for p in (0, 7):
        for k in (0, 4, 8):
            np.testing.assert_allclose(st.points[9 * p + k], psys.co_hair(ev, particle_no=p,
                                                                          step=k), atol=1e-6)
    # radius: r = (1 - t)^(1 / (1 - shape)) (root - tip) + tip, root/tip times radius_scale / 2
    seg = np.linalg.norm(np.diff(st.points[:9].astype(np.float64), axis=0), axis=1)
    t = np.concatenate([[0.0], np.cumsum(seg)]) / seg.sum()
    expect = (1 - t) ** 2.0 * (0.01 - 0.0025) + 0.0025
    np.testing.assert_allclose(st.radius[:9], expect, rtol=1e-5)
    assert st.radius[0] == pytest.approx(0.01) and st.radius[8] == pytest.approx(0.0025)


def test_particle_hair_close_tip_and_children(curves_mod):
    scene = empty_scene()
    obj = _hair_sphere(scene, count=6, children=4)
    ev = _evaluated(obj)
    psys = ev.particle_systems[0]
    st = curves_mod.particle_hair_strands(ev, psys, ev.matrix_world, Report())
    assert len(psys.child_particles) == 24
    assert st.num_strands == 24  # children only, as Cycles renders them
    np.testing.assert_allclose(st.points[0], psys.co_hair(ev, particle_no=6, step=0), atol=1e-6)
    assert (st.radius[st.offsets[1:] - 1] == 0.0).all()       # Close Tip
    np.testing.assert_allclose(st.radius[st.offsets[:-1]], 0.01, rtol=1e-6)
    # the whole object: one set, the modifier shown for render
    assert len(curves_mod.object_strands(ev, ev.matrix_world, Report())) == 1
    obj.modifiers["hair"].show_render = False
    ev = _evaluated(obj)
    assert curves_mod.object_strands(ev, ev.matrix_world, Report()) == []


def test_memory_budget_checked_first(curves_mod):
    scene = empty_scene()
    obj = _hair_sphere(scene, count=1000, children=100)
    ev = _evaluated(obj)
    psys = ev.particle_systems[0]
    report = Report()
    n, steps, _ = curves_mod.particle_strand_counts(psys)
    assert n == 100000 and steps == 9
    need = curves_mod.strand_bytes(n, n * steps)
    assert curves_mod.particle_hair_strands(ev, psys, ev.matrix_world, report,
                                            budget=need - 1) is None
    assert len(report.messages) == 1 and "100000 strands" in report.messages[0]


def test_particle_hair_follows_the_instance(curves_mod):
    """co_hair is in the object's own placement; an instance elsewhere moves and scales it."""
    from mathutils import Matrix
    scene = empty_scene()
    obj = _hair_sphere(scene, count=5, close_tip=False)
    ev = _evaluated(obj)
    psys = ev.particle_systems[0]
    own = curves_mod.particle_hair_strands(ev, psys, ev.matrix_world, Report())
    inst = Matrix.Translation((3.0, 0.0, 0.0)) @ Matrix.Scale(2.0, 4) @ ev.matrix_world.inverted()
    moved = curves_mod.particle_hair_strands(ev, psys, inst @ ev.matrix_world, Report())
    expect = (own.points - np.array(ev.matrix_world.translation)) * 2.0 + [3.0, 0.0, 0.0]
    np.testing.assert_allclose(moved.points, expect, atol=1e-5)
    np.testing.assert_allclose(moved.radius, own.radius * 2.0, rtol=1e-6)


def test_catmull_rom_pieces(curves_mod):
    """Through the keys; straight evenly spaced keys stay straight and evenly spaced; keys on a
    circle give pieces on it within the spline's own error (here < 1e-3 of the radius); the
    negative control, linear pieces between the same keys, is off the circle by far more."""
    S = curves_mod.Strands
    line = np.stack([np.zeros(5), np.zeros(5), np.arange(5.0)], axis=1)
    st = S(line.astype(np.float32), np.linspace(0.1, 0.02, 5).astype(np.float32),
           np.array([0, 5], np.int32), np.zeros(1, np.int32))
    out = curves_mod.catmull_rom_pieces(st, 4)
    assert out.offsets.tolist() == [0, 17]
    np.testing.assert_allclose(out.points[::4], line, atol=1e-6)            # through the keys
    np.testing.assert_allclose(out.points[4:13, 2], np.arange(4, 13) / 4.0, atol=1e-6)
    np.testing.assert_allclose(out.radius[::4], st.radius, atol=1e-7)
    a = np.linspace(0.0, np.pi, 13)
    arc = np.stack([np.cos(a), np.sin(a), np.zeros_like(a)], axis=1)
    st = S(arc.astype(np.float32), np.full(13, 0.01, np.float32), np.array([0, 13], np.int32),
           np.zeros(1, np.int32))
    out = curves_mod.catmull_rom_pieces(st, 8)
    inner = out.points[8:-8].astype(np.float64)   # away from the repeated end keys
    err = np.abs(np.linalg.norm(inner, axis=1) - 1.0).max()
    assert err < 1e-3
    mids = 0.5 * (arc[1:] + arc[:-1])
    assert np.abs(np.linalg.norm(mids, axis=1) - 1.0).max() > 10 * err


def test_viewport_depsgraph_keys(curves_mod, addon):
    """A viewport depsgraph's hair holds Viewport Steps' keys (2^display_step + 1), not the
    Render Steps' that a final export counts: the export reads the keys the cache has and names
    the difference (difftest3's hand-made scene: Blender's defaults, display 2, render 3, ran
    every strand's last four keys to the world's origin, (0, 0, 0) from co_hair; Lantern 19 %
    darker than Cycles in the fur's blocks). Equal steps: no warning, 9 keys."""
    from lantern_blender.export import export_scene
    scene = empty_scene()
    obj = _hair_sphere(scene, count=10)
    s = obj.particle_systems[0].settings
    s.display_step = 2
    ev = _evaluated(obj)
    report = Report()
    st = curves_mod.particle_hair_strands(ev, ev.particle_systems[0], ev.matrix_world, report,
                                          viewport_cache=True)
    np.testing.assert_array_equal(np.diff(st.offsets), 5)   # 2^2 + 1 keys
    assert np.linalg.norm(st.points - [0.0, 0.0, 0.5], axis=1).min() > 0.9   # none at 0
    assert len(report.messages) == 1 and "Viewport Steps (2)" in report.messages[0]
    _, rep = export_scene(bpy.context.evaluated_depsgraph_get())
    assert any("Viewport Steps (2)" in m for m in rep.messages), rep.messages
    s.display_step = 3
    _, rep = export_scene(bpy.context.evaluated_depsgraph_get())
    assert not any("Viewport Steps" in m for m in rep.messages), rep.messages


def test_see_through_strands_warned(addon):
    """Strands are opaque in Lantern (the alpha test is the triangles'): a hair material with
    a Transparent BSDF in a mix, or Alpha below 1, is named (difftest D39: a Mix of Emission
    and Transparent rendered 1.89x Cycles); an opaque one and a mesh with the same material
    are not."""
    from lantern_blender.export import export_scene
    scene = empty_scene()
    obj = _curves_object(scene, [3], [[0, 0, 0], [0, 0, 0.5], [0, 0, 1]], radius=[0.01] * 3)
    mat = bpy.data.materials.new("veil")
    nt = mat.node_tree
    for n in list(nt.nodes):
        nt.nodes.remove(n)
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    mix = nt.nodes.new("ShaderNodeMixShader")
    nt.links.new(nt.nodes.new("ShaderNodeEmission").outputs[0], mix.inputs[1])
    transparent = nt.nodes.new("ShaderNodeBsdfTransparent")
    nt.links.new(transparent.outputs[0], mix.inputs[2])
    nt.links.new(mix.outputs[0], out.inputs["Surface"])
    obj.data.materials.append(mat)

    def warned():
        _, report = export_scene(bpy.context.evaluated_depsgraph_get())
        return [m for m in report.messages if "partly transparent" in m]
    assert len(warned()) == 1 and "'veil'" in warned()[0]
    nt.links.remove(transparent.outputs[0].links[0])
    nt.links.new(nt.nodes.new("ShaderNodeBsdfDiffuse").outputs[0], mix.inputs[2])
    assert warned() == []
    bpy.data.objects.remove(obj)
    bpy.ops.mesh.primitive_plane_add()
    bpy.context.object.data.materials.append(mat)
    nt.links.new(transparent.outputs[0], mix.inputs[2])
    assert warned() == []


def test_strand_attributes_warned(addon):
    """Strands carry no vertex attributes (Generated, Object coordinates, colours): a hair
    material whose graph reads one, here a Noise's implicit Generated vector, is named (difftest
    D44: a ridged Noise on a Curves object read black in Lantern); the Noise at the Geometry
    Position and a mesh with the same material are not."""
    from lantern_blender.export import export_scene
    scene = empty_scene()
    obj = _curves_object(scene, [3], [[0, 0, 0], [0, 0, 0.5], [0, 0, 1]], radius=[0.01] * 3)
    mat = bpy.data.materials.new("speckle")
    nt = mat.node_tree
    for n in list(nt.nodes):
        nt.nodes.remove(n)
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    em = nt.nodes.new("ShaderNodeEmission")
    noise = nt.nodes.new("ShaderNodeTexNoise")
    nt.links.new(noise.outputs["Fac"], em.inputs["Strength"])
    nt.links.new(em.outputs[0], out.inputs["Surface"])
    obj.data.materials.append(mat)

    def warned():
        _, report = export_scene(bpy.context.evaluated_depsgraph_get())
        return [m for m in report.messages if "strands do not carry" in m]
    got = warned()
    assert len(got) == 1 and "'speckle'" in got[0] and "'generated'" in got[0], got
    pos = nt.nodes.new("ShaderNodeNewGeometry")
    nt.links.new(pos.outputs["Position"], noise.inputs["Vector"])
    assert warned() == []
    nt.links.remove(noise.inputs["Vector"].links[0])
    bpy.data.objects.remove(obj)
    bpy.ops.mesh.primitive_plane_add()
    bpy.context.object.data.materials.append(mat)
    assert warned() == []


def test_strands_take_their_objects_ray_visibility(addon):
    """Cycles syncs particle hair as a second object of its emitter with the emitter's ray
    visibility, and a Curves object with its own (difftest D58): the strand sets carry the
    kinds that are off, as a mesh does (export/visibility.py), and none where all are on."""
    from lantern_blender.export import export_scene
    scene = empty_scene()
    ball = _hair_sphere(scene, count=4)
    hair = _curves_object(scene, [3], [[0, 0, 0], [0, 0, 0.5], [0, 0, 1]], radius=[0.01] * 3)

    def exported():
        out, _ = export_scene(bpy.context.evaluated_depsgraph_get())
        return {c["name"].split("/")[0]: c for c in out.curves}, \
            {m["name"]: m for m in out.meshes}
    curves, _ = exported()
    for c in curves.values():
        assert not any(k in c for k in ("visible_diffuse", "visible_glossy",
                                        "visible_transmission", "visible_volume_scatter"))
    ball.visible_diffuse = ball.visible_glossy = False
    hair.visible_transmission = False
    curves, meshes = exported()
    assert curves["Ball"]["visible_diffuse"] is False and curves["Ball"]["visible_glossy"] is False
    assert "visible_transmission" not in curves["Ball"]
    assert meshes["Ball"]["visible_diffuse"] is False
    assert curves["Hair"]["visible_transmission"] is False
    assert "visible_diffuse" not in curves["Hair"]
