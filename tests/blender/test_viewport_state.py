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
    state.start_session(lantern.Session(_scene()), 8)
    state.thread.join(10)
    assert not state.refining() and state.error is None
    assert state.session.spp == 8 and state.image_serial == 8
    np.testing.assert_allclose(state.image, 2.0, rtol=1e-4)
    state.free()
    assert state.session is None


def test_stops_promptly_when_unlimited(addon):
    state = addon.engine.EngineState()
    state.start_session(lantern.Session(_scene(256)), 0)  # 0: refine until stopped
    time.sleep(0.2)
    assert state.refining()
    t = time.perf_counter()
    addon.engine.stop_all()
    assert time.perf_counter() - t < 2.0 and not state.refining()
