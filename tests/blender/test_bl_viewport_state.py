"""The viewport's refining thread (no GPU needed): it steps a session to the target, publishes
images under the lock, and stops promptly when asked."""

import time

import numpy as np
import pytest

import lantern

pytestmark = pytest.mark.skipif(not lantern.session.native_available(),
                                reason="lantern native module not built")


def _scene(size=32):
    scene = lantern.Scene()
    scene.film = {"width": size, "height": size, "filter_width": 1.5}
    m = scene.add_material(emission=(2, 2, 2))
    scene.meshes.append({"name": "quad", "material_ids": np.array([m, m], np.uint32),
                         "positions": np.array([[-9, -9, -1], [9, -9, -1], [9, 9, -1],
                                                [-9, 9, -1]], np.float32),
                         "indices": np.array([[0, 1, 2], [0, 2, 3]], np.uint32)})
    return scene


def test_refines_to_target(addon):
    state = addon.engine.EngineState()
    state.start_session(lantern.Session(_scene(), integrator="pt"), 8)
    state.thread.join(10)
    assert not state.refining() and state.error is None
    assert state.session.spp == 8 and state.image_serial == 8
    np.testing.assert_allclose(state.image, 2.0, rtol=1e-4)
    state.free()
    assert state.session is None


def test_stops_promptly_when_unlimited(addon):
    state = addon.engine.EngineState()
    state.start_session(lantern.Session(_scene(256), integrator="pt"), 0)  # 0: refine until stopped
    time.sleep(0.2)
    assert state.refining()
    t = time.perf_counter()
    addon.engine.stop_all()
    assert time.perf_counter() - t < 2.0 and not state.refining()


class _FakeDraw:
    def __init__(self):
        self.uploads, self.draws = [], 0

    def update(self, image, serial):
        self.uploads.append(serial)

    def draw(self, engine, scene, width, height):
        self.draws += 1


class _FakeEngine:
    def __init__(self, addon):
        self._lantern = addon.engine.EngineState()
        self.reports, self.redraws = [], 0

    def report(self, kind, message):
        self.reports.append((kind, message))

    def tag_redraw(self):
        self.redraws += 1


def test_view_draw_exports_refines_and_reuses_scene(empty, addon, monkeypatch):
    """view_draw without a GPU: first draw exports and starts refining; a moved view reuses
    the exported scene; view_update forces a re-export; failures are reported once."""
    import bpy
    from types import SimpleNamespace
    from blender_helpers import add_camera, add_plane, emission_material
    add_camera(empty, location=(0, 0, 5))
    add_plane(empty, size=100.0, material=emission_material(1.5))
    empty.lantern.preview_samples = 4
    depsgraph = bpy.context.evaluated_depsgraph_get()
    cam = empty.camera
    window = cam.calc_matrix_camera(depsgraph, x=32, y=24)

    def context(view):
        return SimpleNamespace(scene=empty, region=SimpleNamespace(width=32, height=24),
                               region_data=SimpleNamespace(view_matrix=view, window_matrix=window,
                                                           is_perspective=True))
    engine = _FakeEngine(addon)
    draw = _FakeDraw()
    engine._lantern.draw = draw
    ctx = context(cam.matrix_world.inverted())
    addon.engine.view_update(engine, ctx, depsgraph)
    addon.engine.view_draw(engine, ctx, depsgraph)
    state = engine._lantern
    first = state.scene
    state.thread.join(10)
    addon.engine.view_draw(engine, ctx, depsgraph)
    assert draw.draws >= 1 and state.session.spp == 4
    np.testing.assert_allclose(state.image, 1.5, rtol=1e-4)
    moved = cam.matrix_world.inverted()
    moved[0][3] += 0.5
    addon.engine.view_draw(engine, context(moved), depsgraph)
    assert state.scene is first  # view change only: no re-export
    addon.engine.view_update(engine, ctx, depsgraph)
    addon.engine.view_draw(engine, ctx, depsgraph)
    assert state.scene is not first
    monkeypatch.setattr(lantern, "Session", lambda *a, **k: (_ for _ in ()).throw(
        ValueError("broken (mocked)")))
    addon.engine.view_update(engine, ctx, depsgraph)
    addon.engine.view_draw(engine, ctx, depsgraph)
    state.thread.join(10)  # the session is built in the refining thread
    addon.engine.view_draw(engine, ctx, depsgraph)
    addon.engine.view_draw(engine, ctx, depsgraph)
    assert [m for k, m in engine.reports if "mocked" in m] and len(engine.reports) == 1
    state.free()
    assert not engine.reports[0][0] == {"WARNING"}
