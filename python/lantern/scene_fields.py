"""The scene's field names and their choices (docs/scene_format.md), and the checks of one
value that every validator in scene_schema.py and scene_schema_objects.py applies: a finite
float, an RGB, a vector, a 4x4 matrix, a bool, an int, a float or index array. Each raises
ValueError naming the field."""

import math

import numpy as np

CAMERA_TYPES = ("perspective", "orthographic", "equirectangular")
MATERIAL_TYPES = ("diffuse", "conductor", "dielectric", "principled", "mix", "translucent",
                  "hair")
MIX_LEAVES = 4
LIGHT_TYPES = ("point", "spot", "area", "sun")
AREA_SHAPES = ("square", "rectangle", "disk", "ellipse")
# a mesh's object ray visibility (Cycles' Object > Visibility; pt: native/src/integrator/
# pt_ray_visibility.h), each a bool, True when absent
RAY_VISIBILITY = ("visible_diffuse", "visible_glossy", "visible_transmission",
                  "visible_volume_scatter")
MESH_ARRAYS = ("positions", "indices", "normals", "uvs", "tangents", "material_ids",
               "attributes", "deform")
# node-graph programs (docs/scene_format.md "Node programs"; native/src/scene/material_program.h)
PROGRAM_TARGETS = ("base_color", "roughness", "metallic", "emission", "alpha", "mix_factor",
                   "bump", "displacement", "normal_map", "normal_map_world", "tangent", "density",
                   "volume_emission", "volume_color", "volume_emission_color",
                   "volume_absorption_color")
PROGRAM_REGS = 192
TEXTURE_COLORSPACES = ("srgb", "linear")
TEXTURE_WRAPS = ("repeat", "extend", "clip", "mirror")
TEXTURE_INTERPOLATIONS = ("linear", "closest")
TEXTURE_OUTPUTS = ("color", "alpha", "red", "green", "blue")
# material inputs that may name a texture (index into Scene.textures)
MATERIAL_TEXTURES = ("base_color_texture", "roughness_texture", "metallic_texture",
                     "alpha_texture", "normal_texture", "mix_texture", "emission_texture",
                     "coat_normal_texture")


def identity4():
    return [[1.0 if r == c else 0.0 for c in range(4)] for r in range(4)]


# ---- Small coercion helpers, each raising ValueError with the element's name ----
def _finite_float(value, what):
    try:
        f = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{what}: expected a number, got {value!r}") from None
    if not math.isfinite(f):
        raise ValueError(f"{what}: must be finite, got {f}")
    return f


def _rgb(value, what, nonnegative=True):
    if np.isscalar(value):
        value = [value] * 3
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{what}: expected an RGB triple, got {value!r}") from None
    if arr.shape != (3,):
        raise ValueError(f"{what}: expected 3 values (r, g, b), got shape {arr.shape}")
    if not np.isfinite(arr).all():
        raise ValueError(f"{what}: values must be finite, got {arr.tolist()}")
    if nonnegative and (arr < 0).any():
        raise ValueError(f"{what}: values must be >= 0, got {arr.tolist()}")
    return [float(x) for x in arr]


def _vec(value, n, what):
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{what}: expected {n} numbers, got {value!r}") from None
    if arr.shape != (n,):
        raise ValueError(f"{what}: expected {n} numbers, got shape {arr.shape}")
    if not np.isfinite(arr).all():
        raise ValueError(f"{what}: values must be finite, got {arr.tolist()}")
    return [float(x) for x in arr]


def _matrix(value, what, rigid=False):
    try:
        m = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{what}: expected a 4x4 matrix, got {value!r}") from None
    if m.shape != (4, 4):
        raise ValueError(f"{what}: expected a 4x4 matrix, got shape {m.shape}")
    if not np.isfinite(m).all():
        raise ValueError(f"{what}: matrix entries must be finite")
    if rigid:
        rot = m[:3, :3]
        if not np.allclose(rot.T @ rot, np.eye(3), atol=1e-3):
            raise ValueError(f"{what}: must be rigid (rotation + translation, no scale or shear)")
    return [[float(x) for x in row] for row in m]


def _bool(value, what):
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)) and value in (0, 1):
        return bool(value)
    raise ValueError(f"{what}: expected a bool, got {value!r}")


def _int(value, what, minimum=None):
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        else:
            raise ValueError(f"{what}: expected an integer, got {value!r}")
    value = int(value)
    if minimum is not None and value < minimum:
        raise ValueError(f"{what}: must be >= {minimum}, got {value}")
    return value


def _float_array(value, cols, what):
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError):
        raise ValueError(f"{what}: expected a numeric array") from None
    if arr.dtype.kind not in "fiu":
        raise ValueError(f"{what}: expected a numeric array, got dtype {arr.dtype}")
    if arr.ndim != 2 or arr.shape[1] != cols:
        raise ValueError(f"{what}: expected shape (N, {cols}), got {arr.shape}")
    return np.ascontiguousarray(arr, dtype=np.float32)


def _index_array(value, shape_desc, ndim, cols, what):
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError):
        raise ValueError(f"{what}: expected an integer array") from None
    if arr.size == 0 and arr.dtype.kind == "f":
        arr = arr.astype(np.int64)
    if arr.dtype.kind not in "iu":
        raise ValueError(f"{what}: expected an integer array, got dtype {arr.dtype}")
    if arr.ndim != ndim or (cols is not None and arr.shape[1] != cols):
        raise ValueError(f"{what}: expected shape {shape_desc}, got {arr.shape}")
    if arr.size and arr.min() < 0:
        raise ValueError(f"{what}: negative index {int(arr.min())}")
    if arr.size and int(arr.max()) > 0xFFFFFFFF:
        raise ValueError(f"{what}: index {int(arr.max())} does not fit in uint32")
    return np.ascontiguousarray(arr, dtype=np.uint32)


def motion_steps(steps, what):
    """Motion blur's matrices at the shutter's steps as nested lists (S, 4, 4), S >= 2. Values
    are not judged here: a singular or non-finite step gets the core's warning (the object then
    renders without motion blur)."""
    try:
        a = np.asarray(steps, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{what}: expected a list of 4x4 matrices") from None
    if a.ndim != 3 or a.shape[1:] != (4, 4) or a.shape[0] < 2:
        raise ValueError(f"{what}: expected at least 2 matrices of 4x4, got shape {a.shape}")
    return a.tolist()
