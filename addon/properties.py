"""Render settings stored in the .blend as `scene.lantern`."""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty


class LanternSceneSettings(bpy.types.PropertyGroup):
    samples: IntProperty(name="Samples", description="Samples per pixel for final renders",
                         default=64, min=1, soft_max=4096, max=1 << 20)
    preview_samples: IntProperty(name="Viewport Samples",
                                 description="Samples per pixel in the viewport (0: unlimited)",
                                 default=1024, min=0, max=1 << 20)
    time_limit: FloatProperty(name="Time Limit", description="Stop a final render after this "
                              "many seconds (0: no limit); the first sample always completes", default=0.0, min=0.0, unit="TIME_ABSOLUTE")
    max_depth: IntProperty(name="Max Depth", description="Longest path, in segments: 1 shows "
                           "emitters only, 2 direct light, 3 one indirect bounce", default=12,
                           min=1, max=1024)
    integrator: EnumProperty(
        name="Integrator",
        items=[("auto", "Automatic", "Path tracing or CIS-LBDPT, chosen per render from "
                "the render's own measurements of each one's noise and cost (the status bar "
                "says which)"),
               ("pt", "Path Tracing", "Unidirectional path tracing with light sampling"),
               ("bdpt", "BDPT", "Bidirectional path tracing: each camera path connects to "
                "every vertex of its own light path (a reference)"),
               ("lvc", "LVC-BDPT", "Light-vertex-cache BDPT: each camera vertex connects to N "
                "light vertices picked uniformly"),
               ("cis", "CIS-LBDPT", "Light-vertex-cache BDPT with sorting and resampled "
                "connections: the best of M candidates, N kept (lights in fixtures, glass)")],
        default="auto")
    backend: EnumProperty(
        name="Device",
        description="Where to render; a GPU that is missing or out of memory falls back to "
                    "the CPU with a warning",
        items=[("auto", "Auto", "The GPU when one is usable, else the CPU"),
               ("cuda", "GPU (CUDA)", "Render on an NVIDIA GPU (CUDA)"),
               ("cpu", "CPU", "Render on the CPU (Embree, or Lantern's own BVH without it)")],
        default="auto")
    connections: IntProperty(name="Connections (N)", description="Light vertices each camera "
                             "vertex connects to", default=5, min=1, max=64)
    candidates: IntProperty(name="Candidates (M)", description="Light vertices considered "
                            "before resampling N of them (CIS-LBDPT)", default=10, min=1, max=64)
    sort: EnumProperty(
        name="Sort by Material",
        description="Sort each bounce's shading work by material type for coherence",
        items=[("auto", "Automatic", "On for CIS-LBDPT, off for the others"),
               ("on", "On", "Always sort"),
               ("off", "Off", "Never sort")],
        default="auto")
    seed: IntProperty(name="Seed", default=0, min=0)
    spp_per_iteration: IntProperty(name="Samples per Iteration", default=1, min=1, max=4096)
    threads: IntProperty(name="Threads", description="CPU threads (0: all cores)", default=0,
                         min=0, max=1024)
    use_adaptive_sampling: BoolProperty(
        name="Noise Threshold", description="Stop sampling each pixel of a final render once "
        "its noise is below the threshold (Cycles' meaning: the relative error of each pixel's "
        "value); the render ends when every pixel has",
        default=False)
    adaptive_threshold: FloatProperty(
        name="Noise Threshold", description="Relative standard error, per pixel, below which "
        "a pixel stops sampling (0.01 as Cycles' default); checked on the pixels' own sample "
        "variance, estimated from two halves of the samples", default=0.01, min=0.0001,
        max=1.0, precision=4, step=0.1)
    adaptive_min_samples: IntProperty(
        name="Min Samples", description="Samples before the noise is first checked (0: "
        "automatic, as Cycles: enough for a stable estimate)", default=0, min=0, max=4096)

    def session_settings(self, preview=False):
        """Keyword arguments for lantern.Session."""
        return {"integrator": self.integrator, "backend": self.backend,
                "max_depth": self.max_depth, "seed": self.seed,
                "spp_per_iteration": self.spp_per_iteration, "threads": self.threads,
                "connections": self.connections, "candidates": self.candidates,
                "sort": {"auto": None, "on": True, "off": False}[self.sort]}


class LanternViewLayerSettings(bpy.types.PropertyGroup):
    denoising_store_passes: BoolProperty(
        name="Denoising Data", description="Write Denoising Albedo, Denoising Normal and "
        "Denoising Depth (Cycles' names), for the compositor's Denoise node. Cycles' own "
        "Denoising Data setting of the view layer turns them on too", default=False)
    pass_sample_count: BoolProperty(
        name="Sample Count", description="Debug Sample Count (Cycles' name): each pixel's own "
        "samples, fewer where adaptive sampling stopped it. Cycles' own switch of the view "
        "layer turns it on too", default=False)


def denoising_passes_enabled(view_layer):
    """Lantern's Denoising Data switch of the view layer, or Cycles' (an artist's existing
    compositor set-up keeps its inputs when the engine changes)."""
    own = getattr(getattr(view_layer, "lantern", None), "denoising_store_passes", False)
    cycles = getattr(getattr(view_layer, "cycles", None), "denoising_store_passes", False)
    return bool(own or cycles)


def register():
    bpy.utils.register_class(LanternSceneSettings)
    bpy.utils.register_class(LanternViewLayerSettings)
    bpy.types.Scene.lantern = PointerProperty(type=LanternSceneSettings)
    bpy.types.ViewLayer.lantern = PointerProperty(type=LanternViewLayerSettings)


def unregister():
    del bpy.types.ViewLayer.lantern
    del bpy.types.Scene.lantern
    bpy.utils.unregister_class(LanternViewLayerSettings)
    bpy.utils.unregister_class(LanternSceneSettings)
