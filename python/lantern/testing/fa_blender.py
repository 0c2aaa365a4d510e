"""False-alarm families of tests/blender's F12 comparisons, for false_alarm.py (its
FAMILIES, loaded by load_family_modules). Each trial builds the test's scene on the `empty`
fixture's scene (blender_helpers.empty_scene) through the test file's own helpers and renders it
with its own seeds (scene.lantern.seed; Cycles' scene.cycles.seed), at the test's settings.
Needs bpy.

- bl_direct: test_bl_render.py::test_matches_cycles_direct_light, 16 Lantern F12s of 64 spp
  against 8 Cycles F12s of 16 spp, both sides re-rendered every trial (Cycles here is cheap);
- bl_exact: test_bl_render.py's glass pane over a mirror against 2 and white Principled furnace
  against 1 (pt and cis, 16 seeds, cap 1e-4), and test_bl_textures.py::test_normal_map_f12[cis]
  against its exact radiance (16 seeds, the plane's inner 4x4 blocks, cap 1e-4).
"""

import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[3]
for sub in ("tools", "tests/blender"):
    if str(ROOT / sub) not in sys.path:
        sys.path.insert(0, str(ROOT / sub))

_TMP = Path(tempfile.mkdtemp(prefix="fa_blender_"))


def _empty():
    import lantern_bpy
    lantern_bpy.load_addon()
    from blender_helpers import empty_scene
    return empty_scene()


def pairs_bl_direct(trial):
    import test_bl_render as tb

    def run():
        scene = _empty()
        tb.direct_light_scene(scene)
        scene.lantern.samples = tb.DIRECT_SPP
        seed0 = 2700000 + 1000 * trial
        lan = tb.seed_renders(scene, _TMP, "lantern", range(seed0, seed0 + tb.DIRECT_SEEDS))
        cyc = tb.direct_light_cycles(scene, _TMP, range(seed0 + 500, seed0 + 508), 16)
        return lan, cyc, {"block": 8}
    yield "F12 direct light vs Cycles (test_bl_render)", run


def pairs_bl_exact(trial):
    import test_bl_render as tb
    import test_bl_textures as tt

    def glass(integrator):
        scene = _empty()
        tb.mirror_scene(scene, integrator)
        tb.add_glass_pane(scene)
        seed0 = 2800000 + 1000 * trial
        seeds = tb.seed_renders(scene, _TMP, "glass", range(seed0, seed0 + tb.GLASS_SEEDS))
        return seeds, 2.0, {"block": 4, "bias_cap": 1e-4}

    def furnace(integrator):
        scene = _empty()
        tb.furnace_scene(scene, integrator)
        seed0 = 2850000 + 1000 * trial
        full = tb.seed_renders(scene, _TMP, "furnace", range(seed0, seed0 + tb.FURNACE_SEEDS))
        return [px[tb.FURNACE_CROP] for px in full], 1.0, {"block": 4, "bias_cap": 1e-4}

    def normal_map():
        scene = _empty()
        _, _, expected = tt.normal_map_scene(scene, "cis")
        seed0 = 2900000 + 1000 * trial
        imgs = tt.normal_map_seeds(scene, _TMP, range(seed0, seed0 + 16))
        return imgs, np.full((32, 32, 3), expected), {"block": 4, "mask": tt.NORMAL_MAP_MASK,
                                                      "bias_cap": 1e-4}
    for integrator in ("pt", "cis"):
        yield f"F12 glass pane over a mirror ({integrator}) vs 2 (test_bl_render)", (
            lambda integrator=integrator: glass(integrator))
    for integrator in ("pt", "cis"):
        yield f"F12 white principled furnace ({integrator}) vs 1 (test_bl_render)", (
            lambda integrator=integrator: furnace(integrator))
    yield "F12 normal map (cis) vs its exact radiance (test_bl_textures)", normal_map


FAMILIES = {"bl_direct": pairs_bl_direct, "bl_exact": pairs_bl_exact}
