"""World -> Lantern world (docs/scene_format.md, "World"): the Background node's colour times
its strength, or an Environment Texture (equirectangular or mirror ball) reached through
Texture Coordinate (Generated, Object) and Mapping nodes, as a float radiance map and the 3x3
matrix that takes a world direction to the vector the texture reads. The core builds the
map's importance distribution once per scene. A missing or unreadable image renders a black
world with a warning; what Lantern does not render is named in a warning."""

import math

import bpy
import numpy as np

from .sky import sky_world
from .texture import mapping_constant
from .volume import attach_world_volume
from .world_nodes import bake as bake_node_world

MAX_MAP_WIDTH = 8192  # wider maps are box-filtered down (their lighting changes little)
_LINEAR_SPACES = {"Non-Color", "Linear", "Linear Rec.709", "Raw", "Generic Data",
                  "Utility - Raw"}
_PROJECTIONS = {"EQUIRECTANGULAR": "equirectangular", "MIRROR_BALL": "mirror_ball"}


def _socket_color(socket):
    v = socket.default_value
    return [float(v[0]), float(v[1]), float(v[2])]


def _euler_xyz(rx, ry, rz):
    """Blender's XYZ Euler rotation matrix (X applied first)."""
    cx, sx, cy, sy, cz, sz = (math.cos(rx), math.sin(rx), math.cos(ry), math.sin(ry),
                              math.cos(rz), math.sin(rz))
    x = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    y = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    z = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return z @ y @ x


def mapping_matrix(kind, location, rotation, scale, where, report):
    """The linear part of a Mapping node of `kind` on a direction, as a 3x3 array, or None."""
    r = _euler_xyz(*rotation)
    s = np.diag(scale).astype(np.float64)
    if kind in ("POINT", "TEXTURE") and max(abs(v) for v in location) > 1e-6:
        report.warn(f"{where}: the Mapping Location moves a direction; Lantern ignores it for "
                    "the world")
    if kind in ("POINT", "VECTOR"):      # R (S v) (+ L)
        return r @ s
    if abs(np.linalg.det(s)) < 1e-12:
        report.warn(f"{where}: a Mapping Scale of zero; the mapping is ignored")
        return None
    if kind == "TEXTURE":                # S^-1 R^-1 (v - L)
        return np.linalg.inv(s) @ r.T
    if kind == "NORMAL":                 # R (S^-1 v), normalised: a direction anyway
        return r @ np.linalg.inv(s)
    report.warn(f"{where}: Mapping type {kind} is not supported; ignored")
    return None


def vector_matrix(env_node, where, report):
    """World direction -> the Environment Texture's vector: Mapping and Texture Coordinate
    nodes upstream of its Vector input, composed (3x3)."""
    m = np.eye(3)
    # by identifier: bpy 5.0.1's inputs.get misses a socket it holds unavailable
    sock = next((s for s in env_node.inputs if s.identifier == "Vector"), None)
    if sock is not None and sock.is_linked and not (sock.enabled and sock.links[0].is_valid):
        # bpy 5.0.1 holds the Multiple and Single Scattering Sky Texture's Vector unavailable
        # while its Sun Disc is on, and Cycles then ignores a link into it: the sky is not
        # turned (measured, tests/render/test_sky_cycles.py); Preetham's is always available
        report.warn(f"{where}: '{env_node.name}': the link into its unavailable Vector input "
                    "is ignored (as Cycles does)")
        return m
    for _ in range(16):
        if sock is None or not sock.is_linked:
            break
        link = sock.links[0]
        src = link.from_node
        if src.type == "REROUTE":
            sock = src.inputs[0]
        elif src.type == "MAPPING":
            def const(name, default):
                return mapping_constant(src, name, where, report) or [default] * 3
            mm = mapping_matrix(getattr(src, "vector_type", "POINT"), const("Location", 0.0),
                                const("Rotation", 0.0), const("Scale", 1.0),
                                f"{where}: Mapping '{src.name}'", report)
            if mm is not None:
                m = m @ mm
            sock = src.inputs.get("Vector")
        elif src.type == "TEX_COORD":
            out = link.from_socket.name
            if out == "Object" and src.object is not None:
                # Cycles transforms the direction by the object's inverse matrix
                inv = np.linalg.inv(np.array(src.object.matrix_world, dtype=np.float64))
                if np.abs(inv[:3, 3]).max() > 1e-6:
                    report.warn(f"{where}: Texture Coordinate '{src.name}' Object: the "
                                f"translation of '{src.object.name}' is ignored for the world")
                m = m @ inv[:3, :3]
            elif out not in ("Generated", "Object", "Normal"):
                report.warn(f"{where}: Texture Coordinate output '{out}' is not supported for "
                            "the world; the view direction is used")
            break
        else:
            report.warn(f"{where}: '{src.name}' ({src.type}) feeding the Environment Texture's "
                        "Vector is not supported; the view direction is used")
            break
    return m


def read_map(image, where, report, cache=None):
    """Linear RGB float32 (H, W, 3), rows bottom to top, of a Blender image; None when it
    cannot be read (missing file, no pixels)."""
    key = ("world", image.name_full, tuple(image.size), image.filepath_raw,
           image.colorspace_settings.name, bool(image.is_dirty))
    if cache is not None and key in cache:
        return cache[key]
    try:
        w, h, ch = int(image.size[0]), int(image.size[1]), int(image.channels)
        if w <= 0 or h <= 0 or ch not in (1, 2, 3, 4):
            return None
        buf = np.empty(w * h * ch, np.float32)
        image.pixels.foreach_get(buf)
    except (RuntimeError, ReferenceError, ValueError) as e:
        report.warn(f"{where}: image '{image.name}' could not be read ({e})")
        return None
    buf = buf.reshape(h, w, ch)
    rgb = np.repeat(buf[..., :1], 3, axis=2) if ch < 3 else buf[..., :3]
    space = image.colorspace_settings.name
    if not image.is_float and space not in _LINEAR_SPACES:
        if space != "sRGB":
            report.warn(f"{where}: image '{image.name}' is in colour space '{space}'; read as "
                        "sRGB")
        rgb = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
    elif image.is_float and space not in _LINEAR_SPACES:
        report.warn(f"{where}: float image '{image.name}' is in colour space '{space}'; read as "
                    "linear Rec.709")
    rgb = downsample(np.ascontiguousarray(rgb, np.float32), where, report)
    if cache is not None:
        cache[key] = rgb
    return rgb


def downsample(rgb, where, report):
    """Box-filter a map wider than MAX_MAP_WIDTH by an integer factor (NaN-safe: bad texels
    stay the core's to clean and warn about)."""
    h, w = rgb.shape[:2]
    f = -(-w // MAX_MAP_WIDTH)
    if f <= 1:
        return rgb
    report.warn(f"{where}: the {w}x{h} world map is reduced {f}x to {w // f}x{max(1, h // f)} "
                "texels")
    hh, ww = max(1, h // f), w // f
    fy = f if h >= f else 1
    out = rgb[:hh * fy, :ww * f].reshape(hh, fy, ww, f, 3).mean(axis=(1, 3))
    return np.ascontiguousarray(out, np.float32)


def _background_input(world, node, report):
    """(colour socket source or None, constant colour, strength) of a Background node."""
    color_in, strength_in = node.inputs["Color"], node.inputs["Strength"]
    if strength_in.is_linked:
        report.warn(f"World '{world.name}': a linked Background Strength is not supported; "
                    "its own value is used")
    s = float(strength_in.default_value)
    src = color_in.links[0].from_node if color_in.is_linked else None
    while src is not None and src.type == "REROUTE":
        src = src.inputs[0].links[0].from_node if src.inputs[0].is_linked else None
    return src, _socket_color(color_in), s


def export_world(world, report, cache=None, integrator="pt"):
    """The scene's world dict; `cache` (optional, kept between viewport exports) holds map
    pixels by image; `integrator` (kept for the callers) no longer changes the ray visibility
    exported: the core hands it to pt where the integrator does not render it (_visibility).
    The Volume output: export/volume.py."""
    out = _export_world_surface(world, report, cache, integrator)
    return attach_world_volume(world, out, report)


def _export_world_surface(world, report, cache=None, integrator="pt"):
    if world is None:
        return {"color": [0.0, 0.0, 0.0]}
    tree = world.node_tree
    if bpy.app.version < (5, 0, 0) and not world.use_nodes:  # always nodes from 5.0
        tree = None
    if tree is None:
        return {"color": [float(c) for c in world.color[:3]]}
    output = next((n for n in tree.nodes if n.type == "OUTPUT_WORLD" and n.is_active_output), None)
    if output is None:
        output = next((n for n in tree.nodes if n.type == "OUTPUT_WORLD"), None)
    surface = output.inputs["Surface"] if output else None
    if surface is None or not surface.is_linked:
        return {"color": [0.0, 0.0, 0.0]}
    node = surface.links[0].from_node
    if node.type != "BACKGROUND":
        report.warn(f"World '{world.name}': node '{node.name}' ({node.type}) is not supported; "
                    "the world renders black")
        return {"color": [0.0, 0.0, 0.0]}
    out = {"color": [0.0, 0.0, 0.0]}
    out.update(_visibility(world, report, integrator))
    _settings(world, report)
    if bake_node_world(world, node, out, report):   # procedural worlds (world_nodes.py)
        return out
    src, color, s = _background_input(world, node, report)
    if src is None:
        out["color"] = [c * s for c in color]
        return out
    where = f"World '{world.name}'"
    if src.type == "TEX_SKY":  # addon/export/sky.py
        return sky_world(src, out, color, s, vector_matrix(src, where, report), where, report)
    if src.type != "TEX_ENVIRONMENT":
        report.warn(f"{where}: '{src.name}' ({src.type}) feeding the Background Color is not "
                    "supported; the socket's own colour is used")
        out["color"] = [c * s for c in color]
        return out
    image = src.image
    rgb = read_map(image, where, report, cache) if image is not None else None
    if rgb is None:
        name = image.name if image is not None else "none"
        path = (image.filepath or "no file") if image is not None else "no image"
        report.warn(f"{where}: the Environment Texture's image '{name}' is missing or "
                    f"unreadable ({path}); the world renders black")
        return out
    projection = _PROJECTIONS.get(src.projection)
    if projection is None:
        report.warn(f"{where}: Environment Texture projection {src.projection} is not "
                    "supported; rendered as equirectangular")
        projection = "equirectangular"
    if src.interpolation not in ("Linear", "Smart", "Cubic"):
        report.warn(f"{where}: Environment Texture interpolation {src.interpolation} renders "
                    "as Linear")
    out.update({"map": rgb, "map_name": image.name, "strength": [s, s, s],
                "projection": projection,
                "to_map": vector_matrix(src, where, report).tolist()})
    return out


def _visibility(world, report, integrator="pt"):
    """Cycles' world ray visibility (World > Settings > Ray Visibility): camera for every
    integrator; diffuse, glossy, transmission (integrator/pt.h pt_world_sees) and volume
    scatter (a medium vertex's phase ray and next event, integrator/pt_volume.h) rendered by
    pt: bdpt, lvc, cis and lt hand a scene with any of them hidden over to pt, with the core's
    warning naming it (allocation.cpp world_rays_reason; volume scatter only beside media), and
    auto renders it with pt."""
    vis = getattr(world, "cycles_visibility", None)
    if vis is None:
        return {}
    out = {"visible_camera": bool(getattr(vis, "camera", True))}
    off = [ray for ray in ("diffuse", "glossy", "transmission", "scatter")
           if not getattr(vis, ray, True)]
    out.update({"visible_volume_scatter" if ray == "scatter" else f"visible_{ray}": False
                for ray in off})
    return out


def mixed_lobe_warning(world, world_out, materials, report):
    """Where the world is hidden from diffuse or glossy rays but not both, the materials that
    have lobes of both kinds (Principled, mixes) see it in every reflection (integrator/pt.h
    pt_world_sees): named, once, when the scene has such a material."""
    d, g = (world_out.get(f"visible_{ray}", True) for ray in ("diffuse", "glossy"))
    if d == g or world is None:
        return
    mixed = [m.get("name", "?") for m in materials if m.get("type") in ("principled", "mix")]
    if mixed:
        report.warn(f"World '{world.name}': the world is hidden from "
                    f"{'glossy' if d else 'diffuse'} rays only; Principled and mixed materials "
                    f"({', '.join(mixed[:3])}{', ...' if len(mixed) > 3 else ''}) see it in "
                    "every reflection")


def _settings(world, report):
    """Cycles' world settings that change the image and that Lantern does not honour."""
    cw = getattr(world, "cycles", None)
    bounces = getattr(cw, "max_bounces", 1024)
    if bounces < 1024:
        report.warn(f"World '{world.name}': Max Bounces {bounces} is not honoured (the world "
                    "lights every bounce)")
