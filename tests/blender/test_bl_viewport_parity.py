"""The viewport renders what F12 renders: the incremental sync (export/sync.py) walks the
instances with export_scene's own per-instance routine (export/walk.py), so its scene holds
what a fresh export of the same view holds: particle hair, holdouts, light linking, instancers
hidden. Each case: the synced scene's contents against a fresh
export_scene(region_view=ViewportView(ctx)), the viewport's own image against a render of the
fresh export (the same seed: the same bits), paired renders of the two scenes, a render of the
scene without the feature told apart (the negative control), then an edit where it matters:
what it tags and that the next sync picks it up without extracting meshes again.
Found by reading the code: before export/walk.py the sync skipped all four."""

import bpy
import bmesh
import numpy as np
import pytest

import lantern
from blender_helpers import diffuse_material
from test_bl_viewport_sync import (SEEDS, SPP, _apply, _changes, _fresh, _paired, _refined,
                                   _renders, _start, _told_apart, stage)  # noqa: F401

pytestmark = pytest.mark.skipif(not lantern.session.native_available(),
                                reason="lantern native module not built")

FLAGS = ("visible_camera", "cast_shadow", "visible_diffuse", "visible_glossy",
         "visible_transmission", "visible_volume_scatter", "light_set", "shadow_set",
         "shadow_catcher", "receivers", "blockers")


def _materials_of(scene, item):
    """(name, holdout) of the materials an item's triangles or strands use: material slots
    are numbered differently by a sync that kept its table, so compare what they hold."""
    ids = np.unique(np.asarray(item["material_ids"])).tolist()
    return sorted((scene.materials[i].get("name"), bool(scene.materials[i].get("holdout")))
                  for i in ids)


def _same_contents(got, want):
    """The synced scene `got` holds what the fresh export `want` holds."""
    assert [m["name"] for m in got.meshes] == [m["name"] for m in want.meshes]
    for a, b in zip(got.meshes, want.meshes):
        np.testing.assert_allclose(a["positions"], b["positions"], atol=1e-6)
        assert {f: a.get(f) for f in FLAGS} == {f: b.get(f) for f in FLAGS}, a["name"]
        assert _materials_of(got, a) == _materials_of(want, b), a["name"]
    assert len(got.lights) == len(want.lights)
    for a, b in zip(got.lights, want.lights):
        assert {f: a.get(f) for f in FLAGS} == {f: b.get(f) for f in FLAGS}, a.get("name")
    assert [c["name"] for c in got.curves] == [c["name"] for c in want.curves]
    for a, b in zip(got.curves, want.curves):
        np.testing.assert_allclose(a["points"], b["points"], atol=1e-6)
        np.testing.assert_allclose(a["radius"], b["radius"], atol=1e-7)
        assert _materials_of(got, a) == _materials_of(want, b)
        assert {f: a.get(f) for f in FLAGS} == {f: b.get(f) for f in FLAGS}
    assert got.attribute_channels == want.attribute_channels


def _agrees(state, stage, ctx, image=None):
    """Contents, the viewport's image (when given) and paired renders against a fresh export;
    returns the fresh export's renders (for a negative control)."""
    fresh = _fresh(stage, ctx, stage.lantern)
    _same_contents(state.sync.scene, fresh)
    if image is not None:  # the session the viewport built from its snapshot of the scene
        np.testing.assert_array_equal(
            image, lantern.render(fresh, spp=SPP, **stage.lantern.session_settings()))
    want = _renders(fresh, SEEDS)
    _paired("synced scene vs fresh export", _renders(state.sync.scene, SEEDS), want)
    return want


def _without(stage, ctx, fn):
    """Renders of a fresh export of the scene with `fn` applied (then undone by the caller)."""
    fn()
    bpy.context.view_layer.update()
    return _renders(_fresh(stage, ctx, stage.lantern), range(21, 26))


# ---- particle hair ----
def _hair_ball(scene):
    mesh = bpy.data.meshes.new("Ball")
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=12, v_segments=6, radius=0.4)
    bm.to_mesh(mesh)
    bm.free()
    obj = bpy.data.objects.new("Ball", mesh)
    scene.collection.objects.link(obj)
    obj.location = (-0.9, 0.3, 0.5)
    red = diffuse_material(0.1)
    red.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.9, 0.1, 0.05, 1)
    mesh.materials.append(red)
    mod = obj.modifiers.new("hair", "PARTICLE_SYSTEM")
    s = mod.particle_system.settings
    s.type, s.count, s.hair_length = "HAIR", 60, 0.6
    s.display_step = s.render_step = 2
    s.root_radius, s.tip_radius, s.radius_scale, s.use_close_tip = 1.0, 1.0, 0.06, False
    return obj, mod


def _curves(scene):
    """A Curves object (Blender's hair data): two strands of four points."""
    data = bpy.data.hair_curves.new("Hair")
    data.add_curves([4, 4])
    pos = [(0.6, 0.5, 0.0), (0.6, 0.5, 0.3), (0.7, 0.5, 0.6), (0.8, 0.5, 0.9),
           (0.9, 0.4, 0.0), (0.9, 0.4, 0.3), (1.0, 0.4, 0.6), (1.1, 0.4, 0.9)]
    data.attributes["position"].data.foreach_set("vector", np.ravel(pos).astype(np.float32))
    attr = data.attributes.get("radius") or data.attributes.new("radius", "FLOAT", "POINT")
    attr.data.foreach_set("value", np.full(8, 0.06, np.float32))
    obj = bpy.data.objects.new("Hair", data)
    scene.collection.objects.link(obj)
    return obj


def test_hair_in_the_viewport(addon, stage):
    ball, mod = _hair_ball(stage)
    hair = _curves(stage)
    bpy.context.view_layer.update()
    engine, ctx = _start(addon, stage)
    state = engine._lantern
    image = _refined(engine, addon, ctx)
    assert len(state.sync.scene.curves) == 2 and state.sync.counts["strands"] == 2
    want = _agrees(state, stage, ctx, image)
    assert _told_apart(_without(stage, ctx, lambda: setattr(mod, "show_viewport", False)), want)
    mod.show_viewport = True
    bpy.context.view_layer.update()
    from lantern_blender.export import changes as ch
    home = ball.location.copy()  # the emitter's hair is in world space: moving it tags
    assert _changes(lambda: setattr(ball, "location", (0.9, 0.25, 0.6))).has(ch.GEOMETRY)
    ball.location = home
    bpy.context.view_layer.update()
    _apply(addon, engine, ctx, lambda: setattr(ball, "location", (0.9, 0.25, 0.6)))
    counts = state.sync.counts  # the hair read again, the ball's mesh only extracted again
    assert counts["strands"] == 1 and counts["meshes_extracted"] == 1
    _agrees(state, stage, ctx)
    card = bpy.data.objects["Card"]  # another object moves: the hair is kept
    _apply(addon, engine, ctx, lambda: setattr(card, "location", (0.5, 0, 0.6)))
    counts = state.sync.counts
    assert counts["strands"] == 0 and counts["meshes_extracted"] == 0
    _same_contents(state.sync.scene, _fresh(stage, ctx, stage.lantern))
    # a Curves object moved (a transform edit): its strands read again, and the running
    # session, which moves meshes only, is replaced (the image: bit for bit a fresh render's)
    assert _changes(lambda: setattr(hair, "location", (-0.5, 0, 0))).flags == ch.TRANSFORM
    hair.location = (0, 0, 0)
    bpy.context.view_layer.update()
    session = state.session
    image = _apply(addon, engine, ctx, lambda: setattr(hair, "location", (-0.5, 0, 0)))
    assert state.sync.counts["strands"] == 1 and state.session is not session
    _agrees(state, stage, ctx, image)
    state.free()


# ---- holdouts ----
def test_holdout_in_the_viewport(addon, stage):
    card = bpy.data.objects["Card"]
    card.is_holdout = True
    bpy.context.view_layer.update()
    engine, ctx = _start(addon, stage)
    state = engine._lantern
    image = _refined(engine, addon, ctx)
    want = _agrees(state, stage, ctx, image)
    assert _told_apart(_without(stage, ctx, lambda: setattr(card, "is_holdout", False)), want)
    card.is_holdout = True
    bpy.context.view_layer.update()
    tables = len(state.sync.scene.materials)
    from lantern_blender.export import changes as ch
    for on in (False, True):  # a scene-level change: every instance walked, none extracted
        assert _changes(lambda: setattr(card, "is_holdout", on)).has(ch.SETTINGS)
        card.is_holdout = not on
        bpy.context.view_layer.update()
        _apply(addon, engine, ctx, lambda: setattr(card, "is_holdout", on))
        counts = state.sync.counts
        assert counts["meshes_extracted"] == 0 and counts["meshes_placed"] == 0
        _agrees(state, stage, ctx)
    # the reused placed meshes were not remapped twice: one holdout copy, made once
    assert len(state.sync.scene.materials) == tables
    # a material edit converts the holdout copy again too (indirect rays see its colour)
    mat = bpy.data.materials["CardMat"]
    _apply(addon, engine, ctx, lambda: setattr(
        mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"], "default_value",
        (0.1, 0.9, 0.1, 1)))
    assert state.sync.counts["materials"] == 1
    copies = [m for m in state.sync.scene.materials if m.get("name") == "CardMat (holdout)"]
    assert len(copies) == 1 and copies[0]["base_color"] == pytest.approx([0.1, 0.9, 0.1])
    _agrees(state, stage, ctx)
    state.free()


# ---- light linking ----
def _linked_lamp(scene):
    data = bpy.data.lights.new("Spot", "POINT")
    data.energy = 300.0
    data.shadow_soft_size = 0.2
    lamp = bpy.data.objects.new("Lamp", data)
    lamp.location = (0.0, -1.0, 2.0)
    scene.collection.objects.link(lamp)
    receivers = bpy.data.collections.new("Receivers")
    receivers.objects.link(bpy.data.objects["Card"])
    lamp.light_linking.receiver_collection = receivers
    return lamp, receivers


def test_light_linking_in_the_viewport(addon, stage):
    lamp, receivers = _linked_lamp(stage)
    bpy.context.view_layer.update()
    engine, ctx = _start(addon, stage)
    state = engine._lantern
    image = _refined(engine, addon, ctx)
    assert any("receivers" in light for light in state.sync.scene.lights)
    want = _agrees(state, stage, ctx, image)
    assert _told_apart(_without(
        stage, ctx, lambda: setattr(lamp.light_linking, "receiver_collection", None)), want)
    lamp.light_linking.receiver_collection = receivers
    bpy.context.view_layer.update()
    floor = bpy.data.objects["Floor"]
    from lantern_blender.export import changes as ch
    assert _changes(lambda: receivers.objects.link(floor)).has(ch.SETTINGS)
    receivers.objects.unlink(floor)
    bpy.context.view_layer.update()
    _apply(addon, engine, ctx, lambda: receivers.objects.link(floor))  # the floor lit too
    counts = state.sync.counts
    assert counts["meshes_extracted"] == 0 and counts["meshes_placed"] == 0
    _agrees(state, stage, ctx)
    # the sets live on each walk's copies: the placed meshes the sync keeps carry none
    assert not any("light_set" in m for _, m in state.sync._placed.values() if m is not None)
    state.free()


# ---- an instancer hidden ----
def test_hidden_instancer_in_the_viewport(addon, stage):
    """A particle emitter hidden (Object > Instancing > Show Instancer off): the depsgraph
    lists it with show_self False; its hair renders, its mesh does not. (A hidden face or
    vertex instancer is left out of the depsgraph's instances by Blender itself.)"""
    ball, _ = _hair_ball(stage)
    ball.show_instancer_for_viewport = ball.show_instancer_for_render = False
    bpy.context.view_layer.update()
    engine, ctx = _start(addon, stage)
    state = engine._lantern
    image = _refined(engine, addon, ctx)
    assert "Ball" not in [m["name"] for m in state.sync.scene.meshes]
    assert len(state.sync.scene.curves) == 1
    want = _agrees(state, stage, ctx, image)
    assert _told_apart(_without(stage, ctx, lambda: setattr(
        ball, "show_instancer_for_viewport", True)), want)
    ball.show_instancer_for_viewport = False
    bpy.context.view_layer.update()
    from lantern_blender.export import changes as ch
    assert _changes(lambda: setattr(ball, "show_instancer_for_viewport", True)).has(
        ch.GEOMETRY)
    ball.show_instancer_for_viewport = False
    bpy.context.view_layer.update()
    _apply(addon, engine, ctx, lambda: setattr(ball, "show_instancer_for_viewport", True))
    assert "Ball" in [m["name"] for m in state.sync.scene.meshes]
    _agrees(state, stage, ctx)
    state.free()


# ---- an object's own settings ----
def test_object_settings_in_the_viewport(addon, stage):
    """Ray visibility (and holdout, shadow catcher, Object Info colour and pass index): Blender
    tags an edit of these as a shading update of the object alone, as it tags the objects of
    an edited material (measured with bpy 5.0.1); the sync compares what the last walk read
    (walk.object_settings). Before, such an edit was not synced at all."""
    card = bpy.data.objects["Card"]
    nt = bpy.data.materials["CardMat"].node_tree
    info = nt.nodes.new("ShaderNodeObjectInfo")  # a per-object value the placed mesh carries
    nt.links.new(info.outputs["Color"], nt.nodes["Principled BSDF"].inputs["Base Color"])
    card.color = (0.9, 0.2, 0.1, 1)
    bpy.context.view_layer.update()
    engine, ctx = _start(addon, stage)
    state = engine._lantern
    _refined(engine, addon, ctx)
    before = _renders(_fresh(stage, ctx, stage.lantern), range(21, 26))
    from lantern_blender.export import changes as ch
    c = _changes(lambda: setattr(card, "color", (0.1, 0.3, 0.9, 1)))
    assert c.flags == 0 and c.objects == {"Card"}
    card.color = (0.9, 0.2, 0.1, 1)
    bpy.context.view_layer.update()
    _apply(addon, engine, ctx, lambda: setattr(card, "color", (0.1, 0.3, 0.9, 1)))
    counts = state.sync.counts  # placed again (its colour), not extracted
    assert counts["meshes_placed"] == 1 and counts["meshes_extracted"] == 0
    want = _agrees(state, stage, ctx)
    assert _told_apart(before, want)
    _apply(addon, engine, ctx, lambda: setattr(card, "visible_camera", False))
    counts = state.sync.counts  # walked: the flags of each walk's copies
    assert counts["meshes_placed"] == 0 and counts["meshes_extracted"] == 0
    assert _told_apart(want, _agrees(state, stage, ctx))
    # a setting no export reads (tagged the same way): the running session goes on
    session, syncs = state.session, state.sync.syncs
    _apply(addon, engine, ctx, lambda: setattr(card, "show_in_front", True))
    assert state.sync.syncs == syncs + 1 and state.session is session
    # and a material edit stays one (a node-graph material's: a new session, Session.
    # update_materials; before, the viewport failed on it)
    _apply(addon, engine, ctx, lambda: setattr(
        nt.nodes["Principled BSDF"].inputs["Roughness"], "default_value", 0.2))
    counts = state.sync.counts
    assert counts["materials"] == 1 and counts["meshes_placed"] == 0
    _agrees(state, stage, ctx)
    state.free()


# ---- warnings ----
def test_unsupported_warnings_in_the_viewport(addon, stage):
    """The viewport warns as F12 does (export/unsupported.py), once: a move walks every
    instance again, which does not repeat them."""
    cloud = bpy.data.objects.new("Cloud", bpy.data.pointclouds.new("Cloud"))
    stage.collection.objects.link(cloud)
    bpy.context.view_layer.update()
    engine, ctx = _start(addon, stage)
    state = engine._lantern
    _refined(engine, addon, ctx)
    from lantern_blender.export import export_scene
    from lantern_blender.export.camera import ViewportView
    _, report = export_scene(bpy.context.evaluated_depsgraph_get(), region_view=ViewportView(ctx))
    cloud_warning = "Object 'Cloud': point clouds are not rendered"
    assert cloud_warning in report.messages
    shown = [m for _, m in engine.reports]
    assert shown == [f"Lantern: {m}" for m in report.messages]
    card = bpy.data.objects["Card"]
    _apply(addon, engine, ctx, lambda: setattr(card, "location", (0.4, 0, 0.5)))
    assert state.sync.counts["meshes_placed"] == 1
    assert [m for _, m in engine.reports] == shown  # not again
    state.free()
