"""Scenes of lantern.scenes with one feature that `auto` used to give to pt alone
(native/src/integrator/allocation.cpp pt_only_reason; branch autowide): tests/python/
test_auto_wide.py and bench/auto_wide.py. Each builder takes (width, height)."""
import numpy as np

from lantern import scenes


def _mesh(scene, name):
    for m in scene.meshes:
        if m.get("name") == name:
            return m
    raise KeyError(name)


def slide(scene, name, dx):
    """Mesh `name` (world-space vertices) slides by +-dx along x over the shutter."""
    steps = []
    for t in (0.0, 0.5, 1.0):
        m = np.eye(4)
        m[0, 3] = dx * (2.0 * t - 1.0)
        steps.append(m)
    mesh = _mesh(scene, name)
    mesh["motion"] = steps
    mesh["motion_base"] = np.eye(4)
    return scene


def cornell_motion(width, height):
    """The Cornell box, its tall box sliding 0.6 m (cis ~0.5x pt's efficiency, still)."""
    return slide(scenes.cornell_box(width, height), "tall_box", 0.3)


def lantern_motion(width, height):
    """The glass lantern (a bulb in a closed glass cube), the tall box under it sliding 0.6 m
    (cis many times pt's efficiency, still)."""
    return slide(scenes.glass_lantern(width, height), "tall_box", 0.3)


def glossy_motion(width, height):
    """The glossy box (metal floor, a tiny sphere light), its short box sliding 0.6 m (cis
    ~2-3x pt's efficiency, still: bench/results/2026-12-04-auto4)."""
    return slide(scenes.glossy_box(width, height), "short_box", 0.3)


SCENES = {
    "cornell_motion": cornell_motion,
    "lantern_motion": lantern_motion,
    "glossy_motion": glossy_motion,
}
