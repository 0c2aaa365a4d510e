"""Evaluated geometry -> world-space triangle arrays through foreach_get (never as_pointer).

Vertices are emitted per face corner so that split normals and UV seams survive; the arrays of
an object are extracted once and reused for each of its instances (only the transform differs)."""

import numpy as np


def _corner_arrays(mesh):
    """Local-space arrays of an evaluated mesh: per-corner positions, normals, uvs; triangles
    as corner indices; per-triangle material slot."""
    mesh.calc_loop_triangles()
    nt = len(mesh.loop_triangles)
    if nt == 0:
        return None
    nv, nl = len(mesh.vertices), len(mesh.loops)
    co = np.empty(nv * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    corner_vert = np.empty(nl, np.int32)
    mesh.loops.foreach_get("vertex_index", corner_vert)
    tri = np.empty(nt * 3, np.int32)
    mesh.loop_triangles.foreach_get("loops", tri)
    mat = np.empty(nt, np.int32)
    mesh.loop_triangles.foreach_get("material_index", mat)
    normals = np.empty(nl * 3, np.float32)
    mesh.corner_normals.foreach_get("vector", normals)
    uvs = None
    if mesh.uv_layers.active is not None:
        uvs = np.empty(nl * 2, np.float32)
        mesh.uv_layers.active.uv.foreach_get("vector", uvs)
        uvs = uvs.reshape(nl, 2)
    return {"positions": co.reshape(nv, 3)[corner_vert], "normals": normals.reshape(nl, 3),
            "uvs": uvs, "indices": tri.reshape(nt, 3).astype(np.uint32), "slots": mat}


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
        if mesh is not None:
            try:
                arrays = _corner_arrays(mesh)
            finally:
                obj.to_mesh_clear()
        if arrays is not None:
            slots = [self.materials.index(s.material) for s in obj.material_slots] or [0]
            lut = np.array(slots, dtype=np.uint32)
            arrays["material_ids"] = lut[np.clip(arrays.pop("slots"), 0, len(lut) - 1)]
        self._cache[key] = arrays
        return arrays

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
        try:
            normal_matrix = np.linalg.inv(lin).astype(np.float32)  # n' = n @ inv(M)
        except np.linalg.LinAlgError:
            normal_matrix = None
        if normal_matrix is not None and abs(det) > 0:
            normals = local["normals"] @ normal_matrix
            length = np.linalg.norm(normals, axis=1, keepdims=True)
            normals = np.divide(normals, length, out=np.zeros_like(normals), where=length > 0)
        else:
            self.report.warn(f"Object '{obj.name}': degenerate transform; flat shading used")
            normals = None
        if det < 0:
            indices = indices[:, [0, 2, 1]]  # mirrored: keep the winding's orientation
        material_ids = local["material_ids"]
        finite = np.isfinite(positions).all(axis=1)
        if not finite.all():
            self.report.warn(f"Object '{obj.name}': non-finite vertex positions; those "
                             "triangles are skipped")
            keep = finite[indices].all(axis=1)
            indices, material_ids = indices[keep], material_ids[keep]
            positions = np.where(finite[:, None], positions, np.float32(0))
            if normals is not None:
                normals = np.nan_to_num(normals, nan=0.0, posinf=0.0, neginf=0.0)
            if len(indices) == 0:
                return None
        name = obj.name
        if inst.is_instance:
            source = getattr(obj.data, "name", obj.name)
            name = f"{inst.parent.name if inst.parent else obj.name}: {source} (instance)"
        return {"name": name, "positions": np.ascontiguousarray(positions, np.float32),
                "indices": np.ascontiguousarray(indices, np.uint32),
                "normals": None if normals is None else np.ascontiguousarray(normals, np.float32),
                "uvs": local["uvs"], "material_ids": material_ids,
                "visible_camera": bool(getattr(obj, "visible_camera", True)),
                "cast_shadow": bool(getattr(obj, "visible_shadow", True))}

    def clear(self):
        self._cache.clear()
