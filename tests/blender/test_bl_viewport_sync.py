"""Incremental viewport updates: what an edit tags (export/changes.py), what the next sync
exports again (export/sync.py), and that the viewport then renders what a fresh export of the
edited scene renders (bit for bit where the session is only re-aimed, statistically after a
scene edit). Edits reach view_update as in Blender: through the depsgraph's updates, read in a
depsgraph_update_post handler."""

from types import SimpleNamespace

import bpy
import numpy as np
import pytest

import lantern
from lantern import metrics
from blender_helpers import add_camera, add_plane, diffuse_material

pytestmark = pytest.mark.skipif(not lantern.session.native_available(),
                                reason="lantern native module not built")

SPP = 8
SEEDS = range(1, 9)     # paired comparisons (_paired): 8 seeds (the pairs are the same bits
MOVE_SEEDS = range(1, 6)  # today; the viewport sessions of MOVE_SEEDS cost ~0.3 s each)


class _Engine:
    def __init__(self, addon):
        self._lantern = addon.engine.EngineState()
        self.reports = []

    def report(self, kind, message):
        self.reports.append((kind, message))

    def tag_redraw(self):
        pass


class _Draw:
    def update(self, image, serial):
        pass

    def draw(self, *args):
        pass


def _context(scene, view_matrix, size=(32, 24)):
    cam = scene.camera
    window = cam.calc_matrix_camera(bpy.context.evaluated_depsgraph_get(), x=size[0], y=size[1])
    return SimpleNamespace(scene=scene, region=SimpleNamespace(width=size[0], height=size[1]),
                           region_data=SimpleNamespace(view_matrix=view_matrix,
                                                       window_matrix=window,
                                                       is_perspective=True))


def _edit(fn, on_updates):
    """Apply `fn`, then let the depsgraph evaluate: `on_updates(depsgraph)` sees its updates."""
    def handler(scene, depsgraph):
        on_updates(depsgraph)
    bpy.app.handlers.depsgraph_update_post.append(handler)
    try:
        fn()
        bpy.context.view_layer.update()
    finally:
        bpy.app.handlers.depsgraph_update_post.remove(handler)


@pytest.fixture
def stage(empty):
    empty.render.resolution_x, empty.render.resolution_y = 32, 24
    add_camera(empty, location=(0, -4, 3), rotation=(0.93, 0, 0))
    add_plane(empty, size=6.0, material=diffuse_material(0.8), name="Floor")
    box = add_plane(empty, size=1.0, location=(0, 0, 0.5), name="Card")
    box.data.materials.append(diffuse_material(0.5))
    box.data.materials[0].name = "CardMat"
    world = bpy.data.worlds.new("Sky")
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.6, 0.6, 0.6, 1)
    empty.world = world
    empty.lantern.preview_samples = SPP
    empty.lantern.backend = "cpu"
    # the sync's invariants (an update gives the bits of a fresh render) are the integrator's
    # own; "auto", the default, keeps its choice across a camera move (no new pilot at every
    # move: test_auto_keeps_its_choice_across_a_camera_move), which a fresh render makes anew
    empty.lantern.integrator = "pt"
    bpy.context.view_layer.update()
    return empty


def _changes(fn):
    from lantern_blender.export.changes import classify
    got = []
    _edit(fn, lambda dg: got.append(classify(dg.updates)))
    return got[-1]


def test_edits_are_classified(stage):
    from lantern_blender.export import changes as ch
    card = bpy.data.objects["Card"]
    mat = bpy.data.materials["CardMat"]
    c = _changes(lambda: setattr(card, "location", (0.5, 0, 0.5)))
    assert c.flags == ch.TRANSFORM
    c = _changes(lambda: setattr(mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"],
                                 "default_value", (0.9, 0.1, 0.1, 1)))
    assert c.flags == ch.MATERIALS and c.materials == {"CardMat"}
    c = _changes(lambda: setattr(stage.world.node_tree.nodes["Background"].inputs["Color"],
                                 "default_value", (0.2, 0.3, 0.9, 1)))
    assert c.flags == ch.WORLD

    def bend():
        card.data.vertices[0].co.z += 0.3
        card.data.update()
    c = _changes(bend)
    assert c.has(ch.GEOMETRY) and c.geometry == {"Card"} and not c.has(ch.FULL)
    c = _changes(lambda: setattr(stage.camera, "location", (0.3, -4, 3)))
    assert c.flags == ch.VIEW
    c = _changes(lambda: card.hide_set(True))
    assert c.has(ch.SETTINGS) and not c.has(ch.FULL)
    assert ch.classify([]).has(ch.FULL)


def _start(addon, stage):
    engine = _Engine(addon)
    engine._lantern.draw = _Draw()
    view = stage.camera.matrix_world.inverted()
    ctx = _context(stage, view)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    addon.engine.view_update(engine, ctx, depsgraph)
    addon.engine.view_draw(engine, ctx, depsgraph)
    return engine, ctx


def _refined(engine, addon, ctx):
    state = engine._lantern
    state.thread.join(30)
    assert state.error is None and state.session.spp == SPP
    return state.image


def _fresh(stage, ctx, settings):
    """A full export of the scene as it is now, for the viewport's view."""
    from lantern_blender.export import export_scene
    from lantern_blender.export.camera import ViewportView
    scene, _ = export_scene(bpy.context.evaluated_depsgraph_get(), region_view=ViewportView(ctx))
    return scene


def _renders(scene, seeds):
    return [lantern.render(scene, spp=SPP, backend="cpu", seed=s) for s in seeds]


def _paired(name, a, b):
    """a, b: renders of the same seeds (a_k and b_k trace the same random numbers). Paired
    (tests/README.md): E[a_k - b_k] = 0 is tested as a_k - b_k + mean(b) against mean(b),
    taken as exact (the noise both share cancels), by lantern.metrics.assert_agreement with
    its 1 % / 5 % negative controls; identical images pass exactly."""
    return metrics.assert_agreement(name, *metrics.paired_sets(a, b), block=4)


def _apply(addon, engine, ctx, fn):
    _edit(fn, lambda dg: addon.engine.view_update(engine, ctx, dg))
    addon.engine.view_draw(engine, ctx, bpy.context.evaluated_depsgraph_get())
    return _refined(engine, addon, ctx)


def _told_apart(a, b):
    """Independent renders of two different scenes: compare_renders must see them differ."""
    return not metrics.compare_renders(a, b, block=4).passed


def test_camera_move_replaces_the_camera_only(addon, stage):
    engine, ctx = _start(addon, stage)
    state = engine._lantern
    _refined(engine, addon, ctx)
    session, syncs, counts = state.session, state.sync.syncs, dict(state.sync.counts)
    assert counts["meshes_extracted"] == 2 and counts["materials"] == 2
    moved = stage.camera.matrix_world.inverted()
    moved[0][3] += 0.4
    ctx2 = _context(stage, moved)
    addon.engine.view_draw(engine, ctx2, bpy.context.evaluated_depsgraph_get())
    image = _refined(engine, addon, ctx2)
    assert state.session is session and state.camera_updates == 1
    assert state.sync.syncs == syncs  # nothing exported, no new session, no BVH build
    fresh = _fresh(stage, ctx2, stage.lantern)
    want = lantern.render(fresh, spp=SPP, **stage.lantern.session_settings())
    np.testing.assert_array_equal(image, want)  # a re-aimed session renders as a new one
    state.free()


def test_scene_edits_export_what_changed(addon, stage):
    engine, ctx = _start(addon, stage)
    state = engine._lantern
    _refined(engine, addon, ctx)
    before = _fresh(stage, ctx, stage.lantern)
    mat = bpy.data.materials["CardMat"]
    card = bpy.data.objects["Card"]
    edits = [
        ("material", lambda: setattr(mat.node_tree.nodes["Principled BSDF"].inputs[
            "Base Color"], "default_value", (0.9, 0.05, 0.05, 1)),
         {"materials": 1, "meshes_extracted": 0, "meshes_placed": 0, "world": 0}),
        ("world", lambda: setattr(stage.world.node_tree.nodes["Background"].inputs["Color"],
                                  "default_value", (0.1, 0.2, 1.0, 1)),
         {"materials": 0, "meshes_extracted": 0, "meshes_placed": 0, "world": 1}),
        ("transform", lambda: setattr(card, "location", (0.8, 0.3, 0.7)),
         {"materials": 0, "meshes_extracted": 0, "meshes_placed": 1, "world": 0}),
    ]
    for what, fn, want in edits:
        session = state.session
        image = _apply(addon, engine, ctx, fn)
        got = {k: state.sync.counts[k] for k in want}
        assert got == want, what
        # a colour edit and a move are taken by the running session (no scene rebuild, no
        # bottom-level BVH build: test_transform_edit_moves_one_instance)
        assert (state.session is session) == (what in ("material", "transform")), what
        if what != "transform":  # a moved instance: another BVH layout, the same image in law
            np.testing.assert_array_equal(  # the viewport renders the patched scene...
                image, lantern.render(state.sync.scene, spp=SPP,
                                      **stage.lantern.session_settings()))
        fresh = _fresh(stage, ctx, stage.lantern)
        if what == "transform":  # its images: test_transform_edit_moves_one_instance; the
            # sync's scene (what a later new session starts from) is placed as a fresh export
            for got, want in zip(state.sync.scene.meshes, fresh.meshes, strict=True):
                np.testing.assert_allclose(got["positions"], want["positions"], atol=1e-6)
        else:
            # ...which renders as a fresh export of the edited scene (the same seeds: paired;
            # today the same bits)
            want = _renders(fresh, SEEDS)
            _paired(f"{what}: synced scene vs fresh export", _renders(state.sync.scene, SEEDS),
                    want)
            # ...and the scene before the edit is told apart
            assert _told_apart(_renders(before, range(21, 26)), want)
        before = fresh
    assert state.material_updates == 1 and state.instance_moves == 1
    state.free()


@pytest.mark.parametrize("accel", ["bvh", "embree"])
def test_transform_edit_moves_one_instance(addon, stage, monkeypatch, accel):
    """After a move only that instance changes: no mesh extracted, one placed, the running
    session moves it (no bottom-level BVH built, counted by the core), and the viewport's
    image agrees with fresh renders of the moved scene (independent seeds on both sides)."""
    if accel == "embree" and not lantern.session.require_core().embree_available():
        pytest.skip("no Embree")
    monkeypatch.setenv("LANTERN_ACCEL", accel)
    card = bpy.data.objects["Card"]
    home = tuple(card.location)
    images = []
    for seed in MOVE_SEEDS:
        card.location = home
        bpy.context.view_layer.update()
        stage.lantern.seed = seed
        engine, ctx = _start(addon, stage)
        state = engine._lantern
        unmoved = _refined(engine, addon, ctx)
        session = state.session
        builds = session.stats["accel_bottom_builds"]
        assert builds == 2  # one bottom level per mesh: the floor and the card
        assert any("built-in BVH" in w for w in session.warnings) == (accel == "bvh")

        def move():
            card.location = (0.6, 0.4, 0.8)
            card.rotation_euler = (0.3, 0.2, 0.5)
            card.scale = (1.3, 0.8, 1.0)
        images.append(_apply(addon, engine, ctx, move))
        counts = state.sync.counts
        assert counts["meshes_extracted"] == 0 and counts["meshes_placed"] == 1
        assert state.session is session and state.instance_moves == 1
        st = session.stats
        assert st["instance_moves"] == 1 and st["accel_bottom_builds"] == builds
        if seed == MOVE_SEEDS[0]:  # moved back: the session's own placement again, bit for bit

            def back():
                card.location, card.rotation_euler, card.scale = home, (0, 0, 0), (1, 1, 1)
            np.testing.assert_array_equal(_apply(addon, engine, ctx, back), unmoved)
            assert state.session is session and session.stats["instance_moves"] == 2
        state.free()
        card.rotation_euler, card.scale = (0, 0, 0), (1, 1, 1)
    card.location = (0.6, 0.4, 0.8)
    card.rotation_euler, card.scale = (0.3, 0.2, 0.5), (1.3, 0.8, 1.0)
    bpy.context.view_layer.update()
    fresh = _fresh(stage, ctx, stage.lantern)
    # the fresh export rendered with the viewport's seeds: the same paths up to the moved
    # instance's float rounding (another BVH layout), so paired (today the same bits)
    settings = stage.lantern.session_settings()
    want = [lantern.render(fresh, spp=SPP, **dict(settings, seed=seed)) for seed in MOVE_SEEDS]
    _paired(f"moved instance ({accel}) vs fresh export", images, want)
    card.location = home  # the unmoved scene is told apart
    card.rotation_euler, card.scale = (0, 0, 0), (1, 1, 1)
    bpy.context.view_layer.update()
    assert _told_apart(images, _renders(_fresh(stage, ctx, stage.lantern), range(21, 26)))


def test_first_iteration_is_coarse(addon, stage):
    engine = _Engine(addon)
    engine._lantern.draw = _Draw()
    state = engine._lantern
    shapes = []
    publish = state._publish
    state._publish = lambda image: (shapes.append(image.shape[:2]), publish(image))
    ctx = _context(stage, stage.camera.matrix_world.inverted(), size=(256, 256))
    stage.lantern.preview_samples = 2
    depsgraph = bpy.context.evaluated_depsgraph_get()
    addon.engine.view_update(engine, ctx, depsgraph)
    addon.engine.view_draw(engine, ctx, depsgraph)
    state.thread.join(60)
    assert state.error is None
    assert shapes[0] == (64, 64) and shapes[-1] == (256, 256) and len(shapes) == 3
    want = lantern.render(_fresh(stage, ctx, stage.lantern), spp=2,
                          **stage.lantern.session_settings())
    np.testing.assert_array_equal(state.image, want)  # the coarse pass leaves no trace
    state.free()


def test_auto_keeps_its_choice_across_a_camera_move(addon, stage):
    """Integrator "auto" (native/src/integrator/allocation.h) decides once per viewport
    session: after the coarse first pass at 64 x 64 the full-size render does not pilot
    again (its first refined frame would cost the pilot's four trials more)."""
    stage.lantern.integrator = "auto"
    engine = _Engine(addon)
    engine._lantern.draw = _Draw()
    state = engine._lantern
    ctx = _context(stage, stage.camera.matrix_world.inverted(), size=(256, 256))
    stage.lantern.preview_samples = 2
    depsgraph = bpy.context.evaluated_depsgraph_get()
    addon.engine.view_update(engine, ctx, depsgraph)
    addon.engine.view_draw(engine, ctx, depsgraph)
    state.thread.join(60)
    assert state.error is None
    st = state.session.stats
    assert st["auto_choice"] in ("pt", "cis")
    # one pilot (two pt and two cis trials), the coarse pass's sample, the full size's two
    # (a second pilot would add four)
    assert st["auto_pt_iterations"] + st["auto_cis_iterations"] <= 2 + 2 + 1 + 2
    state.free()


def _texture(material, coords):
    """A Checker texture of 4 m squares on `material`'s Base Color, read in `coords` (an output
    of a Texture Coordinate node: Generated, Object, ...), which mesh export carries per vertex."""
    nt = material.node_tree
    checker = nt.nodes.new("ShaderNodeTexChecker")
    checker.inputs["Scale"].default_value = 4.0
    checker.inputs["Color1"].default_value = (0.9, 0.9, 0.9, 1)
    checker.inputs["Color2"].default_value = (0.05, 0.05, 0.05, 1)
    tc = nt.nodes.new("ShaderNodeTexCoord")
    nt.links.new(tc.outputs[coords], checker.inputs["Vector"])
    nt.links.new(checker.outputs["Color"], nt.nodes["Principled BSDF"].inputs["Base Color"])


def test_textures_read_their_coordinates_in_the_viewport(addon, stage):
    """A texture in Generated or Object coordinates reads per-vertex channels that export
    finishes once all materials are known (node_attributes.AttributeTable.finish); the viewport's
    sync must finish them too, also when an edit makes a material read a channel the placed
    meshes were exported without (then it exports everything again). Found by reading the code:
    the sync's scene had no channels and rendered every such texture at coordinate 0."""
    _texture(bpy.data.materials["CardMat"], "Generated")
    bpy.context.view_layer.update()
    engine, ctx = _start(addon, stage)
    state = engine._lantern
    image = _refined(engine, addon, ctx)
    fresh = _fresh(stage, ctx, stage.lantern)
    assert state.sync.scene.attribute_channels == fresh.attribute_channels == ["generated"]
    # the viewport's session (built from a copy of the synced scene) renders them too
    np.testing.assert_array_equal(image, lantern.render(fresh, spp=SPP,
                                                        **stage.lantern.session_settings()))
    _paired("Generated checker: synced scene vs fresh export",
            _renders(state.sync.scene, SEEDS), _renders(fresh, SEEDS))
    before = fresh
    floor = bpy.data.objects["Floor"].data.materials[0]
    _apply(addon, engine, ctx, lambda: _texture(floor, "Object"))
    fresh = _fresh(stage, ctx, stage.lantern)
    assert state.sync.scene.attribute_channels == fresh.attribute_channels
    assert "object" in fresh.attribute_channels
    want = _renders(fresh, SEEDS)
    _paired("Object checker added: synced scene vs fresh export",
            _renders(state.sync.scene, SEEDS), want)
    assert _told_apart(_renders(before, range(21, 26)), want)  # the edit shows
    state.free()
