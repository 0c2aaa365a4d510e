"""Transparent film (Blender's Film > Transparent): alpha is the coverage of each pixel by
camera paths that end on geometry rather than the world; the world is not drawn (the core
hides it from camera rays when `film["transparent"]`) but still lights the scene.

The coverage is rendered by its own cheap pass over the same scene, camera and pixel filter:
every surface a black emitter of red 1 (its alpha and alpha texture kept, so that a surface of
alpha a covers a), no lights, a black world, camera rays only. Its pixel means are the alpha
Cycles writes, with the same filter. Lights seen by the camera do not count as coverage.
Holdouts (material "holdout": True, addon/export/holdout.py) are opaque black: they cover
nothing and hide what is behind them.

Shadow catchers (mesh "shadow_catcher": True, pt only), with the meaning of Cycles' Combined
pass when its Shadow Catcher pass is off: the beauty render treats a catcher seen by the camera
as a holdout (no colour; what other surfaces receive from it stays: integrator/pt.h
pt_catcher_skips), and the film's alpha becomes a + c s: a the coverage above, c the share of
the pixel where the camera sees a catcher (green in the coverage render, where catchers cover
nothing), s the shadow the catcher receives: 1 minus the per-pixel ratio of the catcher's
radiance in the scene (film "catcher_mode" 1) to its radiance when it is alone with the lights
and the world (mode 2: later rays pass through every other surface, which casts no shadow),
averaged over RGB, clamped to [0, 1]. The two catcher renders share the seed, so their noise
largely cancels in the ratio. (Measured against Cycles, tests/render/test_world_film.py: a
pixel half holdout, half shadowed catcher keeps the holdout's half transparent, so the shadow
is weighted by c, not by 1 - a.)"""

import copy

import numpy as np

COVERAGE_KEEP = ("name", "alpha", "alpha_texture")


def has_shadow_catcher(scene):
    return any(m.get("shadow_catcher") for m in scene.meshes)


def coverage_scene(scene):
    """A copy of `scene` whose render is the film's alpha (see the module's docstring): red the
    coverage, green the share of the pixel where the camera sees a shadow catcher."""
    from .scene import Scene
    out = Scene()
    out.film = dict(scene.film)
    out.camera = copy.deepcopy(scene.camera)
    out.world = {"color": [0.0, 0.0, 0.0]}
    out.textures = scene.textures
    out.lights = []
    out.materials = []
    for m in scene.materials:
        leaf = {k: m[k] for k in COVERAGE_KEEP if k in m}
        # a holdout covers nothing, yet hides what is behind it: a black, opaque surface
        cover = 0.0 if m.get("holdout") else 1.0
        leaf.update(type="diffuse", base_color=[0.0, 0.0, 0.0], emission=[cover, 0.0, 0.0])
        if m.get("type") == "mix":  # a mix's coverage: its leaves' alpha is not kept
            leaf.pop("alpha_texture", None)
        out.materials.append(leaf)
    out.meshes = scene.meshes
    if has_shadow_catcher(scene):  # catchers cover nothing: their own copies, green
        n = len(out.materials)
        out.materials += [dict(leaf, emission=[0.0, 1.0, 0.0]) for leaf in out.materials]
        out.meshes = [dict(m, shadow_catcher=False,
                           material_ids=np.asarray(m["material_ids"], np.uint32) + np.uint32(n))
                      if m.get("shadow_catcher") else m for m in scene.meshes]
    return out


def catcher_scene(scene, mode):
    """`scene` rendered in film catcher_mode `mode` (1: the catchers in the scene, 2: alone)."""
    out = copy.copy(scene)
    out.film = dict(scene.film, catcher_mode=int(mode))
    if mode == 2:
        out.meshes = [m if m.get("shadow_catcher") else dict(m, cast_shadow=False)
                      for m in scene.meshes]
    return out


def catcher_shadow(scene, spp, seed=0, **settings):
    """The shadow r (H, W) float32 in [0, 1] that the catchers receive (see the module's
    docstring; 0 where no camera ray reaches one) from `spp` samples per pixel of pt."""
    from .session import Session
    images = []
    for mode in (1, 2):
        s = Session(catcher_scene(scene, mode), integrator="pt", seed=seed + 0x5c,
                    spp_per_iteration=max(1, int(spp)), **settings)
        s.step()
        images.append(np.asarray(s.image(), np.float64)[..., :3])
    with_others, alone = images
    ratio = np.where(alone > 0.0, with_others / np.where(alone > 0.0, alone, 1.0), 1.0)
    return np.clip(1.0 - ratio.mean(axis=2), 0.0, 1.0).astype(np.float32)


def render_alpha(scene, spp, seed=0, **settings):
    """The film's alpha (H, W) float32, top row first, from `spp` coverage samples per pixel;
    all ones when the film is not transparent."""
    from .session import Session
    h, w = scene.film["height"], scene.film["width"]
    if not scene.film.get("transparent"):
        return np.ones((h, w), np.float32)
    depth = settings.get("max_depth")
    settings = {k: v for k, v in settings.items() if k in ("backend", "threads")}
    s = Session(coverage_scene(scene), integrator="pt", max_depth=1, seed=seed + 0x41,
                spp_per_iteration=max(1, int(spp)), **settings)
    s.step()
    cover = np.clip(np.asarray(s.image(), np.float32), 0.0, 1.0)
    alpha = cover[..., 0]
    if has_shadow_catcher(scene):
        if depth is not None:
            settings["max_depth"] = depth
        alpha = np.clip(alpha + cover[..., 1] * catcher_shadow(scene, spp, seed, **settings),
                        0.0, 1.0)
    return alpha


__all__ = ["catcher_scene", "catcher_shadow", "coverage_scene", "has_shadow_catcher",
           "render_alpha"]
