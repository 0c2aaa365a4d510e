"""Issue 17 against Cycles, on blend_scenes/layers_passes.py (two view layers with their own
collections, Depth, Normal and the denoising data), both rendered by F12 through their engines
into multilayer EXRs:

- each view layer's Combined mean within 3% (per channel);
- Depth within 1% (median relative difference over the pixels both see a surface in);
- Normal and Denoising Albedo within 0.05 (mean absolute difference over every pixel), and so
  Denoising Normal and Diffuse Color;
- border renders, crop and no crop, within 3% (mean over the frame they write).

At these sample counts the image means carry about 0.3% of noise (measured: the spread of the
block means), so 3% is a real bound on bias; the differences are printed in pytest's summary."""

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

CYCLES_SPP, LANTERN_SPP = 256, 256
LAYERS = ("Full", "NoProps")


def _cycles(scene):
    rc.cycles_settings(scene, seed=0, spp=CYCLES_SPP)


def _lantern(scene):
    scene.render.engine = "LANTERN"
    s = scene.lantern
    s.samples, s.integrator, s.backend, s.seed = LANTERN_SPP, "pt", "cpu", 1
    s.max_depth = rc.lantern_depth(rc.BOUNCES)


@pytest.fixture(scope="module")
def renders(tmp_path_factory):
    """{(engine, case): passes} for case in full, crop, nocrop."""
    lantern_bpy.load_addon()
    tmp = tmp_path_factory.mktemp("layers_passes")
    out = {}
    for engine, setup in (("cycles", _cycles), ("lantern", _lantern)):
        for case in ("full", "crop", "nocrop"):
            scene = layers_passes.layers_passes()
            setup(scene)
            if case != "full":
                layers_passes.set_border(scene, crop=case == "crop")
            out[engine, case] = exr_passes.render_passes(scene, tmp / f"{engine}_{case}.exr")
    return out


def _rel(a, b):
    return np.abs(a - b) / np.maximum(np.abs(b), 1e-12)


@pytest.mark.parametrize("layer", LAYERS)
def test_combined_per_view_layer(renders, layer):
    lan = renders["lantern", "full"][layer, "Combined"][..., :3].mean(axis=(0, 1))
    cyc = renders["cycles", "full"][layer, "Combined"][..., :3].mean(axis=(0, 1))
    rc.REPORT.append(f"layers_passes {layer}: Combined mean Lantern/Cycles "
                     f"{np.round(lan / cyc, 4).tolist()}")
    assert (_rel(lan, cyc) < 0.03).all(), (lan, cyc)


def test_view_layers_differ_where_the_props_are(renders):
    """The block is in one layer only: without it the frame is darker where it stood and its
    shadow is gone (so the layers are not one image written twice)."""
    full = renders["lantern", "full"]["Full", "Combined"][..., :3]
    no_props = renders["lantern", "full"]["NoProps", "Combined"][..., :3]
    depth_full = renders["lantern", "full"]["Full", "Depth"][..., 0]
    depth_np = renders["lantern", "full"]["NoProps", "Depth"][..., 0]
    block = depth_full < depth_np - 0.1  # pixels where the block is in front of the floor
    assert block.sum() > 30
    assert np.abs(full - no_props).mean() > 0.01


@pytest.mark.parametrize("layer", LAYERS)
def test_depth_normal_albedo(renders, layer):
    lan, cyc = renders["lantern", "full"], renders["cycles", "full"]
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


@pytest.mark.parametrize("case", ["crop", "nocrop"])
def test_border(renders, case):
    for layer in LAYERS:
        lan = renders["lantern", case][layer, "Combined"][..., :3]
        cyc = renders["cycles", case][layer, "Combined"][..., :3]
        assert lan.shape == cyc.shape
        ratio = lan.mean(axis=(0, 1)) / cyc.mean(axis=(0, 1))
        rc.REPORT.append(f"layers_passes {layer} border {case}: mean Lantern/Cycles "
                         f"{np.round(ratio, 4).tolist()}")
        assert (np.abs(ratio - 1) < 0.03).all()
    # the border is the same part of the frame as in the full render
    full = renders["lantern", "full"]["Full", "Combined"][..., :3]
    part = renders["lantern", case]["Full", "Combined"][..., :3]
    if case == "crop":
        x0, x1 = int(0.2 * 64), int(0.7 * 64)
        y0, y1 = int(np.float32(0.15) * np.float32(64)), int(np.float32(0.65) * np.float32(64))
        full = full[64 - y1:64 - y0, x0:x1]
    else:
        inside = part.sum(axis=2) > 0
        full = full[inside]
        part = part[inside]
    assert part.shape == full.shape
    np.testing.assert_allclose(part.mean(), full.mean(), rtol=0.03)
