"""Import a Mitsuba 3 XML scene into a `lantern.Scene` (the subset used in /work/shared/scenes).

    scene = load_mitsuba("scene.xml", width=128, height=128)
    scene.metadata["max_depth"]   # the integrator's max_depth (Mitsuba counts like Lantern)

Supported: `<default>` parameters (`$name`), `<ref>`, shapes obj / ply / rectangle / cube /
sphere / disk with `to_world` (matrix, translate, rotate, scale, lookat), BSDFs diffuse,
(rough)conductor (complex Fresnel, named presets), (rough)dielectric (named IORs) and twosided
(plastics and principled fall back to a diffuse with a warning; Beckmann is read as GGX), area
emitters (-> material emission), constant emitters (-> world colour), point emitters, the
perspective sensor (fov, fov_axis, focal_length, clip planes), hdrfilm size and rfilter, and
the integrator's max_depth. Everything else is skipped with a warning in
`scene.metadata["warnings"]` (also sent to the `lantern.mitsuba` logger).

Conventions (docs/mitsuba_import.md): Mitsuba is +Y up and its camera looks down local +Z with
local +X pointing to the image's *left*; Lantern is +Z up (Blender) and its camera looks down
local -Z with +X to the right. World points map (x, y, z) -> (x, -z, y) (a rotation, so nothing
is mirrored); the camera's Lantern axes are (-X, +Y, -Z) of Mitsuba's camera frame.
"""

from .common import Y_UP_TO_Z_UP, MitsubaError
from .geometry import camera_to_lantern, fov_tangents, parse_transform, read_obj, read_ply
from .loader import load_mitsuba

__all__ = ["load_mitsuba", "MitsubaError", "parse_transform", "read_obj", "read_ply",
           "fov_tangents", "camera_to_lantern", "Y_UP_TO_Z_UP"]
