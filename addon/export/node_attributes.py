"""Per-vertex attribute channels that node-graph programs read (kOpInput attribute mode):
Generated and Object coordinates, the object-space normal, colour attributes and generic mesh
attributes, and per-object values (Object Info location, random, colour). Only the channels
some compiled material asked for are exported, 3 floats per corner vertex each."""

import zlib

import numpy as np

LOCAL = ("generated", "object", "object_normal")          # from the mesh alone
INSTANCE = ("object_location", "object_random", "object_color", "object_normal_x",
            "object_normal_y", "object_normal_z")   # the last three: the normal matrix's rows
# Modifiers that only move vertices: Blender leaves them out of the undeformed coordinates
# (CD_ORCO) that Generated reads, so a mesh whose stack has only these reads its original
# vertices where the depsgraph computed no ORCO (a viewport depsgraph without a 3D view asking
# for it: a background export)
DEFORM_ONLY = frozenset((
    "ARMATURE", "CAST", "CLOTH", "CORRECTIVE_SMOOTH", "CURVE", "DISPLACE", "HOOK",
    "LAPLACIANDEFORM", "LAPLACIANSMOOTH", "LATTICE", "MESH_CACHE", "MESH_DEFORM",
    "SHRINKWRAP", "SIMPLE_DEFORM", "SMOOTH", "SOFT_BODY", "SURFACE_DEFORM", "WARP", "WAVE"))


def _undeformed(obj, mesh, report=None):
    """The vertices Generated reads, (V, 3) float32: Blender's undeformed coordinates
    (MeshVertex.undeformed_co: the vertices before deforming modifiers and shape keys, where
    the evaluated mesh carries them, as it does in a render depsgraph), as Cycles reads them;
    without them, the original mesh's vertices where the stack only deforms (the same vertices,
    found the same way), else the evaluated ones (Cycles' own fallback, with a warning where
    the stack deforms)."""
    nv = len(mesh.vertices)
    co, und = np.empty(nv * 3, np.float32), np.empty(nv * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    co = co.reshape(nv, 3)
    try:
        mesh.vertices.foreach_get("undeformed_co", und)
    except (AttributeError, RuntimeError, TypeError):
        return co
    und = und.reshape(nv, 3)
    if not np.array_equal(und, co):
        return und   # the depsgraph's own undeformed coordinates
    orig = getattr(obj, "original", None)
    data = getattr(orig, "data", None)
    if getattr(orig, "type", None) != "MESH" or data is None or \
            data == getattr(obj, "data", None):
        return co
    mods = [m for m in getattr(orig, "modifiers", ()) if m.show_render or m.show_viewport]
    if any(m.type not in DEFORM_ONLY for m in mods) or len(data.vertices) != nv:
        if report is not None and any(m.type in DEFORM_ONLY for m in mods):
            report.warn(f"Object '{obj.name}': Generated coordinates follow the deformed mesh "
                        "(this depsgraph has no undeformed coordinates for a modifier stack "
                        "that deforms and builds; a final render has them)")
        return co
    base = np.empty(nv * 3, np.float32)
    data.vertices.foreach_get("co", base)
    return base.reshape(nv, 3)


def _generated(mesh, pos):
    """Generated coordinates: the (undeformed) position in the mesh's texture space mapped to
    [0, 1]^3. Blender's own texture space where the mesh has one (auto: the bounding box, each
    half extent at least 1e-5 and an empty one 1, as Blender makes it), else the bounding box."""
    try:
        loc = np.array(mesh.texspace_location[:3], np.float64)
        half = np.array(mesh.texspace_size[:3], np.float64)
    except (AttributeError, TypeError):
        lo, hi = pos.min(axis=0).astype(np.float64), pos.max(axis=0).astype(np.float64)
        loc, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
        half = np.where(half == 0.0, 1.0, np.maximum(half, 1e-5))
    half = np.where(np.isfinite(half) & (np.abs(half) > 0.0), half, 1.0)
    gen = (pos.astype(np.float64) - (loc - half)) / (2.0 * half)
    return np.nan_to_num(gen, nan=0.5, posinf=0.5, neginf=0.5).astype(np.float32)


class AttributeTable:
    def __init__(self, report):
        self.report = report
        self.names = []

    def channel(self, name):
        if name not in self.names:
            self.names.append(name)
        return self.names.index(name)

    # ---- per mesh (instance independent; while the evaluated mesh is alive) ----
    def local(self, obj, mesh, arrays, corner_vert):
        out = {}
        if not self.names:
            return out
        pos = arrays["positions"]
        for name in self.names:
            if name == "generated":
                out[name] = _generated(mesh, _undeformed(obj, mesh, self.report)[corner_vert])
            elif name == "object":
                out[name] = pos.astype(np.float32)
            elif name == "object_normal":
                out[name] = arrays["normals"].astype(np.float32)
            elif name.startswith("color:") or name.startswith("attr:"):
                v = self._mesh_attribute(obj, mesh, name, corner_vert)
                if v is not None:
                    out[name] = v
        return out

    def _mesh_attribute(self, obj, mesh, name, corner_vert):
        kind, key = name.split(":", 1)
        nl = len(corner_vert)
        if kind == "color":
            attrs = mesh.color_attributes
            attr = attrs.get(key) if key else None
            if attr is None and not key:
                idx = getattr(attrs, "render_color_index", -1)
                attr = attrs[idx] if 0 <= idx < len(attrs) else attrs.active_color
        else:
            attr = mesh.attributes.get(key)
        if attr is None:
            self.report.warn(f"Object '{obj.name}': no attribute '{key or '(render color)'}' "
                             "for a material's node graph; it reads 0")
            return None
        n = len(attr.data)
        dt = attr.data_type
        if dt in ("FLOAT_COLOR", "BYTE_COLOR"):
            buf = np.empty(n * 4, np.float32)
            attr.data.foreach_get("color", buf)
            v = buf.reshape(n, 4)[:, :3]
        elif dt == "FLOAT_VECTOR":
            buf = np.empty(n * 3, np.float32)
            attr.data.foreach_get("vector", buf)
            v = buf.reshape(n, 3)
        elif dt == "FLOAT2":
            buf = np.empty(n * 2, np.float32)
            attr.data.foreach_get("vector", buf)
            v = np.concatenate([buf.reshape(n, 2), np.zeros((n, 1), np.float32)], axis=1)
        elif dt in ("FLOAT", "INT", "BOOLEAN"):
            buf = np.empty(n, np.float32 if dt == "FLOAT" else np.int32)
            attr.data.foreach_get("value", buf)
            v = np.repeat(buf.astype(np.float32)[:, None], 3, axis=1)
        else:
            self.report.warn(f"Object '{obj.name}': attribute '{key}' of type {dt} is not "
                             "supported by node graphs; it reads 0")
            return None
        if attr.domain == "POINT":
            v = v[corner_vert]
        elif attr.domain != "CORNER":
            self.report.warn(f"Object '{obj.name}': attribute '{key}' on the {attr.domain} "
                             "domain is not supported by node graphs; it reads 0")
            return None
        if len(v) != nl:
            return None
        return np.ascontiguousarray(v, np.float32)

    # ---- per instance ----
    def instance(self, inst, local, nl, normals_to_world=None):
        """The channels of one instance: its local ones and the per-object values."""
        out = dict(local)
        obj = inst.object
        if any(n in self.names for n in INSTANCE):
            m = np.array(inst.matrix_world, dtype=np.float64)
            seed = zlib.crc32(f"{obj.name}/{getattr(inst, 'random_id', 0)}".encode())
            rnd = float(seed & 0xFFFFFF) / float(0xFFFFFF)
            per = {"object_location": m[:3, 3],
                   "object_random": (rnd, float(getattr(obj, "pass_index", 0)), 0.0),
                   "object_color": tuple(getattr(obj, "color", (1, 1, 1, 1)))[:3]}
            try:   # object-space normals to the world: the inverse transpose
                nrm = np.linalg.inv(m[:3, :3]).T
            except np.linalg.LinAlgError:
                nrm = np.eye(3)
            for k, axis in enumerate("xyz"):
                per[f"object_normal_{axis}"] = nrm[k]
            for name in INSTANCE:
                if name in self.names:
                    out[name] = np.tile(np.asarray(per[name], np.float32), (nl, 1))
        return out

    def finish(self, meshes):
        """Replaces each mesh's channel dict with one (V, 3 C) array; returns the names. A mesh
        that already holds an array of C channels and no dict is left as it is."""
        c = len(self.names)
        for mesh in meshes:
            if "_attributes" not in mesh and mesh.get("attributes") is not None \
                    and mesh["attributes"].shape[1] == 3 * c:
                continue  # finished by an earlier sync (export/sync.py reuses placed meshes)
            got = mesh.pop("_attributes", None) or {}
            if c == 0:
                continue
            nv = len(mesh["positions"])
            arr = np.zeros((nv, 3 * c), np.float32)
            for i, name in enumerate(self.names):
                v = got.get(name)
                if v is not None and len(v) == nv:
                    arr[:, 3 * i:3 * i + 3] = v
            mesh["attributes"] = arr
        return list(self.names)
