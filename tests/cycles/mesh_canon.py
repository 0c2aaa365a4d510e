"""Script-built meshes in an order that is the same in every process."""

import bpy
import numpy as np


def canonical_faces(obj):
    """Rebuild obj's mesh with its faces in a canonical order, each starting at its lowest vertex.

    Blender's UV sphere primitive (5.0.1) gives the same vertices but another face order and
    other loop starts in each process, and the particle system distributes its hair over the
    faces in their order, so the fur (and the key of the stored Cycles reference) would differ
    per process. Vertices, UVs and smooth shading are kept."""
    me = obj.data
    nv, nl, nf = len(me.vertices), len(me.loops), len(me.polygons)
    co = np.empty(nv * 3, np.float32)
    me.vertices.foreach_get("co", co)
    cv = np.empty(nl, np.int32)
    me.loops.foreach_get("vertex_index", cv)
    uv = np.empty(nl * 2, np.float32)
    me.uv_layers.active.uv.foreach_get("vector", uv)
    uv = uv.reshape(nl, 2)
    starts = np.empty(nf, np.int32)
    me.polygons.foreach_get("loop_start", starts)
    sizes = np.empty(nf, np.int32)
    me.polygons.foreach_get("loop_total", sizes)
    smooth = np.empty(nf, bool)
    me.polygons.foreach_get("use_smooth", smooth)
    faces = []
    for f in range(nf):
        loops = list(range(starts[f], starts[f] + sizes[f]))
        r = int(np.argmin(cv[loops]))
        loops = loops[r:] + loops[:r]
        faces.append((tuple(int(v) for v in cv[loops]), loops, bool(smooth[f])))
    faces.sort(key=lambda t: t[0])
    new = bpy.data.meshes.new(me.name)
    new.from_pydata(co.reshape(nv, 3).tolist(), [], [t[0] for t in faces])
    layer = new.uv_layers.new(name=me.uv_layers.active.name)
    order = np.array([i for t in faces for i in t[1]], np.int64)
    layer.uv.foreach_set("vector", uv[order].ravel())
    new.polygons.foreach_set("use_smooth", np.array([t[2] for t in faces], bool))
    new.update()
    obj.data = new
    bpy.data.meshes.remove(me)
