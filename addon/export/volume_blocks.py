"""A Volume object's blocks (export/volume_objects.py): the box mesh over a block's trilinear
support, the layout block grown to cover the other grids its programs read, the box's texture
space; its colour grids (Principled Volume's Color Attribute, an Attribute node on a Color)."""

import numpy as np

_COVER_VOXELS = 1 << 25   # 128 MiB of float voxels


def _box(index_to_world, dims):
    """positions (8, 3) and indices (12, 3) of the block's trilinear support [-1, n] per axis
    mapped to the world, faces outward (also under a mirroring matrix)."""
    nx, ny, nz = dims
    lo, hi = [-1.0, -1.0, -1.0], [float(nx), float(ny), float(nz)]
    corners = np.array([[hi[0] if c & 1 else lo[0], hi[1] if c & 2 else lo[1],
                         hi[2] if c & 4 else lo[2], 1.0] for c in range(8)])
    pos = (corners @ np.asarray(index_to_world, np.float64).T)[:, :3]
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    tris = []
    for a, b, c, d in quads:
        tris += [(a, b, c), (a, c, d)]
    tris = np.array(tris, np.uint32)
    if np.linalg.det(np.asarray(index_to_world, np.float64)[:3, :3]) < 0.0:
        tris = tris[:, ::-1].copy()
    return pos.astype(np.float32), np.ascontiguousarray(tris)


def _cover(voxels, to_world, others, warn):
    """(voxels, index_to_world) of the layout block `voxels` (z, y, x) grown with zeros so that
    its trilinear support [-1, n] covers that of each grid in `others` (dicts of "voxels" and
    "index_to_world"); a block read as 0 outside its active voxels (background 0) reads the
    same, as does the layout grid's lookup in the density program. A block that would grow
    past _COVER_VOXELS (and 8x its own) stays, and warn(message) says so."""
    shape = np.array(voxels.shape[::-1])  # (nx, ny, nz)
    lo, hi = np.zeros(3), shape - 1.0     # the voxel centres the block must hold
    world_to_index = np.linalg.inv(np.asarray(to_world, np.float64))
    for o in others:
        n = np.array(o["voxels"].shape[:3][::-1], np.float64)
        c = np.array([[n[0] if k & 1 else -1.0, n[1] if k & 2 else -1.0,
                       n[2] if k & 4 else -1.0, 1.0] for k in range(8)])
        q = (c @ (world_to_index @ np.asarray(o["index_to_world"], np.float64)).T)[:, :3]
        # the support [lo - 1, hi + 1] holds q (a rounding's slack: no voxel more for it)
        qa, qb = q.min(axis=0) + 1.0, q.max(axis=0) - 1.0
        lo = np.minimum(lo, np.floor(qa + 1e-5 * (1.0 + np.abs(qa))))
        hi = np.maximum(hi, np.ceil(qb - 1e-5 * (1.0 + np.abs(qb))))
    lo, hi = lo.astype(np.int64), hi.astype(np.int64)
    dims = hi - lo + 1
    if (lo == 0).all() and (hi == shape - 1).all():
        return voxels, to_world
    if int(np.prod(dims)) > max(_COVER_VOXELS, 8 * voxels.size):
        warn(f"the grids its node graphs read reach beyond its density grid's block, which "
             f"would grow to {dims[0]} x {dims[1]} x {dims[2]} voxels; the medium ends at the "
             "density grid's block")
        return voxels, to_world
    out = np.zeros((dims[2], dims[1], dims[0]), np.float32)
    o = -lo
    out[o[2]:o[2] + shape[2], o[1]:o[1] + shape[1], o[0]:o[0] + shape[0]] = voxels
    shift = np.eye(4)
    shift[:3, 3] = lo
    return np.ascontiguousarray(out), np.asarray(to_world, np.float64) @ shift


def _texture_space(matrix_world, positions):
    """{"generated", "object"} per vertex of the box (world positions): on a Volume object
    Cycles (bpy 5.0.1) gives both as the object-space position (measured: Generated normalised
    to the Volume's bounds, as sync_volume_object's generated transform reads, differed by
    z 180; tests/cycles/test_volumes_vdb_texcoord.py)."""
    p = np.c_[np.asarray(positions, np.float64), np.ones(len(positions))]
    local = (p @ np.linalg.inv(np.array(matrix_world, np.float64)).T)[:, :3].astype(np.float32)
    return {"generated": local, "object": local.copy()}


def _color_attribute_grid(node, file_grids):
    """The grid that a Principled Volume's Color Attribute names, where the object's file has
    it (Cycles multiplies the Color by it; a missing one leaves the Color as it is), or None."""
    sock = node.inputs.get("Color Attribute") if node.type == "PRINCIPLED_VOLUME" else None
    name = str(sock.default_value) if sock is not None else ""
    return name if name and name in file_grids else None


def _times_grid(name):
    """A GraphCompiler post-step: the program's colour times grid `name`'s colour (kOpGrid; a
    float grid's value in all three channels), per channel."""
    def post(ctx, v):
        from .node_handlers import grid_register
        g = ctx.reg(grid_register(ctx, name), 3, "RGBA")
        r, _ = ctx.emit_node("vector_math", [ctx.convert(v, "VECTOR"), ctx.convert(g, "VECTOR"),
                                             ctx.const((0, 0, 0), "VECTOR"),
                                             ctx.const((0,), "VALUE")], 4, mode=2)
        return ctx.reg(r, 3, "RGBA")
    return post


def _color_attribute(node):
    """The grid name of an Attribute node (Geometry, its Color output) on the Color of a
    Principled Volume, Volume Scatter or Volume Absorption, or None."""
    from .volume import _source
    if node.type not in ("PRINCIPLED_VOLUME", "VOLUME_SCATTER", "VOLUME_ABSORPTION"):
        return None
    sock = node.inputs.get("Color")
    src = _source(sock) if sock is not None else None
    if src is None or src.type != "ATTRIBUTE" or \
            getattr(src, "attribute_type", "GEOMETRY") != "GEOMETRY":
        return None
    link = sock.links[0]
    if link.from_node.type != "ATTRIBUTE" or link.from_socket.identifier != "Color":
        return None
    return str(src.attribute_name)


def _color_dropped(medium, c=1.0):
    """medium without its colour grid: the colour c everywhere folded back into sigma_a and
    sigma_s (1: the Color socket alone, as Cycles without the attribute)."""
    scat = medium.pop("color_scatter", [0.0] * 3)
    absorb = medium.pop("color_absorb", [0.0] * 3)
    base = medium.pop("color_base", [1.0] * 3)
    medium["sigma_s"] = [x + s * c for x, s in zip(medium["sigma_s"], scat)]
    medium["sigma_a"] = [x + a * max(1.0 - b * c, 0.0)
                         for x, a, b in zip(medium["sigma_a"], absorb, base)]
