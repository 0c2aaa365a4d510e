"""The scene's fields: their names and choices, Blender's defaults, and the checks that
normalise them (docs/scene_format.md). `Scene` (scene.py) calls `validate_*` as elements are
added and in `Scene.validate()`; each raises ValueError naming the offending element."""

import math

import numpy as np

CAMERA_TYPES = ("perspective", "orthographic", "equirectangular")
MATERIAL_TYPES = ("diffuse", "conductor", "dielectric", "principled", "mix", "translucent")
MIX_LEAVES = 4
LIGHT_TYPES = ("point", "spot", "area", "sun")
AREA_SHAPES = ("square", "rectangle", "disk", "ellipse")
MESH_ARRAYS = ("positions", "indices", "normals", "uvs", "tangents", "material_ids",
               "attributes")
# node-graph programs (docs/scene_format.md "Node programs"; native/src/scene/material_program.h)
PROGRAM_TARGETS = ("base_color", "roughness", "metallic", "emission", "alpha", "mix_factor",
                   "bump", "displacement", "normal_map", "normal_map_world", "tangent")
PROGRAM_REGS = 192
TEXTURE_COLORSPACES = ("srgb", "linear")
TEXTURE_WRAPS = ("repeat", "extend", "clip", "mirror")
TEXTURE_INTERPOLATIONS = ("linear", "closest")
TEXTURE_OUTPUTS = ("color", "alpha", "red", "green", "blue")
# material inputs that may name a texture (index into Scene.textures)
MATERIAL_TEXTURES = ("base_color_texture", "roughness_texture", "metallic_texture",
                     "alpha_texture", "normal_texture", "mix_texture", "emission_texture",
                     "coat_normal_texture")

# Blender's default camera: 50 mm lens on a 36 mm sensor.
DEFAULT_TAN_HALF = 18.0 / 50.0


def identity4():
    return [[1.0 if r == c else 0.0 for c in range(4)] for r in range(4)]


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
    for ray in ("diffuse", "glossy", "transmission"):  # ray visibility (pt)
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

def validate_material(material, index, num_textures=0):
    if not isinstance(material, dict):
        raise ValueError(f"material {index}: expected a dict")
    name = str(material.get("name", f"material_{index}"))
    what = f"material {index} ({name!r})"
    mtype = material.get("type", "diffuse")
    if mtype not in MATERIAL_TYPES:
        raise ValueError(f"{what}: unknown type {mtype!r}, expected one of {MATERIAL_TYPES}")
    out = dict(material)
    out["name"] = name
    out["type"] = mtype
    out["base_color"] = _rgb(material.get("base_color", [0.8, 0.8, 0.8]),
                             f"{what} base_color")
    # an albedo alone (diffuse, translucent, a principled without metal or glass) may exceed
    # 1, as Cycles' closure weights do (docs/nodes.md); where it is also a Fresnel F0 or a
    # tint it may not (the core clamps it there, kAlbedoBase)
    albedo = mtype in ("diffuse", "translucent") or (
        mtype == "principled" and not material.get("metallic", 0.0) and
        not material.get("transmission", 0.0) and "metallic_texture" not in material)
    if max(out["base_color"]) > 1.0 and not albedo:
        raise ValueError(f"{what} base_color: must be in [0, 1] for type {mtype!r}, "
                         f"got {out['base_color']}")
    out["emission"] = _rgb(material.get("emission", [0.0, 0.0, 0.0]), f"{what} emission")
    out["specular_tint"] = _rgb(material.get("specular_tint", [1.0, 1.0, 1.0]),
                                f"{what} specular_tint")
    out["coat_tint"] = _rgb(material.get("coat_tint", [1.0, 1.0, 1.0]), f"{what} coat_tint")
    out["sheen_tint"] = _rgb(material.get("sheen_tint", [1.0, 1.0, 1.0]),
                             f"{what} sheen_tint")
    for key, default, lo, hi in (("roughness", 0.5, 0.0, 1.0), ("ior", 1.5, 0.01, 100.0),
                                 ("diffuse_roughness", 0.0, 0.0, 1.0),
                                 ("anisotropy", 0.0, 0.0, 1.0),
                                 ("anisotropic_rotation", 0.0, -1e6, 1e6),
                                 ("metallic", 0.0, 0.0, 1.0), ("transmission", 0.0, 0.0, 1.0),
                                 ("specular_level", 0.5, 0.0, 1e3),
                                 ("coat_weight", 0.0, 0.0, 1.0),
                                 ("coat_roughness", 0.03, 0.0, 1.0),
                                 ("coat_ior", 1.5, 1.0, 100.0),
                                 ("sheen_weight", 0.0, 0.0, 1e3),
                                 ("sheen_roughness", 0.5, 0.0, 1.0),
                                 ("thin_film_thickness", 0.0, 0.0, 1e5),
                                 ("thin_film_ior", 1.33, 1.0, 100.0),
                                 ("alpha", 1.0, 0.0, 1.0),
                                 ("normal_strength", 1.0, 0.0, 1e3),
                                 ("coat_normal_strength", 1.0, 0.0, 1e3)):
        try:
            v = float(material.get(key, default))
        except (TypeError, ValueError):
            raise ValueError(f"{what} {key}: expected a number, got {material.get(key)!r}")
        if not (lo <= v <= hi):
            raise ValueError(f"{what} {key}: must be in [{lo}, {hi}], got {v}")
        out[key] = v
    tangent = material.get("tangent", "triangle")
    if tangent not in ("uv", "triangle"):
        raise ValueError(f"{what} tangent: 'uv' or 'triangle', got {tangent!r}")
    out["tangent"] = tangent
    dist = material.get("distribution", "ggx")
    if dist not in ("ggx", "beckmann"):
        raise ValueError(f"{what} distribution: 'ggx' or 'beckmann', got {dist!r}")
    if dist == "beckmann" and mtype != "conductor":
        raise ValueError(f"{what}: the Beckmann distribution applies to conductors only")
    out["distribution"] = dist
    ms = material.get("multiscatter", True)
    if not isinstance(ms, (bool, np.bool_)):
        raise ValueError(f"{what} multiscatter: expected True or False, got {ms!r}")
    out["multiscatter"] = bool(ms)
    tint = material.get("tint_reflection", False)
    if not isinstance(tint, (bool, np.bool_)):
        raise ValueError(f"{what} tint_reflection: expected True or False, got {tint!r}")
    out["tint_reflection"] = bool(tint)
    eta, k = material.get("eta"), material.get("k")
    out.pop("eta", None)
    out.pop("k", None)
    if eta is not None or k is not None:
        if mtype != "conductor":
            raise ValueError(f"{what}: eta and k apply to conductors only (type {mtype!r})")
        if eta is None or k is None:
            raise ValueError(f"{what}: a complex index needs both eta and k")
        out["eta"] = _rgb(eta, f"{what} eta")
        out["k"] = _rgb(k, f"{what} k")
    if mtype == "mix":
        mix = material.get("mix")
        if not isinstance(mix, (list, tuple)) or not 1 <= len(mix) <= MIX_LEAVES:
            raise ValueError(f"{what} mix: expected 1 to {MIX_LEAVES} [leaf, weight] pairs, "
                             f"got {mix!r}")
        pairs = []
        for entry in mix:
            if not isinstance(entry, (list, tuple)) or len(entry) != 2:
                raise ValueError(f"{what} mix: expected [leaf, weight] pairs, got {entry!r}")
            leaf = _int(entry[0], f"{what} mix leaf", minimum=0)
            weight = _finite_float(entry[1], f"{what} mix weight")
            if weight < 0:
                raise ValueError(f"{what} mix weight: must be >= 0, got {weight}")
            pairs.append([leaf, weight])
        out["mix"] = pairs
        if material.get("mix_texture") is not None and len(pairs) != 2:
            raise ValueError(f"{what} mix_texture: a factor texture needs exactly two leaves")
    elif "mix" in material:
        raise ValueError(f"{what}: 'mix' applies to materials of type 'mix' only")
    for key in MATERIAL_TEXTURES:
        t = material.get(key)
        if t is None:
            out.pop(key, None)
            continue
        t = _int(t, f"{what} {key}", minimum=0)
        if t >= num_textures:
            raise ValueError(f"{what} {key}: texture {t} out of range (scene has "
                             f"{num_textures} textures)")
        out[key] = t
    if material.get("programs") is not None:
        out["programs"] = [validate_program(p, f"{what} program {i}", num_textures)
                           for i, p in enumerate(material["programs"])]
    return out


def validate_program(prog, what, num_textures=0):
    """A node-graph program: target, code ([[w0, w1, w2, w3], ...] uint32 words), consts
    (floats: the register image, then tables), num_const, result (register)."""
    if not isinstance(prog, dict):
        raise ValueError(f"{what}: expected a dict")
    target = prog.get("target")
    if target not in PROGRAM_TARGETS:
        raise ValueError(f"{what}: unknown target {target!r}, expected one of {PROGRAM_TARGETS}")
    try:
        code = np.asarray(prog.get("code", []), dtype=np.int64).reshape(-1, 4)
        consts = np.asarray(prog.get("consts", []), dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise ValueError(f"{what}: code must be rows of 4 integers and consts numbers") from None
    if code.size and (code.min() < 0 or code.max() > 0xFFFFFFFF):
        raise ValueError(f"{what}: code words must be 32-bit unsigned")
    num_const = _int(prog.get("num_const", 0), f"{what} num_const", minimum=0)
    result = _int(prog.get("result", 0), f"{what} result", minimum=0)
    if num_const > min(len(consts), PROGRAM_REGS) or result + 3 > PROGRAM_REGS:
        raise ValueError(f"{what}: num_const or result out of range")
    return {"target": target, "code": code.tolist(), "consts": [float(c) for c in consts],
            "num_const": num_const, "result": result}


def flatten_programs(materials):
    """The scene's programs as the arrays the core takes: (programs, code, consts) and, per
    material, (first, count) into programs. Table offsets (ops ramp, curves: word 2) become
    offsets in the scene's constants."""
    rows, code, consts, spans = [], [], [], []
    for m in materials:
        progs = m.get("programs") or []
        spans.append((len(rows), len(progs)))
        for p in progs:
            c = np.asarray(p["code"], dtype=np.uint32).reshape(-1, 4).copy()
            base = sum(len(x) for x in consts)
            tables = np.isin(c[:, 0] & 0xFF, (21, 22))   # kOpRamp, kOpCurves
            c[tables, 2] += np.uint32(base)
            rows.append([sum(len(x) for x in code), len(c), base, p["num_const"],
                         PROGRAM_TARGETS.index(p["target"]), p["result"]])
            code.append(c)
            consts.append(np.asarray(p["consts"], np.float32))
    return (np.asarray(rows, np.uint32).reshape(-1, 6),
            np.ascontiguousarray(np.concatenate(code) if code else np.zeros((0, 4), np.uint32)),
            np.ascontiguousarray(np.concatenate(consts) if consts else np.zeros(0, np.float32))
            ), spans

def validate_mesh(mesh, index, num_materials=None):
    """Validates and coerces `mesh` in place."""
    if not isinstance(mesh, dict):
        raise ValueError(f"mesh {index}: expected a dict")
    name = str(mesh.get("name", f"mesh_{index}"))
    mesh["name"] = name
    what = f"mesh {index} ({name!r})"
    for key in ("positions", "indices"):
        if mesh.get(key) is None:
            raise ValueError(f"{what}: missing {key}")
    pos = _float_array(mesh["positions"], 3, f"{what} positions")
    vcount = pos.shape[0]
    idx = _index_array(mesh["indices"], "(T, 3)", 2, 3, f"{what} indices")
    tcount = idx.shape[0]
    if idx.size and int(idx.max()) >= vcount:
        bad = int(np.argmax(idx.max(axis=1) >= vcount))
        raise ValueError(f"{what}: vertex index {int(idx.max())} out of range "
                         f"(mesh has {vcount} vertices; first bad triangle {bad})")
    normals = mesh.get("normals")
    if normals is not None:
        normals = _float_array(normals, 3, f"{what} normals")
        if normals.shape[0] != vcount:
            raise ValueError(f"{what} normals: {normals.shape[0]} rows for {vcount} vertices")
    uvs = mesh.get("uvs")
    if uvs is not None:
        uvs = _float_array(uvs, 2, f"{what} uvs")
        if uvs.shape[0] != vcount:
            raise ValueError(f"{what} uvs: {uvs.shape[0]} rows for {vcount} vertices")
    tangents = mesh.get("tangents")
    if tangents is not None:
        tangents = _float_array(tangents, 4, f"{what} tangents")
        if tangents.shape[0] != vcount:
            raise ValueError(f"{what} tangents: {tangents.shape[0]} rows for {vcount} "
                             "vertices")
    mids = mesh.get("material_ids")
    if mids is None:
        mids = np.zeros(tcount, dtype=np.uint32)
    mids = _index_array(mids, "(T,)", 1, None, f"{what} material_ids")
    if mids.shape[0] != tcount:
        raise ValueError(f"{what} material_ids: {mids.shape[0]} entries for "
                         f"{tcount} triangles")
    if num_materials is not None and mids.size and int(mids.max()) >= num_materials:
        raise ValueError(f"{what}: material id {int(mids.max())} out of range "
                         f"(scene has {num_materials} materials)")
    mesh["positions"] = pos
    mesh["indices"] = idx
    mesh["normals"] = normals
    mesh["uvs"] = uvs
    mesh["tangents"] = tangents
    mesh["material_ids"] = mids
    attrs = mesh.get("attributes")
    if attrs is not None:
        attrs = np.ascontiguousarray(np.asarray(attrs, dtype=np.float32))
        if attrs.ndim != 2 or attrs.shape[0] != vcount or attrs.shape[1] % 3:
            raise ValueError(f"{what} attributes: expected (V, 3 C) floats for {vcount} "
                             f"vertices, got {attrs.shape}")
    mesh["attributes"] = attrs
    mesh["visible_camera"] = _bool(mesh.get("visible_camera", True),
                                   f"{what} visible_camera")
    mesh["cast_shadow"] = _bool(mesh.get("cast_shadow", True), f"{what} cast_shadow")
    if "shadow_catcher" in mesh:  # a shadow catcher (pt; lantern/film.py)
        mesh["shadow_catcher"] = _bool(mesh["shadow_catcher"], f"{what} shadow_catcher")
    return mesh

def validate_light(light, index):
    if not isinstance(light, dict):
        raise ValueError(f"light {index}: expected a dict")
    ltype = light.get("type")
    what = f"light {index} ({ltype})"
    if ltype not in LIGHT_TYPES:
        raise ValueError(f"light {index}: unknown type {ltype!r}, expected one of "
                         f"{LIGHT_TYPES}")
    out = dict(light)
    if light.get("name") is not None:  # the object's name, for warnings
        out["name"] = str(light["name"])
    energy_key = "strength" if ltype == "sun" else "power"
    if energy_key not in light:
        raise ValueError(f"{what}: missing {energy_key!r}")
    out[energy_key] = _rgb(light[energy_key], f"{what} {energy_key}")
    if ltype != "sun":
        out["visible_camera"] = _bool(light.get("visible_camera", False),
                                      f"{what} visible_camera")
    if ltype in ("point", "spot"):
        radius = _finite_float(light.get("radius", 0.0), f"{what} radius")
        if radius < 0:
            raise ValueError(f"{what} radius: must be >= 0, got {radius}")
        out["radius"] = radius
    if ltype == "point":
        out["position"] = _vec(light.get("position", [0.0, 0.0, 0.0]), 3,
                               f"{what} position")
    elif ltype == "spot":
        out["to_world"] = _matrix(light.get("to_world", identity4()), f"{what} to_world")
        size = _finite_float(light.get("spot_size", math.radians(45.0)),
                             f"{what} spot_size")
        if not 0.0 < size <= math.pi:
            raise ValueError(f"{what} spot_size: must be in (0, pi], got {size}")
        out["spot_size"] = size
        blend = _finite_float(light.get("spot_blend", 0.15), f"{what} spot_blend")
        if not 0.0 <= blend <= 1.0:
            raise ValueError(f"{what} spot_blend: must be in [0, 1], got {blend}")
        out["spot_blend"] = blend
    elif ltype == "area":
        out["to_world"] = _matrix(light.get("to_world", identity4()), f"{what} to_world",
                                  rigid=True)
        shape = light.get("shape", "square")
        if shape not in AREA_SHAPES:
            raise ValueError(f"{what} shape: expected one of {AREA_SHAPES}, got {shape!r}")
        out["shape"] = shape
        size = _vec(light.get("size", [1.0, 1.0]), 2, f"{what} size")
        if min(size) <= 0:
            raise ValueError(f"{what} size: must be > 0, got {size}")
        out["size"] = size
    elif ltype == "sun":
        direction = _vec(light.get("direction", [0.0, 0.0, -1.0]), 3, f"{what} direction")
        norm = math.sqrt(sum(d * d for d in direction))
        if norm == 0:
            raise ValueError(f"{what} direction: must not be zero")
        out["direction"] = direction
        angle = _finite_float(light.get("angle", 0.0), f"{what} angle")
        if not 0.0 <= angle <= math.pi:
            raise ValueError(f"{what} angle: must be in [0, pi], got {angle}")
        out["angle"] = angle
    if ltype in ("point", "spot") and light.get("soft_falloff") is not None:
        out["soft_falloff"] = _bool(light["soft_falloff"], f"{what} soft_falloff")
    if ltype == "sun" and light.get("visible_camera") is not None:
        out["visible_camera"] = _bool(light["visible_camera"], f"{what} visible_camera")
    for key in LIGHT_KEYS:  # the core reads every one of these from every light
        if key not in LIGHT_KEYS_OF[ltype]:
            out.pop(key, None)
    return out


LIGHT_KEYS = ("to_world", "position", "direction", "radius", "spot_size", "spot_blend",
              "shape", "size", "angle", "soft_falloff", "power", "strength")
LIGHT_KEYS_OF = {"point": ("position", "radius", "soft_falloff", "power"),
                 "spot": ("to_world", "radius", "spot_size", "spot_blend", "soft_falloff",
                          "power"),
                 "area": ("to_world", "shape", "size", "power"),
                 "sun": ("direction", "angle", "strength")}
