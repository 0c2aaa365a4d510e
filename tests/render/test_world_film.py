"""Transparent film with holdouts and a shadow catcher against Cycles
(blend_scenes/world_scenes.py: world_film_holdout: a holdout object and a Holdout-shader sphere
on the stage, transparent film over a constant world, one area light; world_film_catcher: the
same with the floor a shadow catcher). RGB through lantern.metrics.assert_agreement (Welch
blocks and image-mean tests, negative controls); alpha per 8x8 block within 0.02 of Cycles'
(issue 15), and exactly 0 inside the holdouts.

The Cycles references need transparent film, which tools/make_cycles_refs.py turns off, so this
module makes its own:

    .venv/bin/python tests/render/test_world_film.py [--scene NAME] [--spp 128] [--seeds 8]
"""

import json
import os
import sys
import tempfile

import numpy as np
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.path.insert(0, os.path.join(ROOT, "blend_scenes"))
NAMES = ("world_film_holdout", "world_film_catcher")

bpy = pytest.importorskip("bpy")
import render_compare as rc  # noqa: E402

# beside, not in, refs/: test_cycles_compare.py compares every refs/*.npz as an opaque RGB scene
REF_DIR = os.path.join(rc.REF_DIR, "film")
SEEDS = int(os.environ.get("LANTERN_TEST_SEEDS", "16"))
SPP = int(os.environ.get("LANTERN_TEST_SPP", "128"))
# (seeds, spp) per scene, fewer than the default where the negative controls still fail
# (CI time); the catcher scene renders three times per seed (lantern/film.py)
RUNS = {"world_film_holdout": (max(4, SEEDS // 2), max(16, SPP // 2)),
        "world_film_catcher": (max(4, SEEDS // 2), max(16, SPP // 4))}


def ref_path(name):
    return os.path.join(REF_DIR, name + ".npz")


def build(name):
    import world_scenes
    getattr(world_scenes, name)()


def render_cycles_rgba(seed, spp):
    """Cycles with the comparison settings, transparent film kept: (H, W, 4), top row first."""
    import lantern_bpy
    scene = bpy.context.scene
    settings = rc.cycles_settings(scene, seed, spp)
    scene.render.film_transparent = True       # cycles_settings turns it off
    scene.render.image_settings.color_mode = "RGBA"
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "cycles.exr")
        scene.render.filepath = path
        bpy.ops.render.render(write_still=True)
        img = bpy.data.images.load(path, check_existing=False)
        try:
            w, h = img.size
            px = np.empty(w * h * 4, np.float32)
            img.pixels.foreach_get(px)
        finally:
            bpy.data.images.remove(img)
    del lantern_bpy
    return px.reshape(h, w, 4)[::-1].copy(), settings


def render_lantern_rgba(seed, spp):
    """The add-on's export, pt for the colour and lantern.film for the alpha: (H, W, 4)."""
    import lantern
    from lantern.film import render_alpha
    rc.lantern_bpy.load_addon()
    from lantern_blender.export import export_scene
    scene, report = export_scene(bpy.context.evaluated_depsgraph_get())
    s = lantern.Session(scene, integrator="pt", backend="cpu",
                        max_depth=rc.lantern_depth(rc.BOUNCES), seed=seed, spp_per_iteration=spp)
    s.step()
    rgb = np.asarray(s.image(), np.float32)[..., :3]
    alpha = render_alpha(scene, spp=spp, seed=seed, backend="cpu",
                         max_depth=rc.lantern_depth(rc.BOUNCES))
    return np.concatenate([rgb, alpha[..., None]], axis=2), report.messages


def make_reference(name, spp, seeds):
    build(name)
    images = [render_cycles_rgba(1000 + k, spp)[0] for k in range(seeds)]
    st = rc.stats_over_seeds(images)
    os.makedirs(REF_DIR, exist_ok=True)
    np.savez_compressed(ref_path(name), **st)
    with open(os.path.join(REF_DIR, name + ".json"), "w") as f:
        json.dump({"scene": name, "blend_script": "blend_scenes/world_scenes.py:" + name,
                   "renderer": "Cycles (CPU), transparent film, RGBA",
                   "blender_version": bpy.app.version_string, "spp_per_seed": spp,
                   "seeds": [1000 + k for k in range(seeds)], "block": rc.BLOCK,
                   "image_mean_rgba": st["mean"].reshape(-1, 4).mean(0).tolist()}, f, indent=1)
        f.write("\n")


@pytest.fixture(scope="module", params=NAMES)
def renders(request):
    name = request.param
    lantern = pytest.importorskip("lantern")
    if not lantern.native_available():
        pytest.skip(f"native core not available: {lantern.native_error()}")
    if not os.path.exists(ref_path(name)):
        pytest.skip(f"no Cycles reference {ref_path(name)} (run this file as a script)")
    build(name)
    seeds, spp = RUNS[name]
    out = [render_lantern_rgba(k + 1, spp) for k in range(seeds)]
    return name, [img for img, _ in out], out[0][1], dict(np.load(ref_path(name)))


def test_film_colour_matches_cycles(renders):
    from lantern import metrics
    name, images, warnings, ref = renders
    assert not warnings, f"export warnings: {warnings}"
    cycles = metrics.SeedBlocks(ref["seed_block_means"][..., :3])
    metrics.assert_agreement(name, [i[..., :3] for i in images], cycles, block=rc.BLOCK)


def test_film_alpha_matches_cycles(renders):
    """The film's alpha against Cycles' (its stored per-seed block means): the partly
    transparent blocks (edges, the catcher's shadows) by lantern.metrics.assert_agreement with
    its 1 % / 5 % negative controls; the blocks Cycles renders fully transparent or opaque in
    every seed are where the noise-free ones must be."""
    from lantern import metrics
    name, images, _, ref = renders
    alpha = [i[..., 3:] for i in images]
    cycles = metrics.SeedBlocks(ref["seed_block_means"][..., 3:])
    cyc = ref["block_mean"][..., 3]
    partial = (cyc > 0.01) & (cyc < 0.99)
    assert partial.sum() >= 8, partial.sum()
    metrics.assert_agreement(f"{name} alpha", alpha, cycles, block=rc.BLOCK, mask=partial)
    lan = np.mean([rc.block_means(a) for a in alpha], axis=0)[..., 0]
    rc.REPORT.append(f"{name} alpha: block means max |lantern - cycles| "
                     f"{np.abs(lan - cyc).max():.4f} (mean alpha lantern {lan.mean():.4f}, "
                     f"cycles {cyc.mean():.4f})")
    # the holdouts cut the film: some blocks are fully transparent in both, others opaque
    clear = cycles.blocks[..., 0].max(axis=0) == 0
    opaque = cycles.blocks[..., 0].min(axis=0) == 1
    assert clear.any() and opaque.any()
    assert (lan[clear] < 0.01).all() and (lan[opaque] > 0.99).all()
    if name == "world_film_catcher":  # the shadows on the catcher: partly transparent blocks
        assert ((cyc > 0.1) & (cyc < 0.9)).any()


if __name__ == "__main__":
    import argparse
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=128)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--scene", choices=NAMES, default=None, help="default: all")
    a = ap.parse_args()
    for n in ([a.scene] if a.scene else NAMES):
        make_reference(n, a.spp, a.seeds)
