"""Shared by tools/make_cycles_refs.py and tests/render: the comparison settings, rendering a
blend scene with Cycles or Lantern in this bpy process, and per-block statistics over seeds."""

import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import lantern_bpy  # noqa: E402

ROOT = lantern_bpy.ROOT
REF_DIR = os.path.join(ROOT, "tests", "render", "refs")
BLOCK = 8
REPORT = []          # result lines of tests/render, printed in pytest's summary
SEEDS = 8            # independent renders per image (K)
CYCLES_SPP = 512     # per seed
BOUNCES = 16         # Cycles max_bounces (all kinds); Lantern max_depth = BOUNCES + 2


def lantern_depth(bounces):
    """Lantern max_depth (path segments, Mitsuba's convention) equivalent to Cycles max_bounces:
    Cycles' 0 bounces is direct light only, which is max_depth 2 (measured on the Cornell box,
    tests/render/test_bounces.py)."""
    return bounces + 2


def build_scene(name):
    """Build blend scene `name` into the current bpy data (saved under build/blend_scenes)."""
    sys.path.insert(0, os.path.join(ROOT, "blend_scenes"))
    import scenes
    return scenes.build(name)


def cycles_settings(scene, seed, spp, bounces=None, transparent_bounces=None, threads=None,
                    filter_size=None):
    """Cycles set to match Lantern (the one place these are written; tools/difftest.py and
    make_cycles_refs.py use it too): CPU, `spp` samples of `seed`, no adaptive sampling,
    denoising, clamping or light threshold, Filter Glossy 0, `bounces` of every kind
    (transparent: `transparent_bounces`, default `bounces`), Blackman-Harris 1.5 (and
    render.filter_size when given), opaque film, the Standard view, 32-bit EXR; `threads`
    fixes the thread count; `bounces` defaults to the module's BOUNCES at the call (tests set
    it). Returns the Cycles settings that matter."""
    if bounces is None:
        bounces = BOUNCES
    c = scene.cycles
    scene.render.engine = "CYCLES"
    c.device = "CPU"
    c.samples = spp
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.seed = seed
    c.use_animated_seed = False
    c.max_bounces = bounces
    for k in ("diffuse_bounces", "glossy_bounces", "transmission_bounces", "volume_bounces"):
        setattr(c, k, bounces)
    c.transparent_max_bounces = bounces if transparent_bounces is None else transparent_bounces
    c.blur_glossy = 0.0  # Filter Glossy (default 1) roughens glossy lobes after diffuse bounces
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.light_sampling_threshold = 0.0
    c.pixel_filter_type = "BLACKMAN_HARRIS"
    c.filter_width = 1.5
    if filter_size is not None:
        scene.render.filter_size = filter_size
    scene.render.film_transparent = False
    if threads is not None:
        scene.render.threads_mode = "FIXED"
        scene.render.threads = threads
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    s = scene.render.image_settings
    s.file_format = "OPEN_EXR"
    s.color_depth = "32"
    s.exr_codec = "ZIP"
    return {k: getattr(c, k) for k in (
        "device", "samples", "use_adaptive_sampling", "use_denoising", "seed", "max_bounces",
        "diffuse_bounces", "glossy_bounces", "transmission_bounces", "volume_bounces",
        "transparent_max_bounces", "sample_clamp_direct", "sample_clamp_indirect",
        "light_sampling_threshold", "pixel_filter_type", "filter_width")}


def render_cycles(seed, spp):
    """Render the current scene with Cycles; returns float32 (H, W, 3) and the settings."""
    import bpy
    scene = bpy.context.scene
    settings = cycles_settings(scene, seed, spp)
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "cycles.exr")
        scene.render.filepath = path
        bpy.ops.render.render(write_still=True)
        img = lantern_bpy.read_image_bpy(path)
    return img, settings


def export_current():
    """The current scene as the add-on exports it (a lantern.Scene)."""
    import bpy
    lantern_bpy.load_addon()
    from lantern_blender.export import export_scene
    return export_scene(bpy.context.evaluated_depsgraph_get())[0]


CYCLES_REFS = os.path.join(ROOT, "tests", "refs", "cycles")


def stored_cycles(path, spp, seed0, k_seeds, sources, block=BLOCK):
    """Cycles' k_seeds renders of the current scene (seeds seed0..) as per-seed block means,
    stored at `path` (lantern.testing.refs, tests/README.md "Stored references") and rendered
    again only when their key changes: the scene as the add-on exports it (every array Lantern
    receives, in an order-free form: refs.order_free), the Cycles settings cycles_settings
    writes (the seed aside), the samples and seeds, the bpy version, and the files in
    `sources` (what stages the scene, Cycles-only properties included: the test module and its
    staging helpers; an edit to one of them renders their references again). `block` 1 keeps
    the pixels (K, H, W, C) for tests that need more than block means."""
    import bpy
    from lantern.testing import refs
    settings = cycles_settings(bpy.context.scene, seed0, spp)
    settings.pop("seed")
    key = dict(scene=refs.order_free(export_current()), cycles=settings, spp=spp, seed0=seed0,
               k_seeds=k_seeds, bpy=bpy.app.version_string,
               sources=[refs.file_digest(p) for p in sources])
    return refs.reference_blocks(
        path, lambda: [render_cycles(seed=seed0 + k, spp=spp)[0] for k in range(k_seeds)], key,
        block=block)


def render_lantern(seed, spp, threads=0, integrator="pt"):
    """Export the current scene with the add-on and render it with lantern.Session."""
    import bpy
    import lantern
    lantern_bpy.load_addon()
    from lantern_blender.export import export_scene
    depsgraph = bpy.context.evaluated_depsgraph_get()
    scene, report = export_scene(depsgraph)
    session = lantern.Session(scene, integrator=integrator, backend="cpu",
                              max_depth=lantern_depth(BOUNCES), seed=seed, spp_per_iteration=spp, threads=threads)
    while session.spp < spp:
        session.step()
    return np.asarray(session.image(), dtype=np.float32)[..., :3], report.messages


def block_means(img, block=BLOCK):
    h, w = img.shape[:2]
    hb, wb = h // block, w // block
    x = img[:hb * block, :wb * block].reshape(hb, block, wb, block, -1)
    return x.mean(axis=(1, 3))


def stats_over_seeds(images):
    """Mean image, per-block means and standard errors of the mean over K seeded images."""
    imgs = np.stack(images).astype(np.float64)
    k = imgs.shape[0]
    blocks = np.stack([block_means(i) for i in imgs])
    return {"mean": imgs.mean(axis=0).astype(np.float32),
            "block_mean": blocks.mean(axis=0).astype(np.float32),
            "block_se": (blocks.std(axis=0, ddof=1) / np.sqrt(k)).astype(np.float32),
            "seed_block_means": blocks.astype(np.float32)}
