"""Blender lights -> Lantern lights, in Blender's own quantities (watts; the core converts)."""

import math

import numpy as np

from .node_light import light_factor
from .visibility import mesh_ray_visibility


def _color(light):
    c = np.array(light.color[:3], dtype=np.float64)
    if getattr(light, "use_temperature", False):
        c = c * np.array(light.temperature_color[:3], dtype=np.float64)
    energy = float(light.energy) * 2.0 ** float(getattr(light, "exposure", 0.0))
    return c * energy


def _rigid(m):
    """4x4 without scale: orthonormal axes (Gram-Schmidt), translation kept."""
    x = m[:3, 0] / max(np.linalg.norm(m[:3, 0]), 1e-30)
    y = m[:3, 1] - x * np.dot(m[:3, 1], x)
    y = y / max(np.linalg.norm(y), 1e-30)
    z = np.cross(x, y)
    if np.dot(z, m[:3, 2]) < 0:
        z = -z
    r = np.eye(4)
    r[:3, 0], r[:3, 1], r[:3, 2], r[:3, 3] = x, y, z, m[:3, 3]
    return r.tolist()


def export_light(obj, matrix_world, report):
    """The light's scene dict (None: not rendered), with its own ray visibility's fields that
    are off (Diffuse, Glossy, Transmission, Volume Scatter: export/visibility.py) and its Cast
    Shadow when off (pt: integrator/pt_ray_visibility.h; the others: bidir_ray_visibility.h,
    bidir_linking.h, lt_ray_visibility.h, lt_linking.h, but what allocation.cpp
    bidir_visibility_reason hands to pt)."""
    out = _export_light(obj, matrix_world, report)
    if out is not None:
        out.update(mesh_ray_visibility(obj))
        # the light's Cast Shadow (Cycles reads the light's use_shadow, not the object's
        # visible_shadow, which its panel hides on lights); only when off, so that scenes with
        # shadow-casting lamps export as before (pt: integrator/pt_ray_visibility.h)
        if not getattr(obj.data, "use_shadow", True):
            out["cast_shadow"] = False
    return out


def _export_light(obj, matrix_world, report):
    light = obj.data
    m = np.array(matrix_world, dtype=np.float64)
    power = _color(light)
    factor = light_factor(obj, matrix_world, report)   # the light's node tree (node_light.py)
    if factor is not None:
        power = power * np.array(factor, dtype=np.float64)
    visible = bool(getattr(obj, "visible_camera", False))
    normalize = bool(getattr(light, "normalize", True))
    if light.type in {"POINT", "SPOT"}:
        radius = float(light.shadow_soft_size)
        if not normalize and radius > 0:
            power = power * math.pi * radius * radius
        out = {"type": light.type.lower(), "name": obj.name, "position": m[:3, 3].tolist(),
               "radius": radius,
               "power": power.tolist(), "to_world": _rigid(m), "visible_camera": visible,
               # off: a sphere light, which light paths (bdpt, lvc, cis, lt) can start on; on
               # (Blender's default): a disk facing each receiver, whose light paths (bdpt,
               # lvc, cis) leave its centre; camera-side only in scenes with media, lt refuses
               "soft_falloff": bool(getattr(light, "use_soft_falloff", True))}
        if light.type == "SPOT":
            out["spot_size"] = float(light.spot_size)
            out["spot_blend"] = float(light.spot_blend)
        return out
    if light.type == "AREA":
        sx, sy = float(np.linalg.norm(m[:3, 0])), float(np.linalg.norm(m[:3, 1]))
        shape = light.shape
        w = float(light.size) * sx
        h = float(light.size if shape in {"SQUARE", "DISK"} else light.size_y) * sy
        if shape in {"SQUARE", "RECTANGLE"}:
            shape_out, area = "rectangle", w * h
        else:
            shape_out, area = "ellipse", math.pi * w * h / 4.0
        if not normalize:
            power = power * area
        if area <= 0:
            report.warn(f"Light '{obj.name}': area light of zero size skipped")
            return None
        if float(getattr(light, "spread", math.pi)) < math.pi - 1e-4:
            report.warn(f"Light '{obj.name}': area light spread is not supported yet (uses 180°)")
        return {"type": "area", "name": obj.name, "to_world": _rigid(m), "shape": shape_out,
                "size": [w, h],
                "power": power.tolist(), "visible_camera": visible}
    if light.type == "SUN":
        d = -m[:3, 2]
        d = d / max(np.linalg.norm(d), 1e-30)
        return {"type": "sun", "name": obj.name, "direction": d.tolist(),
                "angle": float(light.angle),
                "strength": power.tolist()}
    report.warn(f"Light '{obj.name}': type {light.type} is not supported")
    return None
