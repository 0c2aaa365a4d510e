"""Render passes with Cycles' names (as bpy 5.0.1's Cycles writes them), per view layer: which
ones a layer asks for, their declaration for the Render Layers node (update_render_passes), and
writing Lantern's data passes (lantern.aov) into a render result."""

import numpy as np

from .properties import denoising_passes_enabled

# (name, channels, channel ids, type, the view layer's switch or None for Denoising Data)
DATA_PASSES = (
    ("Depth", 1, "Z", "VALUE", "use_pass_z"),
    ("Normal", 3, "XYZ", "VECTOR", "use_pass_normal"),
    ("Diffuse Color", 3, "RGB", "COLOR", "use_pass_diffuse_color"),
    ("Emission", 3, "RGB", "COLOR", "use_pass_emit"),
    ("Denoising Normal", 3, "XYZ", "VECTOR", None),
    ("Denoising Albedo", 3, "RGB", "COLOR", None),
    ("Denoising Depth", 1, "Z", "VALUE", None),
)

# view-layer pass switches Lantern does not fill, in the words of the warning
UNSUPPORTED_PASSES = (
    ("use_pass_mist", "Mist"), ("use_pass_position", "Position"), ("use_pass_vector", "Vector"),
    ("use_pass_uv", "UV"), ("use_pass_object_index", "Object Index"),
    ("use_pass_material_index", "Material Index"),
    ("use_pass_ambient_occlusion", "Ambient Occlusion"), ("use_pass_shadow", "Shadow"),
    ("use_pass_environment", "Environment"),
    ("use_pass_diffuse_direct", "Diffuse Direct"),
    ("use_pass_diffuse_indirect", "Diffuse Indirect"),
    ("use_pass_glossy_direct", "Glossy Direct"), ("use_pass_glossy_indirect", "Glossy Indirect"),
    ("use_pass_glossy_color", "Glossy Color"),
    ("use_pass_transmission_direct", "Transmission Direct"),
    ("use_pass_transmission_indirect", "Transmission Indirect"),
    ("use_pass_transmission_color", "Transmission Color"),
    ("use_pass_subsurface_direct", "Subsurface Direct"),
    ("use_pass_subsurface_indirect", "Subsurface Indirect"),
    ("use_pass_subsurface_color", "Subsurface Color"),
    ("use_pass_cryptomatte_object", "Cryptomatte Object"),
    ("use_pass_cryptomatte_material", "Cryptomatte Material"),
    ("use_pass_cryptomatte_asset", "Cryptomatte Asset"),
)


def enabled_passes(view_layer):
    """The data passes this view layer asks for: [(name, channels, chan_id, type)]."""
    denoise = denoising_passes_enabled(view_layer)
    out = []
    for name, channels, chan_id, kind, switch in DATA_PASSES:
        on = denoise if switch is None else bool(getattr(view_layer, switch, False))
        if on:
            out.append((name, channels, chan_id, kind))
    return out


SAMPLE_COUNT = "Debug Sample Count"


def sample_count_enabled(view_layer):
    """Lantern's Sample Count switch of the view layer, or Cycles' Debug Sample Count."""
    own = getattr(getattr(view_layer, "lantern", None), "pass_sample_count", False)
    cycles = getattr(getattr(view_layer, "cycles", None), "pass_debug_sample_count", False)
    return bool(own or cycles)


def register_passes(engine, scene, view_layer):
    """update_render_passes: Combined and every enabled data pass, so that the compositor's
    Render Layers node shows their sockets."""
    engine.register_pass(scene, view_layer, "Combined", 4, "RGBA", "COLOR")
    for name, channels, chan_id, kind in enabled_passes(view_layer):
        engine.register_pass(scene, view_layer, name, channels, chan_id, kind)
    if sample_count_enabled(view_layer):
        engine.register_pass(scene, view_layer, SAMPLE_COUNT, 1, "X", "VALUE")


def write_sample_count(layer, counts):
    """Each pixel's samples, (H, W) top row first, into the layer's Debug Sample Count pass
    (Cycles writes the count itself there too)."""
    for render_pass in layer.passes:
        if render_pass.name == SAMPLE_COUNT:
            _set_rect(render_pass, np.asarray(counts, np.float32)[..., None])


def unsupported_pass_warnings(view_layer):
    """One message per enabled pass Lantern leaves empty."""
    names = [label for attr, label in UNSUPPORTED_PASSES if getattr(view_layer, attr, False)]
    if getattr(view_layer, "aovs", None) and len(view_layer.aovs):
        names.append("shader AOVs")
    if getattr(view_layer, "lightgroups", None) and len(view_layer.lightgroups):
        names.append("light groups")
    return [f"View layer '{view_layer.name}': the {n} pass is not rendered by Lantern (left "
            "empty)" for n in names]


def _set_rect(render_pass, rows_top_first):
    """Writes (H, W[, C]) float32, top row first, into a render pass (bottom row first)."""
    a = np.ascontiguousarray(rows_top_first[::-1], dtype=np.float32)
    flat = a.reshape(-1)
    rect = render_pass.rect
    if hasattr(rect, "foreach_set"):
        rect.foreach_set(flat)
    else:
        render_pass.rect = flat.reshape(a.shape[0] * a.shape[1], -1)


def write_data_passes(layer, aovs):
    """Fills the result layer's data passes from lantern.aov.render_aovs output."""
    for render_pass in layer.passes:
        data = aovs.get(render_pass.name)
        if data is None or render_pass.name == "Combined":
            continue
        want = render_pass.channels
        data = data if data.ndim == 3 else data[..., None]
        if data.shape[2] != want:
            raise ValueError(f"pass {render_pass.name}: {data.shape[2]} channels, the result "
                             f"has {want}")
        _set_rect(render_pass, data)

