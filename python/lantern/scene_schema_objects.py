"""The checks of a scene's materials (with their node programs), meshes and lights
(docs/scene_format.md); scene_schema.py is where they are imported from. Each normalises its
element and raises ValueError naming the offending one."""

import math

import numpy as np

from .medium_schema import validate_material_volume
from .scene_fields import (AREA_SHAPES, LIGHT_TYPES, MATERIAL_TEXTURES, MATERIAL_TYPES,
                           MIX_LEAVES, PROGRAM_REGS, PROGRAM_TARGETS, RAY_VISIBILITY, _bool,
                           _finite_float, _float_array, _index_array, _int, _matrix, _rgb, _vec, identity4,
                           motion_steps)


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
    _validate_subsurface(material, out, what, mtype)
    if mtype == "hair":  # Principled Hair (docs/curves.md)
        from .curves_schema import validate_hair
        validate_hair(material, out, what)
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
    validate_material_volume(material, out, what)  # media: lantern/medium_schema.py
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
    for key in RAY_VISIBILITY:  # object ray visibility (pt); absent: visible
        if key in mesh:
            mesh[key] = _bool(mesh[key], f"{what} {key}")
    for key in ("light_set", "shadow_set"):  # light / shadow linking (pt): its set
        if key in mesh:
            mesh[key] = _int(mesh[key], f"{what} {key}", minimum=0)
            if mesh[key] > 63:
                raise ValueError(f"{what} {key}: must be in [0, 63], got {mesh[key]}")
    for key in ("receivers", "blockers"):  # the sets its emission lights / is shadowed by
        if key in mesh:
            mesh[key] = receiver_mask(mesh[key], f"{what} {key}")
    if "flat_shading" in mesh:  # each triangle shaded by its own normal, the normals unread
        mesh["flat_shading"] = _bool(mesh["flat_shading"], f"{what} flat_shading")
    if "terminator_offset" in mesh:  # Cycles' Shadow Terminator Geometry Offset (pt)
        t = _finite_float(mesh["terminator_offset"], f"{what} terminator_offset")
        if not 0.0 <= t <= 1.0:
            raise ValueError(f"{what} terminator_offset: must be in [0, 1], got {t}")
        mesh["terminator_offset"] = t
    if "shadow_catcher" in mesh:  # a shadow catcher (pt; lantern/film.py)
        mesh["shadow_catcher"] = _bool(mesh["shadow_catcher"], f"{what} shadow_catcher")
    if mesh.get("deform") is not None:  # deformation blur (docs/motion_blur.md)
        mesh["deform"] = deform_steps(mesh["deform"], vcount, f"{what} deform")
    if mesh.get("motion") is not None:  # motion blur (docs/motion_blur.md)
        mesh["motion"] = motion_steps(mesh["motion"], f"{what} motion")
        base = mesh.get("motion_base")
        mesh["motion_base"] = motion_steps([base if base is not None else np.eye(4)] * 2,
                                           f"{what} motion_base")[0]
    return mesh


def deform_steps(steps, vcount, what):
    """Deformation blur's positions at the shutter's steps: float32 (S, N, 3), S >= 2, N the
    mesh's vertex count. Values are not judged here: a non-finite step gets the core's warning
    (the mesh then renders without deformation blur)."""
    try:
        a = np.asarray(steps)
    except (TypeError, ValueError):
        raise ValueError(f"{what}: expected a numeric array of shape (S, N, 3)") from None
    if a.dtype.kind not in "fiu":
        raise ValueError(f"{what}: expected a numeric array, got dtype {a.dtype}")
    if a.ndim != 3 or a.shape[0] < 2 or a.shape[1:] != (vcount, 3):
        raise ValueError(f"{what}: expected shape (S >= 2, {vcount}, 3) (the positions at each "
                         f"step), got {a.shape}")
    return np.ascontiguousarray(a, dtype=np.float32)


def receiver_mask(value, what):
    """Light linking: the receiver sets an emitter lights, a 64-bit mask (bit s: set s; the
    meshes' light_set) given as an int or a list of set numbers."""
    if isinstance(value, (list, tuple)):
        mask = 0
        for s in value:
            s = _int(s, what, minimum=0)
            if s > 63:
                raise ValueError(f"{what}: receiver set {s} is not in [0, 63]")
            mask |= 1 << s
        return mask
    mask = _int(value, what, minimum=0)
    if mask >= 1 << 64:
        raise ValueError(f"{what}: a 64-bit mask, got {value!r}")
    return mask


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
    for key in ("receivers", "blockers"):  # light and shadow linking (pt)
        if key in light:
            out[key] = receiver_mask(light[key], f"{what} {key}")
    for key in RAY_VISIBILITY:  # a lamp's own ray visibility (pt); absent: visible
        if key in light:
            out[key] = _bool(light[key], f"{what} {key}")
    if "cast_shadow" in light:  # Blender's Cast Shadow (pt; absent: it casts shadows)
        out["cast_shadow"] = _bool(light["cast_shadow"], f"{what} cast_shadow")
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


SUBSURFACE_METHODS = ("random_walk", "random_walk_skin")


def _validate_subsurface(material, out, what, mtype):
    """Principled subsurface (docs/subsurface.md): kept only where a key is given, so that
    materials without it stay as they were. Radius is Blender's Radius x Scale in metres; 0
    renders as the diffuse base and above 1e6 is clamped (the core says so in its warnings)."""
    keys = ("subsurface_weight", "subsurface_radius", "subsurface_ior",
            "subsurface_anisotropy", "subsurface_method")
    for key in keys:
        out.pop(key, None)
    if not any(key in material for key in keys):
        return
    if mtype != "principled":
        raise ValueError(f"{what}: subsurface applies to principled materials only "
                         f"(type {mtype!r})")
    for key, default, lo, hi in (("subsurface_weight", 0.0, 0.0, 1.0),
                                 ("subsurface_ior", 1.4, 0.01, 100.0),
                                 ("subsurface_anisotropy", 0.0, -1.0, 1.0)):
        try:
            v = float(material.get(key, default))
        except (TypeError, ValueError):
            raise ValueError(f"{what} {key}: expected a number, got {material.get(key)!r}")
        if not (lo <= v <= hi):
            raise ValueError(f"{what} {key}: must be in [{lo}, {hi}], got {v}")
        out[key] = v
    out["subsurface_radius"] = _rgb(material.get("subsurface_radius", [0.05, 0.02, 0.01]),
                                    f"{what} subsurface_radius")
    method = material.get("subsurface_method", "random_walk")
    if method not in SUBSURFACE_METHODS:
        raise ValueError(f"{what} subsurface_method: one of {SUBSURFACE_METHODS}, "
                         f"got {method!r}")
    out["subsurface_method"] = method
