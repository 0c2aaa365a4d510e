"""The scene's fields: their names and choices, Blender's defaults, and the checks that
normalise them (docs/scene_format.md). `Scene` (scene.py) calls `validate_*` as elements are
added and in `Scene.validate()`; each raises ValueError naming the offending element.

The field names and the checks of one value are in scene_fields.py, the checks of materials,
meshes and lights in scene_schema_objects.py; this module holds Blender's defaults and the
checks of the film, camera, world and textures, and is where all of them are imported from."""

import math

import numpy as np

from .medium_schema import validate_world_volume
from .scene_fields import (  # noqa: F401 (imported from here: scene.py, scene_file.py)
    AREA_SHAPES, CAMERA_TYPES, LIGHT_TYPES, MATERIAL_TEXTURES, MATERIAL_TYPES, MESH_ARRAYS,
    MIX_LEAVES, PROGRAM_REGS, RAY_VISIBILITY, PROGRAM_TARGETS, TEXTURE_COLORSPACES, TEXTURE_INTERPOLATIONS,
    TEXTURE_OUTPUTS, TEXTURE_WRAPS, _bool, _finite_float, _float_array, _index_array, _int,
    _matrix, _rgb, _vec, identity4)
from .scene_schema_objects import (  # noqa: F401
    LIGHT_KEYS, LIGHT_KEYS_OF, flatten_programs, receiver_mask, validate_light, validate_material,
    validate_mesh, validate_program)

# Blender's default camera: 50 mm lens on a 36 mm sensor.
DEFAULT_TAN_HALF = 18.0 / 50.0


def look_at(eye, target, up=(0.0, 0.0, 1.0)):
    """Rigid row-major 4x4 camera-to-world matrix: the camera at `eye` looks down its local -Z
    towards `target`, local +Y as close to `up` as possible (Blender's camera convention)."""
    eye = np.asarray(eye, dtype=np.float64)
    forward = np.asarray(target, dtype=np.float64) - eye
    if not np.linalg.norm(forward) > 0:
        raise ValueError("look_at: eye and target coincide")
    forward /= np.linalg.norm(forward)
    up = np.asarray(up, dtype=np.float64)
    right = np.cross(forward, up)
    if np.linalg.norm(right) < 1e-9:
        # looking along `up`: pick any perpendicular
        right = np.cross(forward, [1.0, 0.0, 0.0])
        if np.linalg.norm(right) < 1e-9:
            right = np.cross(forward, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    true_up = np.cross(right, forward)
    m = np.eye(4)
    m[:3, 0] = right
    m[:3, 1] = true_up
    m[:3, 2] = -forward
    m[:3, 3] = eye
    return m.tolist()


def screen_for_fov(fov_deg, width, height):
    """Perspective view window on z=-1 for a field of view along the larger image side."""
    if not 0.0 < fov_deg < 180.0:
        raise ValueError(f"field of view must be in (0, 180) degrees, got {fov_deg}")
    t = math.tan(math.radians(fov_deg) / 2.0)
    if width >= height:
        tx, ty = t, t * height / width
    else:
        tx, ty = t * width / height, t
    return [-tx, tx, -ty, ty]


def default_film():
    return {"width": 64, "height": 64, "filter_width": 1.5}


def default_camera():
    return {
        "type": "perspective",
        "to_world": identity4(),
        "screen": [-DEFAULT_TAN_HALF, DEFAULT_TAN_HALF, -DEFAULT_TAN_HALF, DEFAULT_TAN_HALF],
        "clip": [0.1, 1000.0],
    }


def default_world():
    return {"color": [0.0, 0.0, 0.0]}


def validate_film(film):
    if not isinstance(film, dict):
        raise ValueError("film: expected a dict")
    out = dict(film)
    out["width"] = _int(film.get("width", 64), "film width", minimum=1)
    out["height"] = _int(film.get("height", 64), "film height", minimum=1)
    if out["width"] > 65536 or out["height"] > 65536:
        raise ValueError(f"film: resolution {out['width']}x{out['height']} is too large")
    fw = _finite_float(film.get("filter_width", 1.5), "film filter_width")
    if fw < 0:
        raise ValueError(f"film filter_width: must be >= 0, got {fw}")
    out["filter_width"] = fw
    if "transparent" in film:  # Blender's Film > Transparent (lantern.film)
        out["transparent"] = _bool(film["transparent"], "film transparent")
    if "catcher_mode" in film:  # the renders of shadow catchers (lantern/film.py)
        out["catcher_mode"] = _int(film["catcher_mode"], "film catcher_mode", minimum=0)
        if out["catcher_mode"] > 2:
            raise ValueError(f"film catcher_mode: expected 0, 1 or 2, got {out['catcher_mode']}")
    return out


def validate_camera(camera):
    if not isinstance(camera, dict):
        raise ValueError("camera: expected a dict")
    base = default_camera()
    out = dict(camera)
    ctype = camera.get("type", base["type"])
    if ctype not in CAMERA_TYPES:
        raise ValueError(f"camera type: expected one of {CAMERA_TYPES}, got {ctype!r}")
    out["type"] = ctype
    out["to_world"] = _matrix(camera.get("to_world", base["to_world"]), "camera to_world",
                              rigid=True)
    screen = _vec(camera.get("screen", base["screen"]), 4, "camera screen")
    if not (screen[0] < screen[1] and screen[2] < screen[3]):
        raise ValueError(f"camera screen: need xmin < xmax and ymin < ymax, got {screen}")
    out["screen"] = screen
    clip = _vec(camera.get("clip", base["clip"]), 2, "camera clip")
    if not (0.0 <= clip[0] < clip[1]):
        raise ValueError(f"camera clip: need 0 <= start < end, got {clip}")
    out["clip"] = clip
    if camera.get("dof") is not None:
        out["dof"] = validate_dof(camera["dof"])
    if camera.get("motion") is not None:  # motion blur: to_world at the shutter's steps
        from .scene_schema_objects import motion_steps
        out["motion"] = motion_steps(camera["motion"], "camera motion")
    for key, lim in (("longitude", math.pi), ("latitude", math.pi / 2)):
        if camera.get(key) is not None:  # equirectangular: [min, max] radians
            rng = _vec(camera[key], 2, f"camera {key}")
            if not (-lim - 1e-6 <= rng[0] < rng[1] <= lim + 1e-6):
                raise ValueError(f"camera {key}: need -{lim:.4f} <= min < max <= {lim:.4f}, "
                                 f"got {rng}")
            out[key] = rng
    return out


def validate_dof(dof):
    """Depth of field: a thin lens of `radius` m (Blender: lens / (2 f-stop)) focused at
    `focus_distance` m along the view axis; `blades` >= 3 make the aperture a polygon turned
    by `rotation` (radians); `ratio` is Blender's anamorphic aperture ratio."""
    if not isinstance(dof, dict):
        raise ValueError("camera dof: expected a dict")
    out = {"radius": _finite_float(dof.get("radius", 0.0), "camera dof radius"),
           "focus_distance": _finite_float(dof.get("focus_distance", 10.0),
                                           "camera dof focus_distance"),
           "blades": _int(dof.get("blades", 0), "camera dof blades", minimum=0),
           "rotation": _finite_float(dof.get("rotation", 0.0), "camera dof rotation"),
           "ratio": _finite_float(dof.get("ratio", 1.0), "camera dof ratio")}
    if out["radius"] < 0.0 or out["focus_distance"] < 0.0 or out["ratio"] <= 0.0:
        raise ValueError(f"camera dof: need radius >= 0, focus_distance >= 0, ratio > 0, "
                         f"got {out}")
    return out


WORLD_PROJECTIONS = ("equirectangular", "mirror_ball")


def validate_world(world):
    if not isinstance(world, dict):
        raise ValueError("world: expected a dict")
    out = dict(world)
    out["color"] = _rgb(world.get("color", [0.0, 0.0, 0.0]), "world color")
    out["visible_camera"] = _bool(world.get("visible_camera", True), "world visible_camera")
    for ray in ("diffuse", "glossy", "transmission", "volume_scatter"):  # ray visibility (pt)
        if f"visible_{ray}" in world:
            out[f"visible_{ray}"] = _bool(world[f"visible_{ray}"], f"world visible_{ray}")
    if world.get("map") is not None:
        _validate_world_map(world, out)
    if world.get("sun") is not None:  # the Sky Texture's sun disc: a sun light of the world
        sun = world["sun"]
        if not isinstance(sun, dict) or sun.get("type") != "sun":
            raise ValueError("world sun: expected a light dict of type 'sun'")
        out["sun"] = validate_light(sun, "of the world")
    else:
        out.pop("sun", None)
    validate_world_volume(world, out)  # media: lantern/medium_schema.py
    return out


def _validate_world_map(world, out):
    """The environment map: float32 (H, W, 3|4) linear radiance, rows bottom to top; its
    non-finite or negative texels are the core's to clamp (with a warning), not an error."""
    try:
        px = np.asarray(world["map"])
    except (TypeError, ValueError):
        raise ValueError("world map: expected an array") from None
    if px.ndim != 3 or px.shape[2] not in (3, 4) or px.shape[0] < 1 or px.shape[1] < 1:
        raise ValueError(f"world map: expected shape (height, width, 3), got {px.shape}")
    if px.shape[0] > 65536 or px.shape[1] > 65536:
        raise ValueError(f"world map: {px.shape[1]}x{px.shape[0]} is too large")
    if px.dtype.kind not in "fiu":
        raise ValueError(f"world map: expected float32 texels, got {px.dtype}")
    out["map"] = np.ascontiguousarray(px, dtype=np.float32)
    out["map_name"] = str(world.get("map_name", ""))
    out["strength"] = _rgb(world.get("strength", [1.0, 1.0, 1.0]), "world strength")
    projection = world.get("projection", "equirectangular")
    if projection not in WORLD_PROJECTIONS:
        raise ValueError(f"world projection: expected one of {WORLD_PROJECTIONS}, "
                         f"got {projection!r}")
    out["projection"] = projection
    try:
        m = np.asarray(world.get("to_map", np.eye(3)), dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise ValueError("world to_map: expected a 3x3 matrix") from None
    if m.shape != (9,) or not np.isfinite(m).all():
        raise ValueError(f"world to_map: expected a finite 3x3 matrix, got {m.tolist()}")
    out["to_map"] = m.reshape(3, 3).tolist()


def validate_texture(texture, index):
    if not isinstance(texture, dict):
        raise ValueError(f"texture {index}: expected a dict")
    name = str(texture.get("name", f"texture_{index}"))
    what = f"texture {index} ({name!r})"
    out = dict(texture)
    out["name"] = name
    try:
        px = np.asarray(texture.get("pixels"))
    except (TypeError, ValueError):
        raise ValueError(f"{what} pixels: expected an array") from None
    if px.ndim != 3 or px.shape[2] not in (3, 4) or px.shape[0] < 1 or px.shape[1] < 1:
        raise ValueError(f"{what} pixels: expected shape (height, width, 4), got {px.shape}")
    if px.shape[0] > 65536 or px.shape[1] > 65536:
        raise ValueError(f"{what} pixels: {px.shape[1]}x{px.shape[0]} is too large")
    if px.dtype == np.uint8:
        if px.shape[2] == 3:
            px = np.concatenate([px, np.full(px.shape[:2] + (1,), 255, np.uint8)], axis=2)
    elif px.dtype.kind in "fiu":
        px = px.astype(np.float32)
        if px.shape[2] == 3:
            px = np.concatenate([px, np.ones(px.shape[:2] + (1,), np.float32)], axis=2)
    else:
        raise ValueError(f"{what} pixels: expected uint8 or float32, got {px.dtype}")
    out["pixels"] = np.ascontiguousarray(px)
    for key, allowed, default in (("colorspace", TEXTURE_COLORSPACES, "srgb"),
                                  ("wrap", TEXTURE_WRAPS, "repeat"),
                                  ("interpolation", TEXTURE_INTERPOLATIONS, "linear"),
                                  ("output", TEXTURE_OUTPUTS, "color")):
        v = texture.get(key, default)
        if v not in allowed:
            raise ValueError(f"{what} {key}: expected one of {allowed}, got {v!r}")
        out[key] = v
    if px.dtype != np.uint8:
        out["colorspace"] = "linear"  # float texels are scene linear
    xf = texture.get("uv_transform", [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    try:
        xf = np.asarray(xf, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{what} uv_transform: expected a 2x3 matrix") from None
    if xf.shape != (2, 3) or not np.isfinite(xf).all():
        raise ValueError(f"{what} uv_transform: expected a finite 2x3 matrix, got {xf.tolist()}")
    out["uv_transform"] = xf.tolist()
    return out
