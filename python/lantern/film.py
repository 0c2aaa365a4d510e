"""Transparent film (Blender's Film > Transparent): alpha is the coverage of each pixel by
camera paths that end on geometry rather than the world; the world is not drawn (the core
hides it from camera rays when `film["transparent"]`) but still lights the scene.

The coverage is rendered by its own cheap pass over the same scene, camera and pixel filter:
every surface a black emitter of 1 (its alpha and alpha texture kept, so that a surface of
alpha a covers a), no lights, a black world, camera rays only. Its pixel means are the alpha
Cycles writes, with the same filter. Lights seen by the camera do not count as coverage.
Holdouts (material "holdout": True, addon/export/holdout.py) are opaque black: they cover
nothing and hide what is behind them."""

import copy

import numpy as np

COVERAGE_KEEP = ("name", "alpha", "alpha_texture")


def coverage_scene(scene):
    """A copy of `scene` whose render is the film's alpha (see the module's docstring)."""
    from .scene import Scene
    out = Scene()
    out.film = dict(scene.film)
    out.camera = copy.deepcopy(scene.camera)
    out.world = {"color": [0.0, 0.0, 0.0]}
    out.textures = scene.textures
    out.meshes = scene.meshes
    out.lights = []
    out.materials = []
    for m in scene.materials:
        leaf = {k: m[k] for k in COVERAGE_KEEP if k in m}
        # a holdout covers nothing, yet hides what is behind it: a black, opaque surface
        cover = 0.0 if m.get("holdout") else 1.0
        leaf.update(type="diffuse", base_color=[0.0, 0.0, 0.0], emission=[cover] * 3)
        if m.get("type") == "mix":  # a mix's coverage: its leaves' alpha is not kept
            leaf.pop("alpha_texture", None)
        out.materials.append(leaf)
    return out


def render_alpha(scene, spp, seed=0, **settings):
    """The film's alpha (H, W) float32, top row first, from `spp` coverage samples per pixel;
    all ones when the film is not transparent."""
    from .session import Session
    h, w = scene.film["height"], scene.film["width"]
    if not scene.film.get("transparent"):
        return np.ones((h, w), np.float32)
    settings = {k: v for k, v in settings.items() if k in ("backend", "threads")}
    s = Session(coverage_scene(scene), integrator="pt", max_depth=1, seed=seed + 0x41,
                spp_per_iteration=max(1, int(spp)), **settings)
    s.step()
    return np.clip(np.asarray(s.image(), np.float32).mean(axis=2), 0.0, 1.0)


__all__ = ["coverage_scene", "render_alpha"]
