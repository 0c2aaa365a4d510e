"""Helpers for scripts that drive Blender (bpy) with the Lantern add-on.

The add-on in addon/ is loaded as the package `lantern_blender`, as tests/blender does, and
registered once. Images are read back through bpy (never OpenImageIO in a bpy process)."""

import importlib.util
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ADDON_DIR = os.path.join(ROOT, "addon")
_registered = False


def load_addon():
    """Import addon/ as `lantern_blender` and register it (idempotent). Returns the module."""
    global _registered
    mod = sys.modules.get("lantern_blender")
    if mod is None:
        spec = importlib.util.spec_from_file_location(
            "lantern_blender", os.path.join(ADDON_DIR, "__init__.py"),
            submodule_search_locations=[ADDON_DIR])
        mod = importlib.util.module_from_spec(spec)
        sys.modules["lantern_blender"] = mod
        spec.loader.exec_module(mod)
    import bpy
    # tests/blender's session fixture may already have registered the same module
    if not _registered and not hasattr(bpy.types.Scene, "lantern"):
        mod.register()
        _registered = True
    return mod


def read_image_bpy(path):
    """Float RGB (H, W, 3) of an image file, top row first, read through bpy."""
    import bpy
    img = bpy.data.images.load(path, check_existing=False)
    try:
        w, h = img.size
        c = img.channels
        px = np.empty(w * h * c, dtype=np.float32)
        img.pixels.foreach_get(px)
    finally:
        bpy.data.images.remove(img)
    return px.reshape(h, w, c)[::-1, :, :3].copy()
