"""Mitsuba XML values, transforms, mesh files (OBJ, PLY), primitive shapes and the camera window:
the parts of the importer that turn Mitsuba's definitions into numbers and arrays."""

import math
import re

import numpy as np

from .common import MitsubaError

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
