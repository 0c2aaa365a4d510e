"""F12 through bpy.ops.render.render, checked on the written EXR (the operator returns FINISHED
even when the engine failed, so only the pixels tell)."""

import math

import bpy
import numpy as np
import pytest

import lantern
from blender_helpers import add_camera, add_plane, emission_material, render_exr, shader_material

pytestmark = pytest.mark.skipif(not lantern.session.native_available(),
                                reason="lantern native module not built")


def diffuse_bsdf(albedo):
    mat = bpy.data.materials.new("DiffuseBSDF")
    nodes = mat.node_tree.nodes
    nodes.remove(nodes["Principled BSDF"])
    d = nodes.new("ShaderNodeBsdfDiffuse")
    d.inputs["Color"].default_value = (albedo, albedo, albedo, 1)
    mat.node_tree.links.new(d.outputs[0], nodes["Material Output"].inputs["Surface"])
    return mat


def test_emissive_plane_fills_view(empty, tmp_path, errors):
    add_camera(empty, location=(0, 0, 5))
    add_plane(empty, size=100.0, material=emission_material(3.0, (1, 0.5, 0.25)))
    empty.lantern.samples = 4
    px = render_exr(empty, tmp_path)
    assert px.shape == (24, 32, 4)
    np.testing.assert_allclose(px[..., :3], np.broadcast_to([3, 1.5, 0.75], (24, 32, 3)),
                               rtol=1e-4)
    assert not [c for c in errors if c[0] == "ERROR"]


def test_sun_on_white_diffuse_plane(empty, tmp_path, errors):
    add_camera(empty, location=(0, 0, 5))
    add_plane(empty, size=100.0, material=diffuse_bsdf(0.5))
    sun = bpy.data.lights.new("Sun", "SUN")
    sun.energy = 2.0
    sun.angle = 0.0
    obj = bpy.data.objects.new("Sun", sun)
    empty.collection.objects.link(obj)  # default orientation shines down -Z: head-on
    empty.lantern.samples = 16
    px = render_exr(empty, tmp_path)
    expect = 0.5 * 2.0 / math.pi  # noise-free by construction: one sharp sun, one diffuse bounce
    np.testing.assert_allclose(px[..., :3].mean(), expect, rtol=1e-4)
    np.testing.assert_allclose(px[..., :3], expect, rtol=1e-4)
    assert not [c for c in errors if c[0] == "ERROR"]


def test_render_orientation_top_row_first(empty, tmp_path):
    """An emitter only in the upper half of the view shows in the top rows of the EXR,
    exactly: the view (50 mm at 5 m: 0.1125 m a pixel, y 1.35 m at the top) sees the emitter
    (y 1..5) in rows 0..3 (row 3 in part), so rows 0..1 read its radiance 1 and rows 6.. the
    black of no world, noise-free (a camera ray meets the emitter or nothing); was "the top
    rows' mean above 0.5 and the bottom's under 0.01"."""
    add_camera(empty, location=(0, 0, 5))
    add_plane(empty, size=4.0, location=(0, 3, 0), material=emission_material(1.0))
    empty.lantern.samples = 4
    px = render_exr(empty, tmp_path)
    np.testing.assert_allclose(px[:2, :, :3], 1.0, rtol=1e-4)
    assert (px[6:, :, :3] == 0.0).all()


def test_engine_failure_is_reported(empty, tmp_path, errors, monkeypatch):
    add_camera(empty)

    def broken(*args, **kwargs):
        raise RuntimeError("native module missing (mocked)")
    monkeypatch.setattr(lantern, "Session", broken)
    # an ERROR report reaches Python as the operator's RuntimeError; Blender itself carries on
    with pytest.raises(RuntimeError, match="mocked"):
        render_exr(empty, tmp_path)
    assert any("mocked" in msg for kind, msg in errors if kind == "ERROR")
    monkeypatch.undo()
    empty.lantern.samples = 1
    assert np.isfinite(render_exr(empty, tmp_path, "after.exr")).all()  # still renders


@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_bidirectional_integrators_through_f12(empty, tmp_path, errors, integrator):
    """The Integrator menu reaches the core: a sharp sun on a white plane renders rho E / pi
    with every bidirectional integrator (light tracing splats included)."""
    add_camera(empty, location=(0, 0, 5))
    add_plane(empty, size=100.0, material=diffuse_bsdf(0.5))
    sun = bpy.data.lights.new("Sun", "SUN")
    sun.energy = 2.0
    sun.angle = 0.0
    empty.collection.objects.link(bpy.data.objects.new("Sun", sun))
    empty.lantern.integrator = integrator
    empty.lantern.sort = "on"
    empty.lantern.connections = 3
    empty.lantern.samples = 16
    px = render_exr(empty, tmp_path)
    expect = 0.5 * 2.0 / math.pi  # exact for every integrator: the plane sees only the sun
    assert np.isfinite(px).all()
    np.testing.assert_allclose(px[..., :3].mean(), expect, rtol=1e-4)
    np.testing.assert_allclose(px[..., :3], expect, rtol=1e-4)
    assert not [c for c in errors if c[0] == "ERROR"]


def test_unsupported_setting_is_reported(empty, tmp_path, errors):
    """A setting the core refuses (here a connection count past its limit, set through the
    Python API around the UI's range) is an ERROR report, not a crash."""
    add_camera(empty)
    empty.lantern.integrator = "cis"
    with pytest.raises(ValueError) as refused:
        lantern.Session(lantern.Scene(), integrator="cis", connections=100)
    import lantern_blender.properties as props  # the add-on's module in these tests
    original = props.LanternSceneSettings.session_settings

    def too_many(self, preview=False):
        return dict(original(self, preview), connections=100)
    props.LanternSceneSettings.session_settings = too_many
    try:
        with pytest.raises(RuntimeError, match="Lantern"):
            render_exr(empty, tmp_path)
    finally:
        props.LanternSceneSettings.session_settings = original
    assert any(str(refused.value)[:30] in msg for kind, msg in errors if kind == "ERROR")


def test_time_limit_stops_early(empty, tmp_path):
    add_camera(empty)
    add_plane(empty, size=100.0, location=(0, 0, -5), material=emission_material(1.0))
    empty.render.resolution_x, empty.render.resolution_y = 320, 240
    empty.lantern.samples = 1_000_000
    empty.lantern.time_limit = 0.5
    import time
    t = time.perf_counter()
    px = render_exr(empty, tmp_path)
    assert time.perf_counter() - t < 10
    np.testing.assert_allclose(px[..., :3], 1.0, rtol=1e-4)


def test_a_time_limit_shorter_than_a_sample_still_gives_one(empty, tmp_path):
    """The first sample is never cut (a loaded machine made the 0.5 s limit above fall inside
    it: 0 spp, a black frame); what comes after it is."""
    add_camera(empty)
    add_plane(empty, size=100.0, location=(0, 0, -5), material=emission_material(1.0))
    empty.render.resolution_x, empty.render.resolution_y = 480, 360  # a step > 50 ms
    empty.lantern.samples = 1_000_000
    empty.lantern.time_limit = 1e-6
    px = render_exr(empty, tmp_path)
    np.testing.assert_allclose(px[..., :3], 1.0, rtol=1e-4)


# ---- Bad input through F12: a finite image, nothing escapes, warnings reported ----

def test_empty_scene_with_camera(empty, tmp_path, errors):
    add_camera(empty)
    px = render_exr(empty, tmp_path)
    assert np.isfinite(px).all() and px[..., :3].max() == 0
    assert not [c for c in errors if c[0] == "ERROR"]


def test_nan_vertices_and_degenerate_triangles(empty, tmp_path, errors):
    add_camera(empty, location=(0, 0, 5))
    mesh = bpy.data.meshes.new("Bad")
    nan = float("nan")
    mesh.from_pydata([(-50, -50, 0), (50, -50, 0), (50, 50, 0), (-50, 50, 0),
                      (nan, 0, 0), (0, nan, 1), (0, 0, nan),
                      (1, 1, 1), (1, 1, 1), (2, 2, 2)],
                     [], [(0, 1, 2, 3), (4, 5, 6), (7, 8, 9)])
    mesh.materials.append(emission_material(2.0))
    obj = bpy.data.objects.new("Bad", mesh)
    empty.collection.objects.link(obj)
    empty.lantern.samples = 2
    px = render_exr(empty, tmp_path)
    assert np.isfinite(px).all()
    np.testing.assert_allclose(px[..., :3], 2.0, rtol=1e-4)
    assert not [c for c in errors if c[0] == "ERROR"]
    assert any("non-finite" in msg for kind, msg in errors if kind == "WARNING")


def test_object_without_material(empty, tmp_path, errors):
    add_camera(empty, location=(0, 0, 5))
    add_plane(empty, size=100.0)
    world = bpy.data.worlds.new("W")
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
    empty.world = world
    empty.lantern.samples = 8
    px = render_exr(empty, tmp_path)
    assert np.isfinite(px).all() and 0 < px[..., :3].mean() < 1
    assert not [c for c in errors if c[0] == "ERROR"]


def test_camera_inside_geometry(empty, tmp_path, errors):
    bpy.ops.mesh.primitive_cube_add(size=4)
    add_camera(empty, location=(0, 0, 0))
    light = bpy.data.lights.new("P", "POINT")
    light.energy = 100
    obj = bpy.data.objects.new("P", light)
    obj.location = (0.5, 0.5, 0.5)
    empty.collection.objects.link(obj)
    empty.lantern.samples = 4
    px = render_exr(empty, tmp_path)
    assert np.isfinite(px).all() and px[..., :3].mean() > 0
    assert not [c for c in errors if c[0] == "ERROR"]


class _FakeEngine:
    """Stands in for the RenderEngine: test_break turns true after `breaks_after` polls."""

    def __init__(self, breaks_after):
        self.polls, self.breaks_after = 0, breaks_after
        self.stats, self.updates = [], 0

    def test_break(self):
        self.polls += 1
        return self.polls > self.breaks_after

    def update_result(self, result):
        self.updates += 1

    def update_stats(self, a, b):
        self.stats.append(b)

    def update_progress(self, p):
        pass


class _FakeResult:
    class _Pass:
        rect = None

    def __init__(self):
        self.layers = [type("L", (), {"passes": {"Combined": self._Pass()}})()]


def test_cancel_stops_within_an_iteration(addon):
    """test_break during a long iteration cancels it: the loop returns well before the
    iteration would have finished, keeping the last finished image."""
    import time
    scene = lantern.Scene()
    scene.film = {"width": 512, "height": 512, "filter_width": 1.5}
    m = scene.add_material(emission=(1, 1, 1))
    scene.meshes.append({"name": "quad", "material_ids": np.array([m, m], np.uint32),
                         "positions": np.array([[-9, -9, -1], [9, -9, -1], [9, 9, -1], [-9, 9, -1]],
                                               np.float32),
                         "indices": np.array([[0, 1, 2], [0, 2, 3]], np.uint32)})
    session = lantern.Session(scene, spp_per_iteration=1, integrator="pt")
    t = time.perf_counter()
    session.step()
    one = time.perf_counter() - t
    session = lantern.Session(scene, spp_per_iteration=max(64, int(64 * 0.5 / max(one, 1e-4))),
                              integrator="pt")
    engine = _FakeEngine(breaks_after=1)
    t = time.perf_counter()
    addon.engine._render_loop(engine, session, _FakeResult(), 10**9, 0.0, t)
    assert time.perf_counter() - t < 2.0
    assert engine.stats and engine.stats[-1].startswith("Sample ")


# ---- Light units through the add-on (Cycles' conventions, docs/scene_format.md) ----

def _light(scene, kind, location, **props):
    data = bpy.data.lights.new(kind, kind)
    for k, v in props.items():
        setattr(data, k, v)
    obj = bpy.data.objects.new(kind, data)
    obj.location = location
    scene.collection.objects.link(obj)
    return obj


def _point_over_plane(power, height, albedo, cam_height, lens_mm, w, h, sub=16):
    """Exact pixel values (H, W) of a point light `height` over a diffuse plane seen straight
    down by a camera at `cam_height` (sensor 36 mm, fit to the width): (a / pi) (P / 4 pi)
    h / r^3 (the cos^3 falloff), averaged over sub x sub points of each pixel's area."""
    half_w = cam_height * 18.0 / lens_mm
    half_h = half_w * h / w
    x = ((np.arange(w * sub) + 0.5) / (w * sub) * 2 - 1) * half_w
    y = ((np.arange(h * sub) + 0.5) / (h * sub) * 2 - 1) * half_h
    xx, yy = np.meshgrid(x, y)
    r = np.sqrt(xx ** 2 + yy ** 2 + height ** 2)
    val = albedo / math.pi * power / (4 * math.pi) * height / r ** 3
    return val.reshape(h, sub, w, sub).mean(axis=(1, 3))


def test_point_light_power_units(empty, tmp_path):
    """A point light of P watts at height h over a diffuse plane (albedo 0.5): radiance under
    it is 0.5/pi * P/(4 pi h^2), falling off as cos^3 away from it (integrated per pixel)."""
    add_camera(empty, location=(0, 0, 5), lens=500)
    add_plane(empty, size=100.0, material=diffuse_bsdf(0.5))
    _light(empty, "POINT", (0, 0, 2), energy=1000.0, shadow_soft_size=0.0)
    empty.lantern.samples = 4
    px = render_exr(empty, tmp_path)[..., :3].astype(np.float64)
    expect = _point_over_plane(1000.0, 2.0, 0.5, 5.0, 500.0, px.shape[1], px.shape[0])
    print(f"point light units: mean {px.mean():.6f}, expected {expect.mean():.6f} (on the "
          f"axis {0.5 / math.pi * 1000.0 / (4 * math.pi * 4.0):.6f})")
    # no noise but the pixel filter's jitter over a smooth cos^3 falloff: 1e-4 on the mean
    np.testing.assert_allclose(px.mean(), expect.mean(), rtol=1e-4)
    np.testing.assert_allclose(px, np.broadcast_to(expect[..., None], px.shape), rtol=1e-3)


def test_area_light_seen_by_camera(empty, tmp_path):
    """An area light of power P and area A has radiance P/(pi A) on its front: pi*100 W over a
    10 m square filling the view renders 1.0 when its object is visible to camera rays."""
    add_camera(empty, location=(0, 0, 0), rotation=(math.pi, 0, 0))  # looking up +Z
    light = _light(empty, "AREA", (0, 0, 1), energy=math.pi * 100.0, size=10.0)
    light.visible_camera = True
    empty.lantern.samples = 4
    px = render_exr(empty, tmp_path)
    np.testing.assert_allclose(px[..., :3], 1.0, rtol=1e-3)


def seed_renders(scene, tmp_path, stem, seeds):
    """One F12 per seed (scene.lantern.seed, or scene.cycles.seed when Cycles renders): the
    written EXRs' RGB as float64."""
    out = []
    for seed in seeds:
        scene.lantern.seed = seed
        scene.cycles.seed = seed
        out.append(render_exr(scene, tmp_path, f"{stem}{seed}.exr")[..., :3].astype(np.float64))
    return out


def direct_light_scene(scene):
    """test_matches_cycles_direct_light's scene: a point light and a sun over a diffuse plane."""
    add_camera(scene, location=(0, 0, 5), lens=80)
    add_plane(scene, size=100.0, material=diffuse_bsdf(0.5))
    _light(scene, "POINT", (0.3, 0.2, 2), energy=500.0, shadow_soft_size=0.0)
    _light(scene, "SUN", (0, 0, 0), energy=1.0, angle=0.0)


def direct_light_cycles(scene, tmp_path, seeds, spp):
    """The same scene through Cycles (CPU, clamps and light threshold off), one F12 a seed."""
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device, c.samples, c.use_denoising, c.use_adaptive_sampling = "CPU", spp, False, False
    c.sample_clamp_indirect, c.sample_clamp_direct = 0.0, 0.0
    c.light_sampling_threshold = 0.0
    c.max_bounces = 12
    c.use_animated_seed = False
    scene.render.filter_size = 1.5
    return seed_renders(scene, tmp_path, "cycles", seeds)


def test_matches_cycles_direct_light(empty, tmp_path):
    """The same small scene (sun + point light over a diffuse plane) through Cycles and through
    Lantern, K seeds each: lantern.metrics.assert_agreement (8x8 blocks, image
    means, negative controls; Cycles' clamp and light threshold off)."""
    from lantern import metrics
    direct_light_scene(empty)
    # no world: with a grey world beside the two lights Lantern's pixels scatter 15x wider
    # than Cycles' (std 3.1 against 0.21 at 16 spp), see tests/README.md, "Noticed"
    # Lantern picks the sun (its power over the 100 m plane's disk) far more often than the
    # point light; without the world its blocks still come out nearly noise-free (the same
    # block means to 1e-5 at 64, 256 and 1024 spp; Cycles' 8 x 16 spp is the noise: se 5e-5
    # on a block of 1.4), so 16 seeds of 64 spp (was 32 of 1024, 37-47 s against 1.6 s) keep
    # what it resolves: the image 0.21 % (the cap), the +5 % block at z in the hundreds
    k, spp = 8, 16
    empty.lantern.samples = DIRECT_SPP
    lan = seed_renders(empty, tmp_path, "lantern", range(1, 1 + DIRECT_SEEDS))
    cyc = direct_light_cycles(empty, tmp_path, range(100, 100 + k), spp)
    metrics.assert_agreement("direct light vs Cycles", lan, cyc, block=8)


DIRECT_SEEDS, DIRECT_SPP = 16, 64


def test_missing_lantern_package_is_reported(empty, tmp_path, errors, monkeypatch):
    import sys
    add_camera(empty)
    monkeypatch.setitem(sys.modules, "lantern", None)  # import lantern -> ImportError
    with pytest.raises(RuntimeError, match="not importable"):
        render_exr(empty, tmp_path)
    assert any("pip install" in msg for kind, msg in errors if kind == "ERROR")


def mirror_scene(scene, integrator):
    """A white F82 mirror under an emissive ceiling of strength 2, 16 x 16, 1 spp."""
    add_camera(scene, location=(0, 0, 1), rotation=(0, 0, 0), lens=80.0)  # looks down -Z
    mirror = shader_material("Mirror", "ShaderNodeBsdfMetallic", **{
        "Base Color": (1, 1, 1, 1), "Edge Tint": (1, 1, 1, 1), "Roughness": 0.0})[0]
    add_plane(scene, size=100.0, location=(0, 0, 0), material=mirror, name="Floor")
    add_plane(scene, size=100.0, location=(0, 0, 3), material=emission_material(2.0),
              name="Ceiling")
    scene.lantern.integrator = integrator
    scene.lantern.samples = 1  # the mirror is exact sample by sample
    scene.lantern.max_depth = 4
    scene.render.resolution_x, scene.render.resolution_y = 16, 16


def add_glass_pane(scene):
    """A smooth glass pane (IOR 1.5) over the mirror; max_depth 8, GLASS_SPP a seed."""
    glass = shader_material("Glass", "ShaderNodeBsdfGlass", **{"Roughness": 0.0, "IOR": 1.5})[0]
    add_plane(scene, size=100.0, location=(0, 0, 0.5), material=glass, name="Pane")
    scene.lantern.max_depth = 8
    scene.lantern.samples = GLASS_SPP


@pytest.mark.parametrize("integrator", ["pt", "cis"])
def test_mirror_and_glass_through_f12(empty, tmp_path, errors, integrator):
    """Analytic: a white F82 mirror (F0 = 1: reflectance 1 at every angle) under the camera
    shows the emissive ceiling (strength 2) exactly; a smooth glass pane (IOR 1.5) over it
    changes nothing in expectation: the pane and the mirror absorb nothing, and every path
    ends on the ceiling. The pane reflects F, passes 1 - F into the glass, and what comes back
    up leaves with 1 - F or goes down again with F: F + (1 - F)^2 (1 + F + F^2 + ...) = 1 at
    every angle (a parallel pane keeps it; radiance crosses it unscaled, as in Cycles). max_depth 8
    cuts the series after F^2 at the latest: 1 - O(F^3), under 1e-4. Exact value, noise from
    the stochastic reflect/transmit choice: 16 seeds against 2, lantern.metrics.assert_agreement
    with its 1 % / 5 % controls (cap 1e-4). Two interfaces without the returns, (1 - F)^2 + F =
    0.962, read 18 se off."""
    from lantern import metrics
    mirror_scene(empty, integrator)
    px = render_exr(empty, tmp_path)
    np.testing.assert_allclose(px[..., :3], 2.0, rtol=1e-3)
    add_glass_pane(empty)
    seeds = seed_renders(empty, tmp_path, "glass", range(1, 1 + GLASS_SEEDS))
    print(f"glass pane ({integrator}): mean / 2 = {np.mean(seeds) / 2.0:.5f}")
    metrics.assert_agreement(f"glass pane over a mirror ({integrator})", seeds, 2.0, block=4,
                             bias_cap=1e-4)
    assert not [c for c in errors if c[0] == "ERROR"]


# 16 seeds of 16 spp at 16x16 (was one render of 8 spp at 32x24 checked as 0.85 < r < 1;
# then 4 spp). Since refraction no longer scales radiance by 1/eta^2 (docs/materials.md) a
# path's throughput stays 1 through the pane, so roulette rarely acts and a block's noise is a
# few rare events: at 4 spp 2 of 4 seed sets read a block at |z| 6.9 and 8.7 (false alarms of
# a t-test on heavy tails; 64 seeds: mean / 2 = 0.99985 +- 0.00028), at 16 spp none above 3.8.
# F12 overhead (~12 ms a render) is most of the time
GLASS_SEEDS, GLASS_SPP = 16, 16


FURNACE_SEEDS, FURNACE_SPP = 16, 8
# a convex object sees only the world: one bounce, albedo 1 -> radiance 1. The sphere (radius 1
# at 6 m, 80 mm lens: ~24 px across) covers the inner 16 x 16 square, out to ~0.94 of its
# radius at the corners (grazing light included)
FURNACE_CROP = (slice(8, 24), slice(8, 24))


def furnace_scene(scene, integrator):
    """A white Principled sphere (part metal, a coat) under a uniform white world, 32 x 32."""
    add_camera(scene, location=(0, 0, 6), lens=80.0)
    world = bpy.data.worlds.new("White")
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    scene.world = world
    mat = bpy.data.materials.new("WhitePrincipled")
    p = mat.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (1, 1, 1, 1)
    p.inputs["Metallic"].default_value = 0.3
    p.inputs["Roughness"].default_value = 0.6
    p.inputs["Coat Weight"].default_value = 0.5
    p.inputs["Coat Roughness"].default_value = 0.2
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=1.0)
    obj = bpy.context.object
    bpy.ops.object.shade_smooth()
    obj.data.materials.append(mat)
    scene.lantern.integrator = integrator
    scene.lantern.samples = FURNACE_SPP
    scene.lantern.max_depth = 8
    scene.render.resolution_x, scene.render.resolution_y = 32, 32


@pytest.mark.parametrize("integrator", ["pt", "cis"])
def test_white_principled_furnace_through_f12(empty, tmp_path, errors, integrator):
    """A white Principled BSDF (base 1, part metal, a coat, multiscatter GGX) on a sphere under a
    uniform white world reflects exactly the world: every pixel 1 in expectation (the layering
    and the multiple-scattering compensation conserve energy; any loss or gain shows as a
    ring). Exact value, noise from the seeds: lantern.metrics.assert_agreement against 1 over
    the sphere's inner square (16 seeds, 4x4 blocks, bias cap 1e-4), with its 1 % / 5 %
    negative controls."""
    from lantern import metrics
    furnace_scene(empty, integrator)
    full = seed_renders(empty, tmp_path, "furnace", range(1, 1 + FURNACE_SEEDS))
    assert all(np.isfinite(px).all() for px in full)
    sphere = [px[FURNACE_CROP] for px in full]
    mean = np.mean(sphere, axis=0)
    print(f"white principled furnace ({integrator}): sphere mean {mean.mean():.5f}, "
          f"min {mean.min():.3f}, max {mean.max():.3f}")
    metrics.assert_agreement(f"white principled furnace ({integrator})", sphere, 1.0,
                             block=4, bias_cap=1e-4)
    assert not [c for c in errors if c[0] == "ERROR"]


def test_backend_choice_is_reported(empty, tmp_path, errors, addon, monkeypatch):
    """The Device setting reaches the session; the render report says which backend rendered;
    asking for the GPU where none is usable renders on the CPU with a warning (not an error)."""
    infos = []
    orig = addon.engine._report_info
    monkeypatch.setattr(addon.engine, "_report_info",
                        lambda eng, msg: (infos.append(msg), orig(eng, msg)))
    add_camera(empty, location=(0, 0, 5))
    add_plane(empty, size=100.0, material=emission_material(2.0, (1, 1, 1)))
    empty.lantern.samples = 2
    empty.lantern.backend = "cuda"
    px = render_exr(empty, tmp_path)
    np.testing.assert_allclose(px[..., :3], 2.0, rtol=1e-4)
    assert not [c for c in errors if c[0] == "ERROR"], errors
    gpu_missing = lantern.session.backend_unavailable("cuda")
    if gpu_missing:
        assert infos == ["rendering on the CPU"], infos
        assert any(c[0] == "WARNING" and "CUDA" in c[1] for c in errors), errors
    else:
        assert infos == ["rendering on the GPU (CUDA)"], infos
    infos.clear()
    empty.lantern.backend = "cpu"
    render_exr(empty, tmp_path)
    assert infos == ["rendering on the CPU"]


def test_device_choices():
    from lantern_blender.properties import LanternSceneSettings
    items = LanternSceneSettings.__annotations__["backend"].keywords["items"]
    assert [(i[0], i[1]) for i in items] == [("auto", "Auto"), ("cuda", "GPU (CUDA)"),
                                             ("cpu", "CPU")]
