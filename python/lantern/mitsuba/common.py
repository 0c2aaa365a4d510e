"""Shared pieces of the Mitsuba importer: axis conversion, BSDF lists, the error type."""

import logging

import numpy as np


log = logging.getLogger("lantern.mitsuba")

# Mitsuba world (Y up) -> Lantern / Blender world (Z up): (x, y, z) -> (x, -z, y).
Y_UP_TO_Z_UP = np.array([[1.0, 0.0, 0.0, 0.0],
                         [0.0, 0.0, -1.0, 0.0],
                         [0.0, 1.0, 0.0, 0.0],
                         [0.0, 0.0, 0.0, 1.0]])

# BSDFs imported as a diffuse (one warning lists them); conductors and dielectrics are mapped
FALLBACK_BSDFS = ("thindielectric", "plastic", "roughplastic", "principled", "principledthin",
                  "hair", "pplastic", "measured", "blendbsdf")
WRAPPER_BSDFS = ("twosided", "mask", "bumpmap", "normalmap")

# Standard deviation (pixels) of one axis of Blackman-Harris over [-w, w], per unit w.
_BH_STD_PER_WIDTH = 2.0 * 0.13850731377878253


class MitsubaError(ValueError):
    """A Mitsuba file this importer cannot read."""
