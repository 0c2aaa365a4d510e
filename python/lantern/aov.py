"""First-hit data passes for compositing, with Cycles' names and meanings (native/src/integrator/
aov.h): Depth, Normal (world space), Diffuse Color, Emission, and the denoiser's features
Denoising Albedo, Denoising Normal (camera space) and Denoising Depth. One camera ray per sample
on the CPU, apart from the render: `render_aovs(scene, spp=16)` -> {name: (H, W[, 3]) float32},
top row first, plus "warnings"."""

from .session import require_core

PASSES = ("Depth", "Normal", "Diffuse Color", "Emission", "Denoising Albedo", "Denoising Normal",
          "Denoising Depth")


def render_aovs(scene, spp=16, seed=0, threads=0):
    """The data passes of a lantern.Scene at `spp` camera samples per pixel."""
    if not hasattr(scene, "to_native"):
        raise TypeError("render_aovs needs a lantern.Scene")
    native_scene = scene.to_native()
    core = require_core()
    return core.render_aovs(native_scene, {"spp": int(spp), "seed": int(seed),
                                           "threads": int(threads)})
