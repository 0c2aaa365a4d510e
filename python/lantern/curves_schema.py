"""Strands and hair materials in a scene (docs/scene_format.md "curves", docs/curves.md): the
checks of one strand set (points, a radius per point, strand offsets, a material per strand)
and of a Principled Hair material's fields, and their members in a .lantern file. Each check
raises ValueError naming the element."""

import numpy as np

from .scene_fields import RAY_VISIBILITY, _bool, _finite_float, _int, _rgb, motion_steps

CURVE_ARRAYS = ("points", "radius", "offsets", "material_ids")
# motion blur (docs/motion_blur.md "Strands"): optional, at the shutter's steps
CURVE_MOTION_ARRAYS = ("deform", "deform_radius")
# field -> (numpy dtype kinds, dimensions, allowed last dimension) of its .npy member
CURVE_ARRAY_SPECS = {"points": ("f", 2, (3,)), "radius": ("f", 1, None),
                     "offsets": ("iu", 1, None), "material_ids": ("iu", 1, None),
                     "deform": ("f", 3, (3,)), "deform_radius": ("f", 2, None)}
HAIR_PARAMETRIZATIONS = ("melanin", "color", "absorption")
# Principled Hair (Chiang) fields with the node's defaults (bpy 5.0.1) and ranges
HAIR_FLOATS = (("melanin", 0.8, 0.0, 1.0), ("melanin_redness", 1.0, 0.0, 1.0),
               ("radial_roughness", 0.3, 0.0, 1.0), ("hair_coat", 0.0, 0.0, 1.0),
               ("hair_offset", 0.034906585, -1.5707963, 1.5707963))
HAIR_KEYS = {"parametrization": "hair_parametrization", "melanin": "melanin",
             "melanin_redness": "melanin_redness", "tint": "hair_tint",
             "absorption": "absorption", "radial_roughness": "radial_roughness",
             "coat": "hair_coat", "offset": "hair_offset"}


def validate_hair(material, out, what):
    """The hair fields of a material of type "hair" into out (normalised)."""
    p = material.get("hair_parametrization", "color")
    if p not in HAIR_PARAMETRIZATIONS:
        raise ValueError(f"{what} hair_parametrization: one of {HAIR_PARAMETRIZATIONS}, "
                         f"got {p!r}")
    out["hair_parametrization"] = p
    for key, default, lo, hi in HAIR_FLOATS:
        v = _finite_float(material.get(key, default), f"{what} {key}")
        if not lo <= v <= hi:
            raise ValueError(f"{what} {key}: must be in [{lo}, {hi}], got {v}")
        out[key] = v
    out["hair_tint"] = _rgb(material.get("hair_tint", [1.0, 1.0, 1.0]), f"{what} hair_tint")
    out["absorption"] = _rgb(material.get("absorption", [0.245531, 0.52, 1.365]),
                             f"{what} absorption")


def validate_curves(curves, index, num_materials=None):
    """One strand set: points (P, 3) float32, radius (P,) float32 (NaN, negative or infinite
    radii are the core's to drop, with a message), offsets (S + 1,) from 0 to P, increasing,
    material_ids (S,). Normalises in place and returns it."""
    if not isinstance(curves, dict):
        raise ValueError(f"curves {index}: expected a dict")
    name = str(curves.get("name", f"curves_{index}"))
    what = f"curves {index} ({name!r})"
    curves["name"] = name
    pts = np.asarray(curves.get("points"))
    if pts.dtype.kind not in "fiu" or pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"{what} points: expected a numeric (P, 3) array, got "
                         f"{getattr(pts, 'shape', None)}")
    curves["points"] = np.ascontiguousarray(pts, dtype=np.float32)
    rad = np.asarray(curves.get("radius"))
    if rad.dtype.kind not in "fiu" or rad.ndim != 1 or len(rad) != len(pts):
        raise ValueError(f"{what} radius: expected one number per point ({len(pts)})")
    curves["radius"] = np.ascontiguousarray(rad, dtype=np.float32)
    off = np.asarray(curves.get("offsets"))
    if off.dtype.kind not in "iu" or off.ndim != 1 or len(off) < 1:
        raise ValueError(f"{what} offsets: expected an integer array of strands + 1 entries")
    if off[0] != 0 or off[-1] != len(pts) or (np.diff(off.astype(np.int64)) < 0).any():
        raise ValueError(f"{what} offsets: must run from 0 to the number of points "
                         f"({len(pts)}) without decreasing")
    if len(pts) >= 2**31:
        raise ValueError(f"{what}: more than 2^31 points")
    curves["offsets"] = np.ascontiguousarray(off, dtype=np.uint32)
    ns = len(off) - 1
    mats = curves.get("material_ids")
    mats = np.zeros(ns, np.uint32) if mats is None else np.asarray(mats)
    if mats.dtype.kind not in "iu" or mats.shape != (ns,) or (mats.size and mats.min() < 0):
        raise ValueError(f"{what} material_ids: expected {ns} non-negative integers")
    if num_materials is not None and mats.size and int(mats.max()) >= max(num_materials, 1):
        raise ValueError(f"{what} material_ids: material id {int(mats.max())} does not exist "
                         f"({num_materials} materials)")
    curves["material_ids"] = np.ascontiguousarray(mats, dtype=np.uint32)
    for key in ("visible_camera", "cast_shadow"):
        curves[key] = _bool(curves.get(key, True), f"{what} {key}")
    for key in RAY_VISIBILITY:  # its object's ray visibility by kind (as a mesh's); absent: seen
        if key in curves:
            curves[key] = _bool(curves[key], f"{what} {key}")
    for key in ("light_set", "shadow_set"):  # light / shadow linking: its object's sets
        if key in curves:
            curves[key] = _int(curves[key], f"{what} {key}", minimum=0)
            if curves[key] > 63:
                raise ValueError(f"{what} {key}: must be in [0, 63], got {curves[key]}")
    # motion blur: points (S, P, 3) and radii (S, P) at S >= 2 steps over the shutter; values
    # are the core's to judge (a non-finite step: a message, the strands still)
    for key, tail in (("deform", (len(pts), 3)), ("deform_radius", (len(pts),))):
        if curves.get(key) is None:
            curves.pop(key, None)
            continue
        a = np.asarray(curves[key])
        if a.dtype.kind not in "fiu" or a.ndim != 1 + len(tail) or a.shape[0] < 2 or \
                a.shape[1:] != tail:
            raise ValueError(f"{what} {key}: expected shape (S >= 2, {', '.join(map(str, tail))})"
                             f" (the {'points' if key == 'deform' else 'radii'} at each motion "
                             f"step), got {getattr(a, 'shape', None)}")
        curves[key] = np.ascontiguousarray(a, dtype=np.float32)
    if "deform_radius" in curves and "deform" not in curves:
        raise ValueError(f"{what} deform_radius: needs deform (the points at the same steps)")
    if "deform" in curves and "deform_radius" in curves and \
            curves["deform"].shape[0] != curves["deform_radius"].shape[0]:
        raise ValueError(f"{what} deform_radius: {curves['deform_radius'].shape[0]} steps, "
                         f"deform has {curves['deform'].shape[0]}")
    # its object's motion (docs/motion_blur.md "Strands of a turning object"): as a mesh's,
    # object-to-world at the steps and the matrix the points (and deform) were exported with
    if curves.get("motion") is not None:
        curves["motion"] = motion_steps(curves["motion"], f"{what} motion")
        base = curves.get("motion_base")
        curves["motion_base"] = motion_steps([base if base is not None else np.eye(4)] * 2,
                                             f"{what} motion_base")[0]
    else:
        curves.pop("motion", None)
        curves.pop("motion_base", None)
    return curves


def save_curves(curves_list, arrays):
    """scene.json entries for the strand sets, their arrays added to `arrays` (member: array)."""
    out = []
    for i, c in enumerate(curves_list):
        entry = {}
        for key, value in c.items():
            if key in CURVE_ARRAYS + CURVE_MOTION_ARRAYS:
                member = f"curves/{i}/{key}.npy"
                arrays[member] = value
                entry[key] = member
            else:
                entry[key] = value
        out.append(entry)
    return out


def read_curves(archive, entry, i, num_materials, member_name):
    """One strand set from a .lantern archive (scene_file.SceneArchive)."""
    if not isinstance(entry, dict):
        raise archive.error("scene.json", f"curves {i}: expected an object")
    c = dict(entry)
    for key in CURVE_ARRAYS + CURVE_MOTION_ARRAYS:
        if key in CURVE_MOTION_ARRAYS and entry.get(key) is None:
            c.pop(key, None)  # optional (motion blur)
            continue
        member = member_name(archive, entry, key, f"curves {i} {key}")
        kinds, ndim, last = CURVE_ARRAY_SPECS[key]
        c[key] = archive.read_array(member, f"curves {i} {key}", kinds, ndim, last)
    try:
        return validate_curves(c, i, num_materials)
    except ValueError as e:
        raise archive.error("scene.json", str(e)) from None
