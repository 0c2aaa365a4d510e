"""F12 with view layers, border renders, the resolution percentage and the data passes, read
back from a multilayer EXR. Emissive planes give closed-form pixels: an emitter that fills the
view renders as its emission exactly."""

import bpy
import numpy as np
import pytest

import lantern
from blender_helpers import (add_camera, add_plane, emission_material, render_exr,
                             shader_material)
from multilayer import render_passes

pytestmark = pytest.mark.skipif(not lantern.session.native_available(),
                                reason="lantern native module not built")


def _collection(scene, name):
    col = bpy.data.collections.new(name)
    scene.collection.children.link(col)
    return col


def _move(obj, col):
    for c in list(obj.users_collection):
        c.objects.unlink(obj)
    col.objects.link(obj)


def test_each_view_layer_renders_its_own_collections(empty, tmp_path, errors):
    add_camera(empty, location=(0, 0, 5))
    red = add_plane(empty, size=100.0, material=emission_material(2.0, (1, 0, 0)), name="Red")
    green = add_plane(empty, size=100.0, location=(0, 0, 1),
                      material=emission_material(3.0, (0, 1, 0)), name="Green")
    _move(red, _collection(empty, "RedSet"))
    _move(green, _collection(empty, "GreenSet"))
    first = empty.view_layers[0]
    first.name = "OnlyRed"
    second = empty.view_layers.new("OnlyGreen")
    first.layer_collection.children["GreenSet"].exclude = True
    second.layer_collection.children["RedSet"].exclude = True
    empty.lantern.samples = 2
    out = render_passes(empty, tmp_path / "layers.exr")
    np.testing.assert_allclose(out[("OnlyRed", "Combined")][..., :3],
                               np.broadcast_to([2, 0, 0], (24, 32, 3)), rtol=1e-5)
    np.testing.assert_allclose(out[("OnlyGreen", "Combined")][..., :3],
                               np.broadcast_to([0, 3, 0], (24, 32, 3)), rtol=1e-5)
    assert not [c for c in errors if c[0] == "ERROR"]


def _split_scene(scene):
    """Left of x = 0.3 red, right of it blue (two emitters side by side), seen from above."""
    add_camera(scene, location=(0, 0, 5))
    left = add_plane(scene, size=20.0, location=(-9.7, 0, 0),
                     material=emission_material(1.0, (1, 0, 0)), name="Left")
    right = add_plane(scene, size=20.0, location=(10.3, 0, 0),
                      material=emission_material(1.0, (0, 0, 1)), name="Right")
    return left, right


def _red_fraction(columns, edge, filter_size=1.5):
    """Expected red fraction of pixel columns `columns` when the red/blue edge is at raster x
    `edge`: a sample of column c lands at c + 0.5 + t, t drawn from the Blackman-Harris window
    over [-w, w], w = Blender's filter size (Cycles' placement, one sample one pixel), so
    the fraction is the window's CDF at edge - c - 0.5 (closed form, not Lantern's table)."""
    width = 2.0 * filter_size
    x = np.clip(edge - np.asarray(columns, float) - 0.5, -width / 2, width / 2)
    v = 2 * np.pi * (x / width + 0.5)
    a0, a1, a2, a3 = 0.35875, 0.48829, 0.14128, 0.01168
    area = a0 * (x + width / 2) - width / (2 * np.pi) * (
        a1 * np.sin(v) - a2 * np.sin(2 * v) / 2 + a3 * np.sin(3 * v) / 3)
    return area / (a0 * width)


# per seed the error of a column is the sampler's last stratum (~0.5 / spp); F12s cost
# ~0.1 s each here: 8 x 64 resolve 0.64 % on the edge columns (16 x 64: 0.35 %, 8 x 512:
# 0.09 %). The two channels compared are R and B (the controls call them by index: "R and G")
BORDER_SEEDS, BORDER_SPP = 8, 64
EDGE = 40 * (0.3 + 1.8) / 3.6   # raster x of the red/blue edge: x = 0.3 m of a 3.6 m view


def _edge_agrees(name, crops, x0):
    """The crops' pixels (one per seed) against the exact red fraction, in the columns where
    the filter blends red and blue: per seed the column means over the rows (the scene does not
    vary along y), one block per column (R and B), by lantern.metrics.assert_agreement with its
    1 % / 5 % negative controls. Seeds, not rows, are the replicates: within one render the
    sampler's sequence repeats its stratification in every pixel (the rows' counts of red
    samples came out equal), so only the seeds' spread measures the error. The columns no
    sample crosses into are exact (checked to 1e-5 by the caller)."""
    from lantern import metrics
    frac = _red_fraction(np.arange(crops[0].shape[1]) + x0, EDGE)
    edge = (frac > 0) & (frac < 1)
    cols = [c[..., [0, 2]].astype(np.float64).mean(axis=0, keepdims=True) for c in crops]
    exact = np.stack([frac, 1 - frac], axis=-1)[None]
    metrics.assert_agreement(name, cols, exact, block=1, mask=edge[None], bias_cap=1e-4)
    for c in crops:  # red + blue = 1 in every pixel (a sample sees exactly one emitter)
        np.testing.assert_allclose(c[..., 0] + c[..., 2], 1.0, rtol=1e-5)


def test_border_with_and_without_crop(empty, tmp_path, errors):
    _split_scene(empty)
    empty.render.resolution_x, empty.render.resolution_y = 40, 30
    empty.lantern.samples = 8
    full = render_passes(empty, tmp_path / "full.exr")[("ViewLayer", "Combined")]
    r = empty.render
    r.use_border = True
    r.border_min_x, r.border_max_x, r.border_min_y, r.border_max_y = 0.3, 0.8, 0.1, 0.6
    x0, x1, y0, y1 = 12, 32, 3, 18          # border * size, truncated (Blender's rule)
    rows = slice(30 - y1, 30 - y0)           # EXR rows are top first, the border's y from below
    ref = full[rows, x0:x1]
    # the same view of the same emitters: equal where no sample can cross the red/blue edge
    # (the filter reaches 1.5 px), and the columns it blends (with their own samples) at the
    # exact fraction within their noise
    frac = _red_fraction(np.arange(x0, x1), EDGE)
    away = np.where((frac == 0) | (frac == 1))[0]
    assert len(away) == (x1 - x0) - 3, frac
    empty.lantern.samples = BORDER_SPP
    r.use_crop_to_border = True
    empty.lantern.seed = 1
    crops = [render_passes(empty, tmp_path / "crop.exr")[("ViewLayer", "Combined")]]
    r.image_settings.media_type = "IMAGE"  # the other seeds: plain EXRs, read in-process
    for k in range(BORDER_SEEDS):
        empty.lantern.seed = 1 + k
        crop = crops[0] if k == 0 else render_exr(empty, tmp_path, f"crop{k}.exr")
        # (a plain EXR holds the same float pixels as the multilayer one's Combined)
        assert crop.shape[:2] == (y1 - y0, x1 - x0)
        np.testing.assert_allclose(crop[:, away], ref[:, away], rtol=1e-5, atol=1e-6)
        if k:
            crops.append(crop)
    _edge_agrees("border, cropped: edge columns", crops, x0)
    # without the crop, the border's pixels are the crop's, bit for bit (the same seed), and
    # Blender leaves the rest of the frame empty
    r.use_crop_to_border = False
    r.image_settings.media_type = "MULTI_LAYER_IMAGE"
    empty.lantern.seed = 1
    nocrop = render_passes(empty, tmp_path / "nocrop.exr")[("ViewLayer", "Combined")]
    assert nocrop.shape[:2] == (30, 40)
    np.testing.assert_array_equal(nocrop[rows, x0:x1], crops[0])
    outside = np.ones((30, 40), bool)
    outside[rows, x0:x1] = False
    assert not nocrop[outside].any()
    assert not [c for c in errors if c[0] == "ERROR"]


def test_resolution_percentage(empty, tmp_path):
    add_camera(empty, location=(0, 0, 5))
    add_plane(empty, size=100.0, material=emission_material(1.0))
    empty.render.resolution_x, empty.render.resolution_y = 64, 48
    empty.render.resolution_percentage = 25
    empty.lantern.samples = 1
    out = render_passes(empty, tmp_path / "pct.exr")
    assert out[("ViewLayer", "Combined")].shape == (12, 16, 4)


def test_data_passes_declared_and_filled_per_layer(empty, tmp_path, errors):
    add_camera(empty, location=(0, 0, 5))
    mat, _ = shader_material("Grey", "ShaderNodeBsdfDiffuse", Color=(0.5, 0.5, 0.5, 1))
    add_plane(empty, size=100.0, material=mat)
    sun = bpy.data.lights.new("Sun", "SUN")
    empty.collection.objects.link(bpy.data.objects.new("Sun", sun))
    first = empty.view_layers[0]
    first.use_pass_z = first.use_pass_normal = True
    first.use_pass_diffuse_color = first.use_pass_emit = True
    first.lantern.denoising_store_passes = True
    plain = empty.view_layers.new("Plain")
    # the compositor's Render Layers node shows what update_render_passes declares
    tree = bpy.data.node_groups.new("Comp", "CompositorNodeTree")
    empty.compositing_node_group = tree
    node = tree.nodes.new("CompositorNodeRLayers")
    node.scene, node.layer = empty, first.name
    sockets = {o.name for o in node.outputs if o.enabled}
    assert {"Depth", "Normal", "Diffuse Color", "Emission", "Denoising Albedo",
            "Denoising Normal", "Denoising Depth"} <= sockets
    node.layer = plain.name
    assert "Depth" not in {o.name for o in node.outputs if o.enabled}
    empty.lantern.samples = 4
    out = render_passes(empty, tmp_path / "passes.exr")
    shape = (24, 32)
    np.testing.assert_allclose(out[("ViewLayer", "Depth")][..., 0], np.full(shape, 5.0), rtol=1e-5)
    np.testing.assert_allclose(out[("ViewLayer", "Normal")],
                               np.broadcast_to([0, 0, 1], shape + (3,)), atol=1e-6)
    np.testing.assert_allclose(out[("ViewLayer", "Denoising Normal")],
                               np.broadcast_to([0, 0, -1], shape + (3,)), atol=1e-6)
    np.testing.assert_allclose(out[("ViewLayer", "Diffuse Color")], 0.5, rtol=1e-5)
    np.testing.assert_allclose(out[("ViewLayer", "Denoising Albedo")], 0.5, rtol=1e-5)
    assert not out[("ViewLayer", "Emission")].any()
    assert {p for (layer, p) in out if layer == "Plain"} == {"Combined"}
    assert not [c for c in errors if c[0] == "ERROR"]


def _spp_rendered(capfd):
    out = capfd.readouterr().out
    line = [ln for ln in out.splitlines() if ln.startswith("Lantern: ") and " spp in " in ln][-1]
    return int(line.split()[1]), "noise threshold reached" in line


def test_noise_threshold_stops_a_converged_frame(empty, tmp_path, capfd):
    """An emitter filling the view has no noise: the render stops at the first check."""
    add_camera(empty, location=(0, 0, 5))
    add_plane(empty, size=100.0, material=emission_material(1.0))
    s = empty.lantern
    s.samples, s.use_adaptive_sampling, s.adaptive_threshold, s.adaptive_min_samples = \
        512, True, 0.01, 8
    assert bpy.ops.render.render() == {"FINISHED"}
    assert _spp_rendered(capfd) == (8, True)


def test_noise_threshold_keeps_a_noisy_frame_going(empty, tmp_path, capfd):
    add_camera(empty, location=(0, 0, 5))
    mat, _ = shader_material("Grey", "ShaderNodeBsdfDiffuse", Color=(0.5, 0.5, 0.5, 1))
    add_plane(empty, size=100.0, material=mat)
    lamp = bpy.data.lights.new("Lamp", "POINT")
    lamp.energy = 100.0
    obj = bpy.data.objects.new("Lamp", lamp)
    obj.location = (0.5, 0.3, 1.0)
    empty.collection.objects.link(obj)
    s = empty.lantern
    s.samples, s.use_adaptive_sampling, s.adaptive_threshold, s.adaptive_min_samples = \
        24, True, 0.0001, 4
    assert bpy.ops.render.render() == {"FINISHED"}
    assert _spp_rendered(capfd) == (24, False)


def _half_emitter(empty):
    """Half the view an emitter (no noise), half a diffuse plane lit by an area light."""
    add_camera(empty, location=(0, 0, 5))
    mat, _ = shader_material("Grey", "ShaderNodeBsdfDiffuse", Color=(0.5, 0.5, 0.5, 1))
    add_plane(empty, size=100.0, material=mat)
    add_plane(empty, size=50.0, material=emission_material(1.0), location=(-25.0, 0.0, 0.1),
              name="Glow")
    lamp = bpy.data.lights.new("Lamp", "AREA")
    lamp.energy, lamp.size = 100.0, 2.0
    obj = bpy.data.objects.new("Lamp", lamp)
    obj.location = (2.0, 0.3, 1.0)
    empty.collection.objects.link(obj)
    s = empty.lantern
    s.samples, s.use_adaptive_sampling, s.adaptive_threshold, s.adaptive_min_samples = \
        32, True, 0.001, 4


def test_noise_threshold_stops_each_pixel(empty, capfd):
    """The emitter's pixels stop at min samples, the plane's go on, so a pixel's mean samples
    lie between."""
    _half_emitter(empty)
    assert bpy.ops.render.render() == {"FINISHED"}
    out = capfd.readouterr().out
    line = [ln for ln in out.splitlines() if ln.startswith("Lantern: ") and " spp in " in ln][-1]
    assert int(line.split()[1]) == 32
    mean = float(line.split("(adaptive: ")[1].split()[0])
    assert 4 < mean < 32, line


@pytest.mark.parametrize("switch", ["lantern", "cycles"])
def test_sample_count_pass(empty, tmp_path, switch):
    """Debug Sample Count (Cycles' name and switch, or Lantern's): each pixel's samples."""
    _half_emitter(empty)
    vl = empty.view_layers[0]
    if switch == "lantern":
        vl.lantern.pass_sample_count = True
    else:
        vl.cycles.pass_debug_sample_count = True
    out = render_passes(empty, tmp_path / "count.exr")
    n = out[("ViewLayer", "Debug Sample Count")]
    n = n[..., 0] if n.ndim == 3 else n
    w = n.shape[1]
    assert (n[:, : w // 2 - 2] == 4).all(), n  # the emitter (x < 0): min samples
    assert (n[:, w // 2 + 2:] == 32).mean() > 0.9, n  # the lit plane: every sample


def test_failing_data_passes_leave_the_render_going(empty, tmp_path, errors, monkeypatch):
    import lantern.aov

    def broken(*args, **kwargs):
        raise RuntimeError("no data passes today")
    monkeypatch.setattr(lantern.aov, "render_aovs", broken)
    add_camera(empty, location=(0, 0, 5))
    add_plane(empty, size=100.0, material=emission_material(1.5))
    empty.view_layers[0].use_pass_z = True
    empty.lantern.samples = 2
    out = render_passes(empty, tmp_path / "broken.exr")
    np.testing.assert_allclose(out[("ViewLayer", "Combined")][..., :3], 1.5, rtol=1e-5)
    depth = out[("ViewLayer", "Depth")]
    assert (depth == depth.flat[0]).all() and depth.flat[0] != 5.0  # Blender's untouched default
    assert [m for kind, m in errors if kind == "WARNING" and "no data passes today" in m]
    assert not [c for c in errors if c[0] == "ERROR"]


def test_view_layer_samples_override(empty, capfd):
    add_camera(empty, location=(0, 0, 5))
    add_plane(empty, size=100.0, material=emission_material(1.0))
    empty.lantern.samples = 50
    empty.view_layers[0].samples = 3
    assert bpy.ops.render.render() == {"FINISHED"}
    assert _spp_rendered(capfd) == (3, False)
