"""Import a Mitsuba 3 XML scene into a `lantern.Scene` (the subset used in /work/shared/scenes).

    scene = load_mitsuba("scene.xml", width=128, height=128)
    scene.metadata["max_depth"]   # the integrator's max_depth (Mitsuba counts like Lantern)

Supported: `<default>` parameters (`$name`), `<ref>`, shapes obj / ply / rectangle / cube /
sphere / disk with `to_world` (matrix, translate, rotate, scale, lookat), BSDFs diffuse and
twosided (conductors, dielectrics and plastics fall back to a diffuse with a warning), area
emitters (-> material emission), constant emitters (-> world colour), point emitters, the
perspective sensor (fov, fov_axis, focal_length, clip planes), hdrfilm size and rfilter, and
the integrator's max_depth. Everything else is skipped with a warning in
`scene.metadata["warnings"]` (also sent to the `lantern.mitsuba` logger).

Conventions (docs/mitsuba_import.md): Mitsuba is +Y up and its camera looks down local +Z with
local +X pointing to the image's *left*; Lantern is +Z up (Blender) and its camera looks down
local -Z with +X to the right. World points map (x, y, z) -> (x, -z, y) (a rotation, so nothing
is mirrored); the camera's Lantern axes are (-X, +Y, -Z) of Mitsuba's camera frame.
"""

import logging
import math
import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from .scene import Scene

log = logging.getLogger("lantern.mitsuba")

# Mitsuba world (Y up) -> Lantern / Blender world (Z up): (x, y, z) -> (x, -z, y).
Y_UP_TO_Z_UP = np.array([[1.0, 0.0, 0.0, 0.0],
                         [0.0, 0.0, -1.0, 0.0],
                         [0.0, 1.0, 0.0, 0.0],
                         [0.0, 0.0, 0.0, 1.0]])

UNSUPPORTED_BSDFS = ("conductor", "roughconductor", "dielectric", "roughdielectric",
                     "thindielectric", "plastic", "roughplastic", "principled",
                     "principledthin", "hair", "pplastic", "measured", "blendbsdf")
WRAPPER_BSDFS = ("twosided", "mask", "bumpmap", "normalmap")

# Standard deviation (pixels) of one axis of Blackman-Harris over [-w, w], per unit w.
_BH_STD_PER_WIDTH = 2.0 * 0.13850731377878253


class MitsubaError(ValueError):
    """A Mitsuba file this importer cannot read."""


# ---------------------------------------------------------------------------------------------
# Small parsing helpers
# ---------------------------------------------------------------------------------------------

def _floats(text, what="value"):
    parts = [p for p in re.split(r"[,\s]+", str(text).strip()) if p]
    try:
        return [float(p) for p in parts]
    except ValueError:
        raise MitsubaError(f"{what}: expected numbers, got {text!r}") from None


def _vec3(text, what):
    v = _floats(text, what)
    if len(v) == 1:
        v = v * 3
    if len(v) != 3:
        raise MitsubaError(f"{what}: expected 3 numbers, got {text!r}")
    return v


def _xyz(el, default=0.0):
    """A point/vector element or transform op: `value="x y z"` or x=, y=, z= attributes."""
    if el.get("value") is not None:
        return _vec3(el.get("value"), el.tag)
    return [float(el.get(k, default)) for k in ("x", "y", "z")]


def _bool_text(text):
    t = str(text).strip().lower()
    if t in ("true", "1", "yes"):
        return True
    if t in ("false", "0", "no"):
        return False
    raise MitsubaError(f"expected a boolean, got {text!r}")


# ---------------------------------------------------------------------------------------------
# Transforms (row-major 4x4, column vectors; each op is applied after the previous ones)
# ---------------------------------------------------------------------------------------------

def translate(v):
    m = np.eye(4)
    m[:3, 3] = v
    return m


def scale(v):
    return np.diag([v[0], v[1], v[2], 1.0])


def rotate(axis, angle_deg):
    """Rotation by `angle_deg` about `axis` (right-handed, as Mitsuba's Transform::rotate)."""
    a = np.asarray(axis, dtype=np.float64)
    n = np.linalg.norm(a)
    if not n > 0:
        raise MitsubaError("rotate: the axis is zero")
    x, y, z = a / n
    t = math.radians(angle_deg)
    c, s = math.cos(t), math.sin(t)
    m = np.eye(4)
    m[:3, :3] = [[x * x * (1 - c) + c, x * y * (1 - c) - z * s, x * z * (1 - c) + y * s],
                 [x * y * (1 - c) + z * s, y * y * (1 - c) + c, y * z * (1 - c) - x * s],
                 [x * z * (1 - c) - y * s, y * z * (1 - c) + x * s, z * z * (1 - c) + c]]
    return m


def mitsuba_look_at(origin, target, up):
    """Mitsuba's Transform::look_at: columns (left, up', dir, origin), dir = target - origin."""
    o = np.asarray(origin, dtype=np.float64)
    d = np.asarray(target, dtype=np.float64) - o
    if not np.linalg.norm(d) > 0:
        raise MitsubaError("lookat: origin and target coincide")
    d /= np.linalg.norm(d)
    left = np.cross(np.asarray(up, dtype=np.float64), d)
    if np.linalg.norm(left) < 1e-12:
        raise MitsubaError("lookat: 'up' is parallel to the viewing direction")
    left /= np.linalg.norm(left)
    new_up = np.cross(d, left)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = left, new_up, d, o
    return m


def parse_transform(el):
    """The 4x4 matrix of a `<transform>` element."""
    m = np.eye(4)
    for op in el:
        tag = op.tag
        if tag == "matrix":
            vals = _floats(op.get("value", ""), "matrix")
            if len(vals) == 16:
                t = np.array(vals).reshape(4, 4)
            elif len(vals) == 9:
                t = np.eye(4)
                t[:3, :3] = np.array(vals).reshape(3, 3)
            else:
                raise MitsubaError(f"matrix: expected 16 (or 9) values, got {len(vals)}")
        elif tag == "translate":
            t = translate(_xyz(op, 0.0))
        elif tag == "scale":
            if op.get("value") is not None:
                t = scale(_vec3(op.get("value"), "scale"))
            else:
                t = scale([float(op.get(k, 1.0)) for k in ("x", "y", "z")])
        elif tag == "rotate":
            if op.get("value") is not None:
                axis = _vec3(op.get("value"), "rotate")
            else:
                axis = [float(op.get(k, 0.0)) for k in ("x", "y", "z")]
            t = rotate(axis, float(op.get("angle", 0.0)))
        elif tag == "lookat":
            origin = _vec3(op.get("origin", "0 0 0"), "lookat origin")
            target = _vec3(op.get("target", "0 0 1"), "lookat target")
            up = op.get("up")
            if up is None:
                d = np.asarray(target) - np.asarray(origin)
                up = [0.0, 1.0, 0.0] if abs(d[1]) < 0.999 * np.linalg.norm(d) else [1.0, 0.0, 0.0]
            else:
                up = _vec3(up, "lookat up")
            t = mitsuba_look_at(origin, target, up)
        else:
            raise MitsubaError(f"transform: unknown operation <{tag}>")
        m = t @ m
    return m


# ---------------------------------------------------------------------------------------------
# Mesh readers
# ---------------------------------------------------------------------------------------------

def _triangulate(faces):
    """Fan-triangulate a list of polygons (lists of corner keys)."""
    tris = []
    for f in faces:
        for k in range(1, len(f) - 1):
            tris.append((f[0], f[k], f[k + 1]))
    return tris


def read_obj(path):
    """Wavefront OBJ (v, vt, vn, f; polygons fan-triangulated, negative indices allowed).
    Returns (positions, indices, normals | None, uvs | None) with vertices split per distinct
    (v, vt, vn) corner."""
    vs, vts, vns, faces = [], [], [], []
    with open(path, "r", encoding="utf-8", errors="replace") as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            key = parts[0]
            if key == "v":
                vs.append([float(x) for x in parts[1:4]])
            elif key == "vt":
                uv = [float(x) for x in parts[1:3]]
                vts.append(uv + [0.0] * (2 - len(uv)))
            elif key == "vn":
                vns.append([float(x) for x in parts[1:4]])
            elif key == "f":
                corners = []
                for c in parts[1:]:
                    idx = c.split("/")
                    ids = []
                    for j, lst in enumerate((vs, vts, vns)):
                        if j < len(idx) and idx[j]:
                            i = int(idx[j])
                            ids.append(i - 1 if i > 0 else len(lst) + i)
                        else:
                            ids.append(-1)
                    corners.append(tuple(ids))
                faces.append(corners)
    tris = _triangulate(faces)
    lookup, order = {}, []
    indices = np.empty((len(tris), 3), dtype=np.uint32)
    for t, tri in enumerate(tris):
        for k, corner in enumerate(tri):
            j = lookup.get(corner)
            if j is None:
                j = lookup[corner] = len(order)
                order.append(corner)
            indices[t, k] = j
    order = np.array(order, dtype=np.int64).reshape(-1, 3)
    pos = np.asarray(vs, dtype=np.float64).reshape(-1, 3)[order[:, 0]]
    uvs = normals = None
    if vts and (order[:, 1] >= 0).all():
        uvs = np.asarray(vts, dtype=np.float64)[order[:, 1]]
    if vns and (order[:, 2] >= 0).all():
        normals = np.asarray(vns, dtype=np.float64)[order[:, 2]]
    return pos, indices, normals, uvs


_PLY_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2",
              "int16": "i2", "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4",
              "uint": "u4", "uint32": "u4", "float": "f4", "float32": "f4", "double": "f8",
              "float64": "f8"}


def read_ply(path):
    """PLY, ASCII or binary (little/big endian): vertex x y z [nx ny nz] [u v | s t |
    texture_u texture_v], face vertex_indices (polygons fan-triangulated).
    Returns (positions, indices, normals | None, uvs | None)."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise MitsubaError(f"{path}: not a PLY file")
    body_start = data.index(b"\n", end) + 1
    header = data[:end].decode("ascii", "replace").splitlines()
    fmt, elements = None, []
    for line in header:
        p = line.split()
        if not p:
            continue
        if p[0] == "format":
            fmt = p[1]
        elif p[0] == "element":
            elements.append({"name": p[1], "count": int(p[2]), "props": []})
        elif p[0] == "property":
            if p[1] == "list":
                elements[-1]["props"].append((p[4], "list", _PLY_TYPES[p[2]], _PLY_TYPES[p[3]]))
            else:
                elements[-1]["props"].append((p[2], "scalar", _PLY_TYPES[p[1]], None))
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise MitsubaError(f"{path}: unknown PLY format {fmt!r}")
    vert, faces = None, None
    if fmt == "ascii":
        tokens = data[body_start:].split()
        pos = 0
        for el in elements:
            rows = []
            for _ in range(el["count"]):
                row = {}
                for name, kind, t1, t2 in el["props"]:
                    if kind == "list":
                        n = int(tokens[pos]); pos += 1
                        row[name] = [float(x) for x in tokens[pos:pos + n]]; pos += n
                    else:
                        row[name] = float(tokens[pos]); pos += 1
                rows.append(row)
            if el["name"] == "vertex":
                vert = {name: np.array([r[name] for r in rows]) for name, *_ in el["props"]}
            elif el["name"] == "face":
                key = next(n for n, kind, *_ in el["props"] if kind == "list")
                faces = [[int(i) for i in r[key]] for r in rows]
    else:
        bo = "<" if fmt == "binary_little_endian" else ">"
        pos = body_start
        for el in elements:
            if all(kind == "scalar" for _, kind, *_ in el["props"]):
                dt = np.dtype([(name, bo + t1) for name, _, t1, _ in el["props"]])
                arr = np.frombuffer(data, dtype=dt, count=el["count"], offset=pos)
                pos += dt.itemsize * el["count"]
                if el["name"] == "vertex":
                    vert = {name: arr[name].astype(np.float64) for name, *_ in el["props"]}
                continue
            # elements with lists: fast path for a lone triangle list, else row by row
            props = el["props"]
            if (len(props) == 1 and el["count"] > 0):
                _, _, tc, ti = props[0]
                cdt, idt = np.dtype(bo + tc), np.dtype(bo + ti)
                n0 = int(np.frombuffer(data, dtype=cdt, count=1, offset=pos)[0])
                rec = np.dtype([("n", cdt), ("i", idt, (n0,))])
                if pos + rec.itemsize * el["count"] <= len(data):
                    arr = np.frombuffer(data, dtype=rec, count=el["count"], offset=pos)
                    if (arr["n"] == n0).all():
                        pos += rec.itemsize * el["count"]
                        if el["name"] == "face":
                            faces = arr["i"].astype(np.int64)
                        continue
            rows = []
            for _ in range(el["count"]):
                row = {}
                for name, kind, t1, t2 in props:
                    if kind == "list":
                        cdt, idt = np.dtype(bo + t1), np.dtype(bo + t2)
                        n = int(np.frombuffer(data, dtype=cdt, count=1, offset=pos)[0])
                        pos += cdt.itemsize
                        row[name] = np.frombuffer(data, dtype=idt, count=n, offset=pos).tolist()
                        pos += idt.itemsize * n
                    else:
                        dt = np.dtype(bo + t1)
                        row[name] = float(np.frombuffer(data, dtype=dt, count=1, offset=pos)[0])
                        pos += dt.itemsize
                rows.append(row)
            if el["name"] == "face":
                key = next(n for n, kind, *_ in props if kind == "list")
                faces = [r[key] for r in rows]
    if vert is None or faces is None:
        raise MitsubaError(f"{path}: PLY without vertex or face elements")
    positions = np.stack([vert["x"], vert["y"], vert["z"]], axis=1)
    normals = uvs = None
    if all(k in vert for k in ("nx", "ny", "nz")):
        normals = np.stack([vert["nx"], vert["ny"], vert["nz"]], axis=1)
    for u, v in (("u", "v"), ("s", "t"), ("texture_u", "texture_v")):
        if u in vert and v in vert:
            uvs = np.stack([vert[u], vert[v]], axis=1)
            break
    if isinstance(faces, np.ndarray):
        if faces.shape[1] == 3:
            indices = faces
        else:
            indices = np.array(_triangulate(faces.tolist()), dtype=np.int64).reshape(-1, 3)
    else:
        indices = np.array(_triangulate(faces), dtype=np.int64).reshape(-1, 3)
    return positions, indices.astype(np.uint32), normals, uvs


# ---------------------------------------------------------------------------------------------
# Built-in shapes, in Mitsuba's object space
# ---------------------------------------------------------------------------------------------

def rectangle_mesh():
    """[-1, 1]^2 in the z=0 plane, normal +Z."""
    p = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], dtype=np.float64)
    n = np.tile([0.0, 0.0, 1.0], (4, 1))
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=np.float64)
    return p, np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32), n, uv


def cube_mesh():
    """[-1, 1]^3, 24 vertices (flat faces), outward normals, counter-clockwise from outside."""
    pos, nrm, uv, idx = [], [], [], []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            n = np.zeros(3)
            n[axis] = sign
            u_ax, v_ax = [(1, 2), (2, 0), (0, 1)][axis]
            base = len(pos)
            for (a, b) in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = np.zeros(3)
                p[axis] = sign
                p[u_ax], p[v_ax] = a, b
                pos.append(p)
                nrm.append(n)
                uv.append([(a + 1) / 2, (b + 1) / 2])
            tri = [[0, 1, 2], [0, 2, 3]] if sign > 0 else [[0, 2, 1], [0, 3, 2]]
            idx += [[base + t[0], base + t[1], base + t[2]] for t in tri]
    return (np.array(pos), np.array(idx, dtype=np.uint32), np.array(nrm), np.array(uv))


def sphere_mesh(center=(0.0, 0.0, 0.0), radius=1.0, rings=64, segments=128):
    """UV sphere with exact normals, poles on +-Z (Mitsuba's sphere parametrisation axis)."""
    theta = np.linspace(0.0, math.pi, rings + 1)
    phi = np.linspace(0.0, 2.0 * math.pi, segments + 1)
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    n = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], axis=-1)
    n = n.reshape(-1, 3)
    uv = np.stack([ph / (2 * math.pi), th / math.pi], axis=-1).reshape(-1, 2)
    idx = []
    w = segments + 1
    for i in range(rings):
        for j in range(segments):
            a, b, c, d = i * w + j, i * w + j + 1, (i + 1) * w + j + 1, (i + 1) * w + j
            if i > 0:
                idx.append([a, d, b])
            if i < rings - 1:
                idx.append([b, d, c])
    pos = np.asarray(center, dtype=np.float64) + radius * n
    return pos, np.array(idx, dtype=np.uint32), n, uv


def disk_mesh(segments=128):
    """Unit disk in the z=0 plane, normal +Z."""
    ang = np.linspace(0.0, 2 * math.pi, segments, endpoint=False)
    p = np.concatenate([[[0.0, 0.0, 0.0]], np.stack([np.cos(ang), np.sin(ang),
                                                     np.zeros_like(ang)], axis=1)])
    idx = [[0, 1 + k, 1 + (k + 1) % segments] for k in range(segments)]
    n = np.tile([0.0, 0.0, 1.0], (len(p), 1))
    return p, np.array(idx, dtype=np.uint32), n, (p[:, :2] + 1) / 2


def transform_mesh(m, positions, normals):
    """Apply a 4x4 transform to points and (inverse-transpose) normals; a mirroring transform
    flips the winding, which the caller handles."""
    p = positions @ m[:3, :3].T + m[:3, 3]
    n = None
    if normals is not None:
        nm = np.linalg.inv(m[:3, :3]).T
        n = normals @ nm.T
        ln = np.linalg.norm(n, axis=1, keepdims=True)
        n = n / np.where(ln > 0, ln, 1.0)
    return p, n


# ---------------------------------------------------------------------------------------------
# Camera
# ---------------------------------------------------------------------------------------------

def fov_tangents(fov_deg, fov_axis, width, height):
    """(tan of half the horizontal angle, tan of half the vertical angle) for Mitsuba's fov
    along `fov_axis` (x, y, diagonal, smaller, larger) on a width x height film."""
    if not 0.0 < fov_deg < 180.0:
        raise MitsubaError(f"fov must be in (0, 180) degrees, got {fov_deg}")
    t = math.tan(math.radians(fov_deg) / 2.0)
    axis = fov_axis.lower()
    if axis == "smaller":
        axis = "x" if width <= height else "y"
    elif axis == "larger":
        axis = "x" if width >= height else "y"
    if axis == "x":
        return t, t * height / width
    if axis == "y":
        return t * width / height, t
    if axis == "diagonal":
        d = math.hypot(width, height)
        return t * width / d, t * height / d
    raise MitsubaError(f"unknown fov_axis {fov_axis!r}")


def camera_to_lantern(m):
    """Mitsuba camera-to-world (local +Z forward, +X to the image's left, +Y up) -> Lantern's
    rigid camera-to-world (local -Z forward, +X right, +Y up), both in Mitsuba world space.
    Scale is removed. Returns (matrix, mirrored) where `mirrored` says the Mitsuba matrix had a
    negative determinant (an image mirror Lantern's rigid camera cannot express)."""
    m = np.asarray(m, dtype=np.float64)
    a = m[:3, :3]
    mirrored = np.linalg.det(a) < 0
    # Gram-Schmidt on (forward, up), then right = forward x up (Lantern: right-handed)
    fwd = a[:, 2] / np.linalg.norm(a[:, 2])
    up = a[:, 1] - fwd * np.dot(a[:, 1], fwd)
    up /= np.linalg.norm(up)
    right = np.cross(fwd, up)
    out = np.eye(4)
    out[:3, 0], out[:3, 1], out[:3, 2], out[:3, 3] = right, up, -fwd, m[:3, 3]
    return out, bool(mirrored)


# ---------------------------------------------------------------------------------------------
# The loader
# ---------------------------------------------------------------------------------------------

class _Loader:
    def __init__(self, path, params):
        self.path = Path(path)
        self.dir = self.path.parent
        self.params = dict(params or {})
        self.warnings = []
        self.ids = {}
        self.scene = Scene()
        self.material_ids = {}       # (bsdf key, emission tuple) -> material id
        self.fallback_types = {}     # bsdf type -> count
        self.one_sided = True
        self.emitter_backs = []
        self.metadata = {"source": str(self.path), "max_depth": None, "integrator": None,
                         "spp": None, "rfilter": "box", "warnings": self.warnings}

    def warn(self, msg):
        if msg not in self.warnings:
            self.warnings.append(msg)
            log.warning(msg)

    # ---- parameters and properties ----

    def subst(self, root):
        """Collect `<default>`s (caller params win), then replace $name in every attribute."""
        for el in list(root):
            if el.tag == "default":
                self.params.setdefault(el.get("name"), el.get("value"))
        names = sorted(self.params, key=len, reverse=True)
        pattern = re.compile(r"\$(" + "|".join(re.escape(n) for n in names) + r")") \
            if names else None
        for el in root.iter():
            for k, v in el.attrib.items():
                if "$" in v and pattern is not None:
                    el.attrib[k] = pattern.sub(lambda mo: str(self.params[mo.group(1)]), v)
                if "$" in el.attrib[k]:
                    raise MitsubaError(f"<{el.tag}> {k}={v!r}: undefined parameter")

    def props(self, el):
        """Named properties of an element: {name: value}; nested objects are skipped."""
        out = {}
        for c in el:
            name = c.get("name")
            tag = c.tag
            if tag in ("float", "integer"):
                out[name] = float(c.get("value")) if tag == "float" else int(float(c.get("value")))
            elif tag == "boolean":
                out[name] = _bool_text(c.get("value"))
            elif tag == "string":
                out[name] = c.get("value")
            elif tag in ("rgb", "spectrum"):
                vals = _floats(c.get("value", "0"), f"<{tag} name={name!r}>")
                if tag == "spectrum" and len(vals) != 1:
                    self.warn(f"spectrum {name!r}: only a constant spectrum is read; "
                              f"using the mean of its values")
                    vals = [float(np.mean(vals[1::2])) if len(vals) % 2 == 0 else vals[0]]
                out[name] = vals * 3 if len(vals) == 1 else vals[:3]
            elif tag in ("point", "vector"):
                out[name] = _xyz(c)
            elif tag == "transform":
                out[name] = parse_transform(c)
        return out

    def _child_objects(self, el, tag):
        """Nested `<tag>` objects and `<ref>`s that resolve to one."""
        out = []
        for c in el:
            if c.tag == tag:
                out.append(c)
            elif c.tag == "ref":
                target = self.ids.get(c.get("id"))
                if target is None:
                    raise MitsubaError(f"<ref id={c.get('id')!r}>: no object with that id")
                if target.tag == tag:
                    out.append(target)
        return out

    # ---- BSDFs ----

    def bsdf_color(self, el, depth=0):
        """(base_color, description) of a BSDF element, with diffuse fallbacks."""
        btype = el.get("type")
        p = self.props(el)
        if btype in WRAPPER_BSDFS:
            inner = self._child_objects(el, "bsdf")
            if not inner:
                raise MitsubaError(f"bsdf {btype!r} without a nested bsdf")
            if btype != "twosided":
                self.warn(f"bsdf {btype!r}: ignored, using its nested bsdf")
            return self.bsdf_color(inner[0], depth + 1)
        if btype == "diffuse":
            return self.reflectance(el, p, "reflectance", 0.5)
        if btype in UNSUPPORTED_BSDFS:
            self.fallback_types[btype] = self.fallback_types.get(btype, 0) + 1
            if btype in ("plastic", "roughplastic", "pplastic"):
                return self.reflectance(el, p, "diffuse_reflectance", 0.5)
            if btype in ("conductor", "roughconductor"):
                return self.reflectance(el, p, "specular_reflectance", 0.8)
            if btype in ("principled", "principledthin"):
                return self.reflectance(el, p, "base_color", 0.5)
            return [0.8, 0.8, 0.8]
        self.warn(f"bsdf {btype!r} is not supported; using a grey diffuse (0.5)")
        return [0.5, 0.5, 0.5]

    def reflectance(self, el, p, name, default):
        if name in p and isinstance(p[name], list):
            c = [float(x) for x in p[name]]
        elif name in p:
            c = [float(p[name])] * 3
        else:
            tex = [t for t in self._child_objects(el, "texture") if t.get("name") == name]
            tex += [c for c in el if c.tag == "texture" and c.get("name") == name]
            if tex:
                tp = self.props(tex[0])
                if tex[0].get("type") == "checkerboard":
                    c0 = tp.get("color0", [0.4] * 3)
                    c1 = tp.get("color1", [0.2] * 3)
                    c = [(a + b) / 2 for a, b in zip(c0, c1)]
                else:
                    c = [0.5, 0.5, 0.5]
                self.warn(f"texture {tex[0].get('type')!r} for {name!r}: textures are not "
                          f"supported; using its mean colour {c}")
            else:
                c = [default] * 3
        if max(c) > 1.0 or min(c) < 0.0:
            self.warn(f"reflectance {c} outside [0, 1]: clamped")
            c = [min(max(x, 0.0), 1.0) for x in c]
        return c

    def material(self, bsdf_el, emission, name):
        key = (id(bsdf_el) if bsdf_el is not None else None, tuple(emission))
        mid = self.material_ids.get(key)
        if mid is None:
            base = self.bsdf_color(bsdf_el) if bsdf_el is not None else [0.5, 0.5, 0.5]
            mname = (bsdf_el.get("id") if bsdf_el is not None else None) or name
            if max(emission) > 0:
                mname = f"{mname}_emitter"
            mid = self.scene.add_material(mname, base_color=base, emission=emission)
            self.material_ids[key] = mid
        return mid

    # ---- shapes ----

    def shape(self, el, index):
        stype = el.get("type")
        p = self.props(el)
        name = el.get("id") or f"{stype}_{index}"
        m = p.get("to_world", np.eye(4))
        if stype in ("obj", "ply"):
            fname = p.get("filename")
            if fname is None:
                raise MitsubaError(f"shape {name!r}: missing filename")
            fpath = Path(fname) if os.path.isabs(fname) else self.dir / fname
            pos, idx, nrm, uv = (read_obj if stype == "obj" else read_ply)(fpath)
            if p.get("face_normals", False):
                nrm = None
        elif stype == "rectangle":
            pos, idx, nrm, uv = rectangle_mesh()
        elif stype == "cube":
            pos, idx, nrm, uv = cube_mesh()
        elif stype == "disk":
            pos, idx, nrm, uv = disk_mesh()
        elif stype == "sphere":
            pos, idx, nrm, uv = sphere_mesh(p.get("center", [0.0, 0.0, 0.0]),
                                            p.get("radius", 1.0))
        elif stype in ("shapegroup", "instance", "serialized", "cylinder"):
            self.warn(f"shape {stype!r} is not supported; skipped")
            return
        else:
            self.warn(f"shape {stype!r} is not supported; skipped")
            return
        pos, nrm = transform_mesh(Y_UP_TO_Z_UP @ m, np.asarray(pos, dtype=np.float64),
                                  None if nrm is None else np.asarray(nrm, dtype=np.float64))
        idx = np.asarray(idx, dtype=np.uint32)
        if np.linalg.det(m[:3, :3]) < 0:
            idx = idx[:, [0, 2, 1]]  # keep the geometric normal on the shading normal's side
        if p.get("flip_normals", False):
            idx = idx[:, [0, 2, 1]]
            if nrm is not None:
                nrm = -nrm
        bsdfs = self._child_objects(el, "bsdf")
        emission = [0.0, 0.0, 0.0]
        for em in self._child_objects(el, "emitter"):
            if em.get("type") == "area":
                emission = [float(x) for x in self.props(em).get("radiance", [1.0] * 3)]
            else:
                self.warn(f"emitter {em.get('type')!r} inside a shape is not supported")
        bsdf = bsdfs[0] if bsdfs else None
        mid = self.material(bsdf, emission, name)
        self.scene.add_mesh(pos, idx, material=mid, normals=nrm, uvs=uv, name=name)
        if max(emission) > 0 and self.one_sided and stype not in ("sphere", "cube"):
            # (closed shapes emit their back side inwards, where it is never seen)
            self.emitter_backs.append((name, pos, idx, nrm, uv, bsdf))

    def add_emitter_backs(self):
        """Mitsuba's area emitters emit from their front (the geometric normal's side) only;
        Lantern's mesh emission is two-sided. Give every emissive mesh a non-emissive copy of
        itself (the emitter's own BSDF) a hair behind it, facing the other way: it absorbs the
        back-side emission and shows the BSDF from behind, as Mitsuba does."""
        if not self.emitter_backs:
            return
        lo = np.min([m["positions"].min(axis=0) for m in self.scene.meshes], axis=0)
        hi = np.max([m["positions"].max(axis=0) for m in self.scene.meshes], axis=0)
        eps = 1e-4 * float(np.linalg.norm(hi - lo))
        for name, pos, idx, nrm, uv, bsdf in self.emitter_backs:
            tri = pos[idx.astype(np.int64)]
            fn = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
            vn = np.zeros_like(pos)
            for k in range(3):
                np.add.at(vn, idx[:, k].astype(np.int64), fn)
            ln = np.linalg.norm(vn, axis=1, keepdims=True)
            vn = vn / np.where(ln > 0, ln, 1.0)
            mid = self.material(bsdf, [0.0, 0.0, 0.0], name)
            self.scene.add_mesh(pos - eps * vn, idx[:, [0, 2, 1]], material=mid,
                                normals=None if nrm is None else -nrm, uvs=uv,
                                name=f"{name}_back")

    # ---- emitters, sensor, integrator ----

    def emitter(self, el):
        etype = el.get("type")
        p = self.props(el)
        if etype == "constant":
            self.scene.world["color"] = [float(x) for x in p.get("radiance", [1.0] * 3)]
        elif etype == "point":
            pos = p.get("position")
            if pos is None:
                pos = p.get("to_world", np.eye(4))[:3, 3].tolist()
            pos = (Y_UP_TO_Z_UP[:3, :3] @ np.asarray(pos, dtype=np.float64)).tolist()
            intensity = np.asarray(p.get("intensity", [1.0] * 3), dtype=np.float64)
            self.scene.add_light("point", position=pos, radius=0.0,
                                 power=(4.0 * math.pi * intensity).tolist(),
                                 soft_falloff=False, visible_camera=False)
        else:
            self.warn(f"emitter {etype!r} is not supported; skipped")

    def sensor(self, el, width, height):
        stype = el.get("type")
        p = self.props(el)
        film = next((c for c in el if c.tag == "film"), None)
        fp = self.props(film) if film is not None else {}
        if film is not None and film.get("type") not in ("hdrfilm", None):
            self.warn(f"film {film.get('type')!r}: read as hdrfilm")
        src_w = int(fp.get("width", 768))
        src_h = int(fp.get("height", 576))
        if any(k in fp for k in ("crop_width", "crop_height", "crop_offset_x", "crop_offset_y")):
            self.warn("film crop window is ignored")
        if width is None and height is None:
            width, height = src_w, src_h
        elif height is None:
            height = max(1, round(width * src_h / src_w))
        elif width is None:
            width = max(1, round(height * src_w / src_h))
        if abs(width / height - src_w / src_h) > 1e-3 * src_w / src_h:
            self.warn(f"resolution {width}x{height} changes the aspect ratio of the scene's "
                      f"{src_w}x{src_h} film")
        self.metadata["source_resolution"] = [src_w, src_h]
        self.scene.film["width"], self.scene.film["height"] = int(width), int(height)

        # pixel filter: Blackman-Harris with the same standard deviation
        rf = film.find("rfilter") if film is not None else None
        rtype = rf.get("type") if rf is not None else "gaussian"
        rp = self.props(rf) if rf is not None else {}
        if rtype == "tent":
            std = rp.get("radius", 1.0) / math.sqrt(6.0)
        elif rtype == "box":
            std = 1.0 / math.sqrt(12.0)
        elif rtype == "gaussian":
            std = rp.get("stddev", 0.5)
        else:
            std = None
            self.warn(f"rfilter {rtype!r}: Lantern has only Blackman-Harris; using its "
                      f"default width 1.5")
        self.metadata["rfilter"] = rtype
        fw = 1.5 if std is None else std / _BH_STD_PER_WIDTH
        # (in pixels of the output film: at a reduced resolution this is the filter Mitsuba
        # itself would use rendering at that resolution)
        self.scene.film["filter_width"] = float(fw)
        sampler = next((c for c in el if c.tag == "sampler"), None)
        if sampler is not None:
            self.metadata["spp"] = self.props(sampler).get("sample_count")

        if stype not in ("perspective", "thinlens"):
            self.warn(f"sensor {stype!r} is not supported; using a perspective camera")
        if stype == "thinlens":
            self.warn("thinlens: depth of field is ignored (pinhole camera)")
        if "focal_length" in p and "fov" not in p:
            f = float(re.sub(r"mm$", "", str(p["focal_length"]).strip()))
            fov = math.degrees(2.0 * math.atan(math.hypot(36.0, 24.0) / (2.0 * f)))
            axis = "diagonal"
        else:
            fov = float(p.get("fov", 0.0)) if "fov" in p else None
            axis = p.get("fov_axis", "x")
            if fov is None:
                fov = math.degrees(2.0 * math.atan(math.hypot(36.0, 24.0) / (2.0 * 50.0)))
                axis = "diagonal"
        if "principal_point_offset_x" in p or "principal_point_offset_y" in p:
            self.warn("principal point offsets are ignored")
        tx, ty = fov_tangents(fov, axis, width, height)
        cam, mirrored = camera_to_lantern(p.get("to_world", np.eye(4)))
        if mirrored:
            self.warn("sensor to_world mirrors the image (negative determinant); Lantern's "
                      "camera is rigid, so the import is the unmirrored image")
        self.scene.camera = {
            "type": "perspective",
            "to_world": (Y_UP_TO_Z_UP @ cam).tolist(),
            "screen": [-tx, tx, -ty, ty],
            "clip": [float(p.get("near_clip", 1e-2)), float(p.get("far_clip", 1e4))],
        }

    def integrator(self, el):
        p = self.props(el)
        itype = el.get("type")
        self.metadata["integrator"] = itype
        if itype not in ("path", "volpath", "volpathmis", "prb", "direct"):
            self.warn(f"integrator {itype!r}: read as a path tracer (max_depth only)")
        depth = p.get("max_depth", -1)
        if itype == "direct":
            depth = 2
        self.metadata["max_depth"] = None if depth is None or depth < 0 else int(depth)

    # ---- whole file ----

    def load(self, width, height):
        try:
            root = ET.parse(self.path).getroot()
        except ET.ParseError as e:
            raise MitsubaError(f"{self.path}: not valid XML ({e})") from None
        if root.tag != "scene":
            raise MitsubaError(f"{self.path}: the root element is <{root.tag}>, not <scene>")
        self.subst(root)
        for el in root.iter():
            if el.get("id") is not None and el.tag != "ref":
                self.ids[el.get("id")] = el
        sensor_seen = False
        shape_index = 0
        for el in root:
            tag = el.tag
            if tag in ("default", "bsdf", "texture", "ref"):
                continue
            if tag == "integrator":
                self.integrator(el)
            elif tag == "sensor":
                if sensor_seen:
                    self.warn("more than one sensor: using the first")
                    continue
                sensor_seen = True
                self.sensor(el, width, height)
            elif tag == "shape":
                self.shape(el, shape_index)
                shape_index += 1
            elif tag == "emitter":
                self.emitter(el)
            else:
                self.warn(f"<{tag}> is not supported; skipped")
        self.add_emitter_backs()
        if not sensor_seen:
            self.warn("no sensor: using Lantern's default camera")
        if self.fallback_types:
            kinds = ", ".join(f"{k} ({n})" for k, n in sorted(self.fallback_types.items()))
            self.warn(f"BSDFs not supported yet, imported as diffuse: {kinds}")
        self.scene.metadata = self.metadata
        return self.scene.validate()


def load_mitsuba(path, width=None, height=None, params=None, one_sided_emitters=True):
    """Read a Mitsuba 3 XML scene into a validated `lantern.Scene`.

    `width`/`height` override the film size (one alone keeps the aspect ratio); `params`
    overrides `<default>` values ({"spp": "16"}). The result carries `scene.metadata`:
    {"max_depth": int | None (Mitsuba's count, which Lantern shares; None = unlimited),
     "integrator", "spp", "rfilter", "source_resolution", "source", "warnings": [...]}.
    `metadata` is not written to `.lantern` files.

    `one_sided_emitters` backs each area emitter with a non-emissive copy of itself a hair
    behind it, so it emits from its front only as in Mitsuba (Lantern's mesh emission is
    two-sided; without this the Cornell box is ~12% too bright: the light's back lights the
    ceiling 2 cm above it)."""
    loader = _Loader(path, params)
    loader.one_sided = bool(one_sided_emitters)
    return loader.load(width, height)
