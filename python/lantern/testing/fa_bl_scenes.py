"""False-alarm families whose scenes are built in bpy (false_alarm.py's docstring lists each:
layers, passes, bl_catcher, bl_hdri, coat_normal, sun_disc). coat_normal_renders is shared
with false_alarm_coat_limb.py. Each family yields (label, make) per trial."""

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[3]   # the checkout: the families render its tests' scenes
sys.path.insert(0, str(ROOT / "tools"))      # render_compare, lantern_bpy

import lantern  # noqa: E402


def _layers_passes(runs):
    """test_layers_passes' module (the add-on loaded) and a getter of its renders, made on the
    first call: for each (key, engine, seed0, crop) of `runs`, tl.SEEDS renders of the
    layers_passes scene by that engine from seed0 on (crop False: the border uncropped)."""
    sys.path.insert(0, str(ROOT / "blend_scenes"))
    sys.path.insert(0, str(ROOT / "tests" / "cycles"))
    import tempfile

    import exr_passes
    import lantern_bpy
    import layers_passes
    import test_layers_passes as tl
    lantern_bpy.load_addon()
    cache = {}

    def renders():
        if not cache:
            tmp = Path(tempfile.mkdtemp())
            for key, engine, seed0, crop in runs:
                setup = tl._cycles if engine == "cycles" else tl._lantern
                for k in range(tl.SEEDS):
                    scene = layers_passes.layers_passes()
                    setup(scene, seed0 + k)
                    if not crop:
                        layers_passes.set_border(scene, crop=False)
                    cache.setdefault(key, []).append(
                        exr_passes.render_passes(scene, tmp / f"{key}{k}.exr"))
        return cache
    return tl, renders


def pairs_layers(trial):
    """test_layers_passes' Combined (both view layers) and uncropped border against Cycles:
    8 seeds of 16 spp an engine, each trial its own seeds on both sides (needs bpy)."""
    tl, renders = _layers_passes((("cycles", "cycles", 10000 + 100 * trial, True),
                                  ("lantern", "lantern", 20000 + 100 * trial, True),
                                  ("nocrop", "lantern", 20000 + 100 * trial, False)))

    def combined(layer):
        r = renders()
        return tl._combined(r["lantern"], layer), tl._combined(r["cycles"], layer), {"block": 8}

    def border(layer):
        r = renders()
        cut = (slice(64 - tl.BY1, 64 - tl.BY0), slice(tl.BX0, tl.BX1))
        return ([x[cut] for x in tl._combined(r["nocrop"], layer)],
                [x[cut] for x in tl._combined(r["cycles"], layer)], {"block": 8})
    for layer in tl.LAYERS:
        yield f"layers_passes {layer} Combined vs Cycles", lambda layer=layer: combined(layer)
        yield f"layers_passes {layer} border vs Cycles", lambda layer=layer: border(layer)


def pairs_passes(trial):
    """test_layers_passes' data passes (Normal, Denoising Albedo, Denoising Normal, Diffuse
    Color; both view layers) against Cycles, 8 seeds of 16 spp an engine, each trial its own
    seeds on both sides (needs bpy)."""
    tl, renders = _layers_passes((("cycles", "cycles", 30000 + 100 * trial, True),
                                  ("lantern", "lantern", 40000 + 100 * trial, True)))

    def one(layer, name):
        r = renders()
        return (tl._pass_seeds(r["lantern"], layer, name),
                tl._pass_seeds(r["cycles"], layer, name), {"block": 8})
    for layer in tl.LAYERS:
        for name in tl.DATA_PASSES:
            yield (f"layers_passes {layer} {name} vs Cycles",
                   lambda layer=layer, name=name: one(layer, name))


def _bl_empty_scene():
    """tests/blender's `empty` fixture: factory settings, no objects, Lantern, 32 x 24."""
    sys.path.insert(0, str(ROOT / "tests" / "blender"))
    import lantern_bpy
    lantern_bpy.load_addon()
    from blender_helpers import empty_scene
    return empty_scene()


_BL_SCENES = {}


def pairs_bl_catcher(trial):
    """test_bl_world.py::test_shadow_catcher_through_f12: the exported catcher-and-wall scene's
    alpha (16 seeds of 8 spp) against the wall's exact shadow (needs bpy)."""
    sys.path.insert(0, str(ROOT / "tests" / "blender"))
    import test_bl_world as tw
    from lantern.film import render_alpha

    def run():
        if "catcher" not in _BL_SCENES:
            tf = tw._film_test_module()
            bscene = _bl_empty_scene()
            tw.catcher_wall_scene(bscene, tf)
            _BL_SCENES["catcher"] = (tw.export(None)[0], bscene.lantern.max_depth,
                                     tw.catcher_expected(tf), tf.CATCHER_CAP)
        scene, depth, expected, cap = _BL_SCENES["catcher"]
        a = [render_alpha(scene, spp=tw.CATCHER_SPP, seed=1000 * trial + 900000 + k,
                          max_depth=depth)[:, tw.CATCHER_COLS] for k in range(tw.CATCHER_SEEDS)]
        return a, expected, {"block": 4, "bias_cap": cap}
    yield "F12 shadow catcher vs its exact wall shadow (test_bl_world)", run


def pairs_bl_hdri(trial):
    """test_bl_world.py::test_hdri_renders_finite_and_lit: the exported HDRI-lit Lambert plane
    (16 seeds of 128 spp) against its exact irradiance (needs bpy)."""
    sys.path.insert(0, str(ROOT / "tests" / "blender"))
    import test_bl_world as tw

    def run():
        if "hdri" not in _BL_SCENES:
            _BL_SCENES["hdri"] = tw.hdri_plane(_bl_empty_scene())
        scene, expected = _BL_SCENES["hdri"]
        imgs = [lantern.render(scene, spp=tw.HDRI_SPP, seed=1000 * trial + 950000 + k,
                               integrator="pt")
                for k in range(16)]
        return [x[tw.HDRI_PLANE][..., :3] for x in imgs], expected, {"block": 4,
                                                                     "bias_cap": 1e-4}
    yield "HDRI world on a Lambert plane vs its exact irradiance (test_bl_world)", run


_COAT = {}


def coat_normal_renders(trial):
    """tests/cycles/test_coat_normal.py's renders for one trial: K Cycles and K Lantern seeds of
    SPP (each trial its own seeds on both sides), the interior blocks and the limb mask."""
    sys.path.insert(0, str(ROOT / "tests" / "cycles"))
    import lantern_bpy
    import render_compare as rc
    import test_coat_normal as tc
    lantern_bpy.load_addon()
    if trial not in _COAT:
        _COAT.clear()
        tc._scene()
        interior, limb = tc._interior_blocks()
        cyc = [rc.render_cycles(seed=50000 + 100 * trial + k, spp=tc.SPP)[0]
               for k in range(tc.K)]
        lan = [rc.render_lantern(seed=60000 + 100 * trial + k, spp=tc.SPP, threads=2)[0]
               for k in range(tc.K)]
        _COAT[trial] = (lan, cyc, interior, limb)
    return _COAT[trial]


def pairs_coat_normal(trial):
    """test_coat_normal.py's interior comparison: Principled Coat Normal against Cycles, 12
    seeds of 128 spp a renderer, 4x4 blocks away from the limb (needs bpy). Its limb ratio is
    counted by false_alarm_coat_limb.py from the same renders."""
    def run():
        lan, cyc, interior, _ = coat_normal_renders(trial)
        return lan, cyc, {"block": 4, "mask": interior, "rel_floor": 1e-3}
    yield "coat normal interior vs Cycles (test_coat_normal)", run


def pairs_sun_disc(trial):
    """test_sky_cycles.py::test_sun_disc_irradiance_matches_cycles, Lantern's side: the disc
    its camera sees (8 seeds of 16 spp, summed over the pixels' solid angles, less the sky)
    against the light's strength, cap 0.3 %, for both skies (needs bpy)."""
    sys.path.insert(0, str(ROOT / "tests" / "render"))
    import test_sky_cycles as ts

    def run(i):
        if ("disc", i) not in _BL_SCENES:
            import lantern_bpy
            lantern_bpy.load_addon()
            node, omega, _, _ = ts.disc_view(ts.DISC_PROPS[i])
            light, scene, sky = ts.lantern_disc(node, omega)
            _BL_SCENES["disc", i] = (scene, omega, sky, np.asarray(light["strength"]))
        scene, omega, sky, mine = _BL_SCENES["disc", i]
        discs = ts.disc_sums(scene, omega, sky, seed0=1000 * trial + 960000)
        return discs, mine, {"block": 1, "bias_cap": ts.DISC_CAP}
    for i, props in enumerate(ts.DISC_PROPS):
        yield (f"sun disc {props.get('sky_type', 'MULTIPLE_SCATTERING')} vs its light "
               f"(test_sky_cycles)", lambda i=i: run(i))


FAMILIES = {"layers": pairs_layers, "passes": pairs_passes, "bl_catcher": pairs_bl_catcher,
            "bl_hdri": pairs_bl_hdri, "coat_normal": pairs_coat_normal,
            "sun_disc": pairs_sun_disc}
