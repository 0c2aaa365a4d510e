"""Evaluated geometry -> world-space triangle arrays through foreach_get (never as_pointer).

Vertices are emitted per face corner so that split normals and UV seams survive; the arrays of
an object are extracted once and reused for each of its instances (only the transform differs)."""

import numpy as np


def _attribute(mesh, name, domain, size, dtype, prop, width=1):
    """An attribute's values through foreach_get (the fast, raw-array path), or None."""
    attr = mesh.attributes.get(name)
    if attr is None or attr.domain != domain:
        return None
    out = np.empty(size * width, dtype)
    attr.data.foreach_get(prop, out)
    return out if width == 1 else out.reshape(size, width)


def _corner_tangents(mesh, report, name):
    """Per-corner MikkTSpace tangents (x, y, z, bitangent sign) of the active UV map, as Blender
    and Cycles compute them for normal maps; None where they cannot be computed."""
    try:
        mesh.calc_tangents(uvmap=mesh.uv_layers.active.name)
    except RuntimeError as e:
        report.warn(f"Object '{name}': no tangents for its normal map ({e}); the uv "
                    "directions of each triangle are used")
        return None
    nl = len(mesh.loops)
    t = np.empty(nl * 3, np.float32)
    mesh.loops.foreach_get("tangent", t)
    sign = np.empty(nl, np.float32)
    mesh.loops.foreach_get("bitangent_sign", sign)
    mesh.free_tangents()
    return np.concatenate([t.reshape(nl, 3), sign[:, None]], axis=1)


def _corner_arrays(mesh):
    """Local-space arrays of an evaluated mesh: per-corner positions, normals, uvs; triangles
    as corner indices; per-triangle material slot.

    Attributes are read directly where they exist (".corner_vert", "position",
    "material_index"): orders of magnitude faster than the per-element RNA collections."""
    mesh.calc_loop_triangles()
    nt = len(mesh.loop_triangles)
    if nt == 0:
        return None
    nv, nl = len(mesh.vertices), len(mesh.loops)
    co = _attribute(mesh, "position", "POINT", nv, np.float32, "vector", 3)
    if co is None:
        co = np.empty(nv * 3, np.float32)
        mesh.vertices.foreach_get("co", co)
        co = co.reshape(nv, 3)
    corner_vert = _attribute(mesh, ".corner_vert", "CORNER", nl, np.int32, "value")
    if corner_vert is None:
        corner_vert = np.empty(nl, np.int32)
        mesh.loops.foreach_get("vertex_index", corner_vert)
    tri = np.empty(nt * 3, np.int32)
    mesh.loop_triangles.foreach_get("loops", tri)
    tri_poly = np.empty(nt, np.int32)
    mesh.loop_triangle_polygons.foreach_get("value", tri_poly)
    poly_mat = _attribute(mesh, "material_index", "FACE", len(mesh.polygons), np.int32, "value")
    mat = poly_mat[tri_poly] if poly_mat is not None else np.zeros(nt, np.int32)
    normals = np.empty(nl * 3, np.float32)
    mesh.corner_normals.foreach_get("vector", normals)
    uvs = None
    if mesh.uv_layers.active is not None:
        uvs = np.empty(nl * 2, np.float32)
        mesh.uv_layers.active.uv.foreach_get("vector", uvs)
        uvs = uvs.reshape(nl, 2)
    # flat shaded throughout (Face normals): Cycles shades each triangle by its own normal, where
    # the corner normals are the face's (a non-planar quad's differ from its triangles')
    flat = getattr(mesh, "normals_domain", "") == "FACE"
    return {"positions": co[corner_vert], "normals": normals.reshape(nl, 3),
            "uvs": uvs, "indices": tri.reshape(nt, 3).astype(np.uint32), "slots": mat,
            "corner_vert": corner_vert, "num_verts": nv, "flat": flat}


def _needs_tangents(m):
    return "normal_texture" in m or "coat_normal_texture" in m or \
        (m.get("anisotropy", 0.0) > 0.0 and m.get("tangent") == "uv")


class MeshExporter:
    def __init__(self, materials, report):
        self.materials = materials
        self.report = report
        self._cache = {}

    def _local(self, obj):
        # geometry-nodes instances come as temporary objects named after the instancer but
        # holding the instanced data: the data's name tells them apart
        data = getattr(obj, "data", None)
        key = (obj.name_full, data.name_full if data is not None else None)
        if key in self._cache:
            return self._cache[key]
        arrays = None
        try:
            mesh = obj.to_mesh()
        except RuntimeError as e:
            self.report.warn(f"Object '{obj.name}': could not get its geometry ({e})")
            mesh = None
        slots = [self.materials.index(s.material) for s in obj.material_slots] or [0]
        if mesh is not None:
            try:
                arrays = _corner_arrays(mesh)
                # tangents only where a material of the object has a normal map or uv-tangent
                # anisotropy (mix leaves follow their mix in the table)
                if arrays is not None and arrays["uvs"] is not None and any(
                        _needs_tangents(m) for m in self._slot_materials(slots)):
                    arrays["tangents"] = _corner_tangents(mesh, self.report, obj.name)
                if arrays is not None:   # what node-graph materials read (node_attributes)
                    arrays["attr_local"] = self.materials.attributes.local(
                        obj, mesh, arrays, arrays["corner_vert"])
            finally:
                obj.to_mesh_clear()
        if arrays is not None:
            lut = np.array(slots, dtype=np.uint32)
            arrays["material_ids"] = lut[np.clip(arrays.pop("slots"), 0, len(lut) - 1)]
        self._cache[key] = arrays
        return arrays

    def _slot_materials(self, slots):
        """The materials of the slots, with the leaves of mixes."""
        table = self.materials.materials
        out = []
        for i in slots:
            m = table[i]
            out.append(m)
            out.extend(table[leaf] for leaf, _ in m.get("mix", ()))
        return out

    def export(self, inst):
        obj = inst.object
        local = self._local(obj)
        if local is None:
            return None
        m = np.array(inst.matrix_world, dtype=np.float64)
        lin, t = m[:3, :3], m[:3, 3]
        positions = (local["positions"] @ lin.T.astype(np.float32)) + t.astype(np.float32)
        indices = local["indices"]
        det = np.linalg.det(lin)
        gram = lin.T @ lin
        scale2 = float(np.trace(gram)) / 3.0
        normals = None
        if abs(det) > 1e-30 and np.allclose(gram, scale2 * np.eye(3), rtol=1e-6, atol=1e-12):
            # rotation and uniform scale (the usual case): unit normals stay unit, no division
            normals = local["normals"] @ (lin.T / np.sqrt(scale2)).astype(np.float32)
        elif abs(det) > 1e-30:
            normals = local["normals"] @ np.linalg.inv(lin).astype(np.float32)  # n @ inv(M)
            length = np.sqrt(np.einsum("ij,ij->i", normals, normals))[:, None]
            normals = np.divide(normals, length, out=np.zeros_like(normals), where=length > 0)
        else:
            self.report.warn(f"Object '{obj.name}': degenerate transform; flat shading used")
        tangents = local.get("tangents")
        if tangents is not None:
            t = tangents[:, :3] @ lin.T.astype(np.float32)
            length = np.sqrt(np.einsum("ij,ij->i", t, t))[:, None]
            t = np.divide(t, length, out=np.zeros_like(t), where=length > 0)
            # a mirroring transform flips the frame's handedness
            sign = tangents[:, 3:] * (np.float32(-1) if det < 0 else np.float32(1))
            tangents = np.ascontiguousarray(np.concatenate([t, sign], axis=1), np.float32)
        if det < 0:
            indices = indices[:, [0, 2, 1]]  # mirrored: keep the winding's orientation
        material_ids = local["material_ids"]
        if not np.isfinite(positions.sum(dtype=np.float64)):  # cheap check first
            finite = np.isfinite(positions).all(axis=1)
            self.report.warn(f"Object '{obj.name}': non-finite vertex positions; those "
                             "triangles are skipped")
            keep = finite[indices].all(axis=1)
            indices, material_ids = indices[keep], material_ids[keep]
            positions = np.where(finite[:, None], positions, np.float32(0))
            if normals is not None:
                normals = np.nan_to_num(normals, nan=0.0, posinf=0.0, neginf=0.0)
            if tangents is not None:
                tangents = np.nan_to_num(tangents, nan=0.0, posinf=0.0, neginf=0.0)
            if len(indices) == 0:
                return None
        name = obj.name
        if inst.is_instance:
            source = getattr(obj.data, "name", obj.name)
            name = f"{inst.parent.name if inst.parent else obj.name}: {source} (instance)"
        attrs = self.materials.attributes  # ray visibility, holdouts, linking: export/walk.py
        extra = {"_attributes": attrs.instance(inst, local.get("attr_local", {}), len(positions))}\
            if attrs.names else {}
        return {**extra, "name": name, "positions": np.ascontiguousarray(positions, np.float32),
                "indices": np.ascontiguousarray(indices, np.uint32),
                "normals": None if normals is None else np.ascontiguousarray(normals, np.float32),
                "uvs": local["uvs"], "tangents": tangents, "material_ids": material_ids,
                **({"flat_shading": True} if local.get("flat") else {})}

    def corners(self, obj):
        """(the vertex of each exported corner of obj, its vertex count), or None: deformation
        blur reads the vertices' positions at the shutter's steps through them (motion.py)."""
        data = getattr(obj, "data", None)
        local = self._cache.get((obj.name_full, data.name_full if data is not None else None))
        if local is None or "corner_vert" not in local:
            return None
        return local["corner_vert"], local["num_verts"]

    def clear(self):
        self._cache.clear()
