"""Issue 17 against Cycles, on blend_scenes/layers_passes.py (two view layers with their own
collections, Depth, Normal and the denoising data), both rendered by F12 through their engines
into multilayer EXRs:

- each view layer's Combined against Cycles: 8 seeds of 16 spp an engine,
  lantern.metrics.assert_agreement (8x8 blocks, the image mean) with its 1 % / 5 % negative
  controls (tests/README.md; was a 3 % bound on one render's mean);
- Depth within 1% (median relative difference over the pixels both see a surface in);
- Normal and Denoising Albedo within 0.05 (mean absolute difference over every pixel), and so
  Denoising Normal and Diffuse Color (on the seeds' mean passes);
- the border without crop: 8 seeds against Cycles' full frame over the border's pixels (Cycles'
  border render is its full render's pixels bit for bit, measured), with the same controls,
  and black outside; the border with crop: the same bits as the uncropped border with the same
  seed (Lantern's sampler keys the frame's pixels, the crop only writes fewer of them)."""

import os
import sys

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")
lantern = pytest.importorskip("lantern")
if not lantern.native_available():
    pytest.skip(f"native core unavailable: {lantern.native_error()}", allow_module_level=True)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.path.insert(0, os.path.join(ROOT, "blend_scenes"))
import exr_passes  # noqa: E402
import lantern_bpy  # noqa: E402
import layers_passes  # noqa: E402
import render_compare as rc  # noqa: E402
from lantern import metrics  # noqa: E402

# 8 seeds of 16 spp an engine (one render of 256 before): the renders cost mostly their F12
# overhead (~0.3-0.4 s each), so the seeds are few and short; Combined detects 0.59-0.71 %
# (a block 3.9-4.3 %), the border 0.88-1.04 % (4.1-4.3 %): every control caught
SEEDS, CYCLES_SPP, LANTERN_SPP = 8, 16, 16
LAYERS = ("Full", "NoProps")
# the border (layers_passes.set_border) in the 64 x 64 frame's pixel rows and columns, top first
BX0, BX1 = int(0.2 * 64), int(0.7 * 64)
BY0, BY1 = int(np.float32(0.15) * np.float32(64)), int(np.float32(0.65) * np.float32(64))


def _cycles(scene, seed):
    rc.cycles_settings(scene, seed=seed, spp=CYCLES_SPP)


def _lantern(scene, seed):
    scene.render.engine = "LANTERN"
    s = scene.lantern
    s.samples, s.integrator, s.backend, s.seed = LANTERN_SPP, "pt", "cpu", seed
    s.max_depth = rc.lantern_depth(rc.BOUNCES)


@pytest.fixture(scope="module")
def renders(tmp_path_factory):
    """{(engine, case): [passes per seed]}: cycles full; lantern full, nocrop (SEEDS seeds
    each) and crop (the first seed only)."""
    lantern_bpy.load_addon()
    tmp = tmp_path_factory.mktemp("layers_passes")
    out = {}
    for engine, setup, seed0, cases in (("cycles", _cycles, 100, ("full",)),
                                        ("lantern", _lantern, 1, ("full", "nocrop", "crop"))):
        for case in cases:
            for k in range(1 if case == "crop" else SEEDS):
                scene = layers_passes.layers_passes()
                setup(scene, seed0 + k)
                if case != "full":
                    layers_passes.set_border(scene, crop=case == "crop")
                out.setdefault((engine, case), []).append(
                    exr_passes.render_passes(scene, tmp / f"{engine}_{case}{k}.exr"))
    return out


def _combined(seeds, layer):
    return [p[layer, "Combined"][..., :3].astype(np.float64) for p in seeds]


def _mean_pass(seeds, layer, name):
    return np.mean([p[layer, name] for p in seeds], axis=0)


def _rel(a, b):
    return np.abs(a - b) / np.maximum(np.abs(b), 1e-12)


@pytest.mark.parametrize("layer", LAYERS)
def test_combined_per_view_layer(renders, layer):
    lan = _combined(renders["lantern", "full"], layer)
    cyc = _combined(renders["cycles", "full"], layer)
    ratio = np.mean(lan, axis=(0, 1, 2)) / np.mean(cyc, axis=(0, 1, 2))
    rc.REPORT.append(f"layers_passes {layer}: Combined mean Lantern/Cycles "
                     f"{np.round(ratio, 4).tolist()}")
    metrics.assert_agreement(f"layers_passes {layer} Combined vs Cycles", lan, cyc, block=8)


def test_view_layers_differ_where_the_props_are(renders):
    """The block is in one layer only: without it the frame is darker where it stood and its
    shadow is gone (so the layers are not one image written twice)."""
    first = renders["lantern", "full"][0]
    full = first["Full", "Combined"][..., :3]
    no_props = first["NoProps", "Combined"][..., :3]
    depth_full = first["Full", "Depth"][..., 0]
    depth_np = first["NoProps", "Depth"][..., 0]
    block = depth_full < depth_np - 0.1  # pixels where the block is in front of the floor
    assert block.sum() > 30
    assert np.abs(full - no_props).mean() > 0.01


@pytest.mark.parametrize("layer", LAYERS)
def test_depth_normal_albedo(renders, layer):
    lan, cyc = renders["lantern", "full"][0], renders["cycles", "full"][0]
    dl, dc = lan[layer, "Depth"][..., 0], cyc[layer, "Depth"][..., 0]
    hit = (dl < 1e9) & (dc < 1e9)
    assert hit.mean() > 0.5
    assert (dl >= 1e9).mean() == pytest.approx((dc >= 1e9).mean(), abs=0.02)
    depth = float(np.median(_rel(dl[hit], dc[hit])))
    normal = float(np.abs(lan[layer, "Normal"] - cyc[layer, "Normal"]).mean())
    albedo = float(np.abs(lan[layer, "Denoising Albedo"] - cyc[layer, "Denoising Albedo"]).mean())
    dnormal = float(np.abs(lan[layer, "Denoising Normal"] - cyc[layer, "Denoising Normal"]).mean())
    diffuse = float(np.abs(lan[layer, "Diffuse Color"] - cyc[layer, "Diffuse Color"]).mean())
    emission = float(np.abs(lan[layer, "Emission"] - cyc[layer, "Emission"]).mean())
    rc.REPORT.append(f"layers_passes {layer}: Depth median rel {depth:.5f}, Normal mean abs "
                     f"{normal:.4f}, Denoising Albedo {albedo:.4f}, Denoising Normal {dnormal:.4f}"
                     f", Diffuse Color {diffuse:.4f}, Emission {emission:.4f}")
    assert diffuse < 0.05
    assert emission < 1e-6  # nothing in the scene emits
    assert depth < 0.01
    assert normal < 0.05
    assert albedo < 0.05
    assert dnormal < 0.05


def test_border_against_cycles(renders):
    for layer in LAYERS:
        nocrop = _combined(renders["lantern", "nocrop"], layer)
        cyc = [c[64 - BY1:64 - BY0, BX0:BX1] for c in _combined(renders["cycles", "full"], layer)]
        inside = [n[64 - BY1:64 - BY0, BX0:BX1] for n in nocrop]
        outside = np.ones(nocrop[0].shape[:2], bool)
        outside[64 - BY1:64 - BY0, BX0:BX1] = False
        assert all((n[outside] == 0).all() for n in nocrop)  # nothing written beyond it
        ratio = np.mean(inside, axis=(0, 1, 2)) / np.mean(cyc, axis=(0, 1, 2))
        rc.REPORT.append(f"layers_passes {layer} border: mean Lantern/Cycles "
                         f"{np.round(ratio, 4).tolist()}")
        metrics.assert_agreement(f"layers_passes {layer} border vs Cycles", inside, cyc, block=8)


def test_crop_is_the_uncropped_border(renders):
    """Exact: the cropped border writes the uncropped border's pixels, the same bits."""
    for layer in LAYERS:
        crop = _combined(renders["lantern", "crop"], layer)[0]
        nocrop = _combined(renders["lantern", "nocrop"], layer)[0]
        assert crop.shape == (BY1 - BY0, BX1 - BX0, 3)
        np.testing.assert_array_equal(crop, nocrop[64 - BY1:64 - BY0, BX0:BX1])
