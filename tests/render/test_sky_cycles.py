"""The Multiple Scattering Sky Texture (addon/export/sky_ms.py) against Cycles itself, texel by
direction: Cycles renders the world alone through a full-sphere equirectangular panoramic
camera (256 x 128, one sample, a pixel filter of 0.01 px: each pixel is its centre's
direction), and a first render of the Texture Coordinate's Generated vector gives each pixel's
direction. The model is deterministic, so the tolerance is its own agreement, not noise: within
0.5 % at every direction where the sky is not black (at most 0.36 % measured); negative
controls (the model 1 % brighter or darker; the aerosols 5 % denser) must fail it. The exported map (1024 x 512) is the model at its texels' directions
outside the horizon band, whose texels are the model's means over their elevation extent
(sky.horizon_band; world_sky_ms in test_cycles_compare.py compares what they light and show).
The same for Single Scattering (sky_ss.py) and Preetham. The panorama's sky reads its Vector
through a Mapping turned 90 degrees: Cycles turns Preetham and a disc-less Multiple or Single
Scattering sky with it and ignores it with the disc on (the Vector is unavailable then); the
model through Lantern's texture vector must match, the other turn must not.

The sun disc, which Lantern exports as a sun light, against the disc Cycles draws (Multiple and
Single Scattering): a camera 2.5 disc diameters wide centred on the sun (Blackman-Harris 1.5
px: the edge antialiased); the image less the model's sky (Cycles' without the disc within
0.3 % per pixel, the disc sums then within 3e-6 of the difference of two Cycles renders,
measured) summed over the pixels' solid angles is the disc's irradiance, within 0.5 % of the
light's (the control: 3 % more Sun Intensity fails). Lantern's camera sees the disc (the
world's sun light) in the same view: its summed radiance (8 seeds x 16 spp) against the light's
strength as exact, metrics.assert_agreement at a stated 0.3 % cap (measured: +0.09 %,
+0.19 %), whose 1 % / 5 % and swapped-channel controls must fail; the control, the same light
as a sun lamp (invisible to the camera, as Blender's are), fails. The scene-level comparison (the stage lit by this sky, the
default disc included) is world_sky_ms in test_cycles_compare.py. Tests that use the
panorama fixture run before the disc tests, which reset Blender's data."""

import math
import os
import tempfile

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")
import lantern_bpy  # noqa: E402
import render_compare as rc  # noqa: E402
from lantern import metrics  # noqa: E402

# The models are deterministic: agreement measured 2026-12-02 at most 0.36 % (the defaults'
# Multiple Scattering sky; 7.5e-4, 4.3e-4, 2.4e-4 in the others, the disc strengths 0.11 %).
# 0.5 %, so that a model 1 % brighter or darker fails everywhere (was 1 %, the size of the
# bias itself); each test checks that (controls_fail)
TOL = 0.005


def controls_fail(ratio):
    """The +-1 % controls of a deterministic ratio model / reference: both must exceed TOL."""
    return all(np.abs(f * np.asarray(ratio) - 1.0).max() > TOL for f in (1.01, 0.99))
PANO = (256, 128)   # the panorama's pixels (a direction each)
CONFIGS = {   # Blender's defaults have the Sun Disc on: the Vector is unavailable then
    "defaults": {"sun_disc": True},
    "low_sun_thin_air": {"sun_elevation": math.radians(3.0), "sun_rotation": math.radians(40.0),
                         "altitude": 3000.0, "air_density": 2.0, "aerosol_density": 0.3,
                         "ozone_density": 3.0, "sun_disc": False},
}


@pytest.fixture(scope="module")
def addon():
    return lantern_bpy.load_addon()


def _render(scene, spp, width, height, filter_width=0.01):
    rc.cycles_settings(scene, 1, spp)
    scene.cycles.filter_width = filter_width
    scene.cycles.max_bounces = 0
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "sky.exr")
        scene.render.filepath = path
        bpy.ops.render.render(write_still=True)
        return lantern_bpy.read_image_bpy(path)[..., :3].astype(np.float64)


def _world():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    world = bpy.data.worlds.new("Sky")
    scene.world = world
    nt = world.node_tree
    sky = nt.nodes.new("ShaderNodeTexSky")
    return scene, nt, sky


def _camera(scene, data):
    obj = bpy.data.objects.new("Camera", data)
    scene.collection.objects.link(obj)
    scene.camera = obj
    return obj


@pytest.fixture(scope="module")
def panorama(addon):
    """(scene, the sky node, the Background node, each pixel's direction (H, W, 3))."""
    scene, nt, node = _world()
    cam = bpy.data.cameras.new("Pano")
    cam.type = "PANO"
    cam.panorama_type = "EQUIRECTANGULAR"
    _camera(scene, cam).rotation_euler = (math.pi / 2, 0.0, 0.0)
    bg = nt.nodes["Background"]
    coord = nt.nodes.new("ShaderNodeTexCoord")
    half = nt.nodes.new("ShaderNodeVectorMath")
    half.operation = "MULTIPLY_ADD"      # (d + 1) / 2: non-negative colours
    half.inputs[1].default_value = half.inputs[2].default_value = (0.5, 0.5, 0.5)
    nt.links.new(coord.outputs["Generated"], half.inputs[0])
    nt.links.new(half.outputs[0], bg.inputs["Color"])
    d = _render(scene, 1, *PANO) * 2.0 - 1.0
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    nt.links.new(node.outputs["Color"], bg.inputs["Color"])
    # a Mapping turning the sky's Vector 90 degrees about Z: Cycles 5.0.1 applies it to a
    # Preetham sky (test_preetham_turns_with_the_mapping) and to a Multiple Scattering one with
    # the Sun Disc off; with the disc on the Vector is unavailable and the link ignored
    mapping = nt.nodes.new("ShaderNodeMapping")
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(90.0))
    nt.links.new(coord.outputs["Generated"], mapping.inputs["Vector"])
    nt.links.new(mapping.outputs["Vector"], node.inputs[0])
    return scene, node, d


@pytest.mark.parametrize("config", list(CONFIGS))
def test_sky_model_matches_cycles(config, panorama, addon):
    from lantern_blender.export import ExportReport, sky, world
    scene, node, d = panorama
    for k, v in CONFIGS[config].items():
        setattr(node, k, v)
    cycles = _render(scene, 1, *PANO)
    # Lantern's texture vector: the Mapping's turn, or none (named) where Cycles ignores it
    report = ExportReport()
    to_map = world.vector_matrix(node, "test", report)
    turn = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    expect, other = (np.eye(3), turn) if node.sun_disc else (turn, np.eye(3))
    assert np.allclose(to_map, expect, atol=1e-6), to_map
    assert [("unavailable Vector" in m) for m in report.messages] == [True] * node.sun_disc

    def model(directions, tables={}):
        params = sky._ms_params(node)
        if params not in tables:
            tables[params] = sky.sky_ms.sky_table(*params)
        return sky.sky_ms.table_radiance(tables[params], directions, sky._XYZ_TO_REC709)

    lit = cycles.sum(-1) > 1e-3 * np.median(cycles.sum(-1))
    assert lit.mean() > 0.9
    # the disc's pixels (Cycles draws it; Lantern's map does not): 1 degree around the sun
    sun = np.asarray(sky.sky_ms.sun_vector(node.sun_elevation, node.sun_rotation))
    lit &= d @ np.linalg.solve(to_map, sun) < math.cos(math.radians(1.0))
    dev = np.abs(model(d @ to_map.T)[lit] / cycles[lit] - 1.0)
    print(f"{config}: |model / Cycles - 1| median {np.median(dev):.2e}, 99 % "
          f"{np.percentile(dev, 99):.2e}, max {dev.max():.2e} over {lit.sum()} directions")
    assert dev.max() < TOL, (config, dev.max())
    assert controls_fail(model(d @ to_map.T)[lit] / cycles[lit])
    assert np.abs(model(d @ other.T)[lit] / cycles[lit] - 1.0).max() > TOL   # the other turn
    # the exported map: the model at its texels, means over sub-rows in the horizon band
    report = ExportReport()
    rgb = np.asarray(sky.sky_map(node, "test", report), np.float64)
    assert not report.messages, report.messages
    w, h = sky.MS_MAP_SIZE
    assert rgb.shape == (h, w, 3)
    texels = sky.equirect_directions(w, h)
    point = ~sky.horizon_band(np.arcsin(texels[:, 0, 2]), node.altitude)
    assert 0 < (~point).sum() < h // 10
    some = np.nonzero(point)[0][::5]      # a fifth of the rows: the same code makes them all
    assert np.allclose(rgb[some], model(texels[some]), rtol=1e-5, atol=1e-7)
    band = rgb[~point]
    assert np.isfinite(band).all() and band.min() >= 0.0
    # the control: the same model with 5 % more aerosols is told apart
    node.aerosol_density = node.aerosol_density * 1.05
    assert np.abs(model(d)[lit] / cycles[lit] - 1.0).max() > TOL


def test_single_scattering_matches_cycles(panorama, addon):
    """The Single Scattering sky (sky_ss.py: Cycles' table, read as Cycles reads it) through
    the fixture's Mapping (its Vector is available with the disc off), away from the defaults:
    within TOL of Cycles at every direction; the control, 5 % more aerosols, fails. The
    exported map is the same lookup at its texels outside the horizon band."""
    from lantern_blender.export import ExportReport, sky, world
    scene, node, d = panorama
    node.sky_type = "SINGLE_SCATTERING"
    node.sun_disc = False
    props = {"sun_elevation": math.radians(10.0), "sun_rotation": math.radians(-60.0),
             "altitude": 800.0, "air_density": 1.5, "aerosol_density": 2.0,
             "ozone_density": 0.5}
    try:
        for k, v in props.items():
            setattr(node, k, v)
        cycles = _render(scene, 1, *PANO)
        report = ExportReport()
        to_map = world.vector_matrix(node, "test", report)
        rgb = np.asarray(sky.sky_map(node, "test", report), np.float64)
        assert not report.messages, report.messages
        params = sky._ms_params(node)
        control = list(params)
        control[4] *= 1.05
    finally:
        node.sky_type = "MULTIPLE_SCATTERING"

    def model(p, dirs):
        return sky.sky_ss.table_radiance(sky.ss_table(tuple(p)), dirs, p[1], sky._XYZ_TO_REC709)
    lit = cycles.sum(-1) > 1e-3 * np.median(cycles.sum(-1))
    assert lit.mean() > 0.6          # the ground fades to black
    dev = np.abs(model(params, d @ to_map.T)[lit] / cycles[lit] - 1.0)
    print(f"Single Scattering: |model / Cycles - 1| median {np.median(dev):.2e}, max "
          f"{dev.max():.2e} over {lit.sum()} directions")
    assert dev.max() < TOL
    assert controls_fail(model(params, d @ to_map.T)[lit] / cycles[lit])
    assert np.abs(model(control, d @ to_map.T)[lit] / cycles[lit] - 1.0).max() > TOL
    w, h = sky.MS_MAP_SIZE
    texels = sky.equirect_directions(w, h)
    rows = np.abs(np.arcsin(texels[:, 0, 2])) >= sky.HORIZON_BAND
    assert np.allclose(rgb[rows], model(params, texels[rows]), rtol=1e-5, atol=1e-7)
    assert np.isfinite(rgb).all() and rgb.min() >= 0.0


def test_preetham_turns_with_the_mapping(panorama, addon):
    """Preetham through the fixture's Mapping (90 degrees about Z; the sun off the zenith,
    which a turn about Z would not move): Cycles' sky is the model at the exported to_map's
    texture vector within TOL at every direction (2.4e-4 measured); the control, the model
    unturned, is far off (a factor 6 at worst)."""
    from lantern_blender.export import ExportReport, sky, world
    scene, node, d = panorama
    node.sky_type = "PREETHAM"
    node.sun_direction = (0.8, 0.0, 0.6)
    try:
        cycles = _render(scene, 1, *PANO)
        report = ExportReport()
        to_map = world.vector_matrix(node, "test", report)
        assert not report.messages, report.messages
    finally:
        node.sky_type = "MULTIPLE_SCATTERING"
    lit = cycles.sum(-1) > 1e-3 * np.median(cycles.sum(-1))
    assert lit.mean() > 0.9

    def ratio(m):
        return sky.preetham_radiance(d @ m.T, node.sun_direction, node.turbidity)[lit] / \
            cycles[lit]
    turned, unturned = np.abs(ratio(to_map) - 1.0), np.abs(ratio(np.eye(3)) - 1.0)
    print(f"Preetham through a Mapping: |model / Cycles - 1| median {np.median(turned):.2e}, "
          f"max {turned.max():.2e}; unturned max {unturned.max():.2e}")
    assert turned.max() < TOL
    assert controls_fail(ratio(to_map))
    assert unturned.max() > 10 * TOL


# the two skies whose disc is compared (tools/false_alarm.py's sun_disc family renders them too)
DISC_PROPS = [{"sun_elevation": math.radians(8.0), "sun_size": math.radians(1.5),
               "sun_intensity": 0.5, "sun_rotation": 2.0},
              {"sky_type": "SINGLE_SCATTERING", "sun_elevation": math.radians(20.0),
               "sun_size": math.radians(1.0), "sun_rotation": -1.0}]
# 4 x 16 before; 16 x 4 gave se 0.1 % (QMC: fewer spp a seed, more noise per sample)
LANTERN_SEEDS, LANTERN_SPP = 8, 16
DISC_CAP = 0.003
DISC_PIXELS = 48


def disc_view(props):
    """A fresh Blender scene: the sky of `props` as the world and a camera 2.5 disc diameters
    wide centred on its sun. Returns (the sky node, each pixel's solid angle (n, n), each
    pixel's direction in the world (n, n, 3), the direction towards the sun)."""
    from mathutils import Vector
    from lantern_blender.export import sky
    scene, nt, node = _world()
    nt.links.new(node.outputs["Color"], nt.nodes["Background"].inputs["Color"])
    for k, v in props.items():
        setattr(node, k, v)
    fov, n = 1.25 * max(node.sun_size, math.radians(0.6)) * 2.0, DISC_PIXELS
    cam = bpy.data.cameras.new("Sun")
    cam.angle = fov
    towards = Vector(tuple(float(c) for c in np.asarray(
        sky.sky_ms.sun_vector(node.sun_elevation, node.sun_rotation))))
    rotation = towards.to_track_quat("-Z", "Y").to_euler()
    _camera(scene, cam).rotation_euler = rotation
    scene.render.resolution_x = scene.render.resolution_y = n  # as _render sets it for Cycles
    scene.render.resolution_percentage = 100
    # a pinhole pixel's solid angle: (2 tan(fov / 2) / n)^2 cos^3 of its angle off the axis
    t = ((np.arange(n) + 0.5) / n - 0.5) * 2.0 * math.tan(fov / 2)
    cos3 = (1.0 + t[:, None] ** 2 + t[None, :] ** 2) ** -1.5
    omega = (2.0 * math.tan(fov / 2) / n) ** 2 * cos3
    # the pixels' directions (rows top first)
    cam_dirs = np.stack(np.broadcast_arrays(t[None, :], -t[:, None], -1.0), axis=-1)
    cam_dirs = cam_dirs / np.linalg.norm(cam_dirs, axis=-1, keepdims=True)
    return node, omega, cam_dirs @ np.array(rotation.to_matrix()).T, towards


def lantern_disc(node, omega):
    """What Lantern's side of the disc comparison needs of the current scene: the light's
    strength the export gives the disc, the exported scene with the disc, and the sky without
    it summed over the pixels' solid angles (one seed: the camera sees the world directly,
    nearly noise-free, and it is 1e-3 of the disc)."""
    from lantern_blender.export import ExportReport, sky
    light = sky.sky_sun(node, 1.0, np.eye(3), "test", ExportReport())
    node.sun_disc = False
    lantern_sky = _lantern(_export(), omega, 1)[0]
    node.sun_disc = True
    return light, _export(), lantern_sky


def disc_sums(scene, omega, lantern_sky, seed0=0):
    """LANTERN_SEEDS renders of the disc Lantern's camera sees, each summed over the pixels'
    solid angles less the sky, as (K, 1, 1, 3) one-pixel images for metrics.compare_renders."""
    return (_lantern(scene, omega, LANTERN_SEEDS, seed0) - lantern_sky)[:, None, None, :]


@pytest.mark.parametrize("props", DISC_PROPS)
def test_sun_disc_irradiance_matches_cycles(props, addon):
    from lantern_blender.export import ExportReport, sky
    node, omega, dirs, towards = disc_view(props)
    scene = bpy.context.scene
    n = DISC_PIXELS
    node.sun_disc = True
    with_disc = _render(scene, 8, n, n, 1.5)   # a wide filter: the disc's edge antialiased
    # the sky without the disc: the model (within 1e-3 of Cycles' sky, above), at the pixels'
    # directions; the sky is 1e-3 of the disc's radiance here
    cycles = ((with_disc - _sky_model(node, dirs)) * omega[..., None]).sum((0, 1))
    report = ExportReport()
    light = sky.sky_sun(node, 1.0, np.eye(3), "test", report)
    assert np.allclose(light["direction"], -np.asarray(towards), atol=1e-6)
    mine = np.asarray(light["strength"])
    print(f"sun disc {props}: Lantern {mine}, Cycles {cycles}")
    assert np.abs(mine / cycles - 1.0).max() < TOL, (mine, cycles)
    assert controls_fail(mine / cycles)
    intensity = node.sun_intensity
    node.sun_intensity = intensity * 1.03
    brighter = np.asarray(sky.sky_sun(node, 1.0, np.eye(3), "test", report)["strength"])
    assert np.abs(brighter / cycles - 1.0).max() > TOL
    node.sun_intensity = intensity
    # the disc Lantern's camera sees (the world's sun light, drawn for camera rays), summed
    # like Cycles' over K seeds, against the light's strength (itself within 0.5 % of Cycles'
    # disc, above) as exact: a stated cap (measured, 2026-12-02: the drawn disc sums +0.09 %
    # and +0.19 % over it, 8 x 16 spp; over Cycles' +0.1 % and +0.3 %) + Student t at 1e-3,
    # with the 1 % / 5 % controls (one value: the block is the image) and the swapped
    # channels; false alarms: tools/false_alarm.py's sun_disc family (was within 1 % + 4 se of
    # 4 seeds of Cycles': a 1 % bias passed)
    _, disc_scene, lantern_sky = lantern_disc(node, omega)
    discs = disc_sums(disc_scene, omega, lantern_sky)
    res = metrics.assert_agreement(f"sun disc seen by Lantern's camera {props}", discs, mine,
                                   block=1, bias_cap=DISC_CAP)
    # the control: the same light as a sun lamp, which the camera does not see (Lantern
    # before the world's sun was drawn)
    lamp_scene = _export()
    lamp_scene.lights.append(lamp_scene.world.pop("sun"))
    lamp = _lantern(lamp_scene, omega, 1)[0] - lantern_sky
    assert np.all(np.abs(lamp / mine - 1.0) > res.mean_allowed.max()), lamp


def _sky_model(node, dirs):
    """The sky of `node` without its disc (Multiple or Single Scattering) at unit `dirs`."""
    from lantern_blender.export import sky
    params = sky._ms_params(node)
    if node.sky_type == "SINGLE_SCATTERING":
        return sky.sky_ss.table_radiance(sky.ss_table(params), dirs, params[1],
                                         sky._XYZ_TO_REC709)
    return sky.sky_ms.table_radiance(sky.sky_ms.sky_table(*params), dirs, sky._XYZ_TO_REC709)


def _export():
    """The current Blender scene exported to a Lantern scene (no warning about the sun)."""
    from lantern_blender.export import export_scene
    scene, report = export_scene(bpy.context.evaluated_depsgraph_get())
    assert not [m for m in report.messages if "sun" in m], report.messages
    return scene


def _lantern(scene, omega, seeds, seed0=0):
    """Lantern's images of `scene` summed over the pixels' solid angles, one row per seed."""
    import lantern
    out = []
    for seed in range(seed0, seed0 + seeds):
        s = lantern.Session(scene, integrator="pt", backend="cpu", max_depth=2, seed=seed,
                            spp_per_iteration=LANTERN_SPP)
        s.step()
        img = np.asarray(s.image(), np.float64)[..., :3]
        out.append((img * omega[..., None]).sum((0, 1)))
    return np.array(out)
