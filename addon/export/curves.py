"""Blender's hair as strands, read as Cycles reads it (intern/cycles/blender/curves.cpp): Curves
objects (the hair of Blender 3.3+) and particle systems of render type Path, into world-space
numpy arrays: points, a radius per point, strand offsets, a material slot per strand.

Particle hair: 2^render_step + 1 keys per strand through ParticleSystem.co_hair (world space);
children replace their parents when the system has them (Cycles renders the parents only
without children); radius at arc-length fraction t: shape-curved blend of root and tip, both
times radius_scale / 2, 0 at the tip with Close Tip. Curves objects: the "radius" point
attribute (Cycles' 0.005 where there is none), "material_index" per curve. Radii are scaled
by the object's mean scale (cube root of |det|). The memory a system needs is checked before any
point is read; strands with a NaN or negative radius or a non-finite point are dropped, with a
message. export/strands.py hands the strands to the scene (docs/curves.md)."""

import numpy as np

DEFAULT_RADIUS = 0.005           # Cycles' radius where a Curves object has no radius attribute
MAX_STRAND_BYTES = 2 << 30       # points (12 B) + radius (4 B) + offsets and materials (8 B)


class Strands:
    """One object's strands: points (P, 3) float32 world space, radius (P,) float32, offsets
    (S + 1,) int32 (strand s is points offsets[s]:offsets[s + 1]), material (S,) int32 slots."""

    def __init__(self, points, radius, offsets, material):
        self.points, self.radius, self.offsets, self.material = points, radius, offsets, material

    @property
    def num_strands(self):
        return len(self.offsets) - 1

    @property
    def nbytes(self):
        return sum(a.nbytes for a in (self.points, self.radius, self.offsets, self.material))


def strand_bytes(num_strands, num_points):
    return 16 * num_points + 8 * num_strands + 4


def shape_radius(shape, root, tip, t):
    """Cycles' particle hair radius at arc-length fraction t (array) for the Shape slider."""
    r = 1.0 - np.clip(t, 0.0, 1.0)
    if shape < 0.0:
        r = r ** (1.0 + shape)
    elif shape > 0.0:
        r = r ** (1.0 / (1.0 - shape))
    return r * (root - tip) + tip


def _mean_scale(matrix_world):
    m = np.array(matrix_world, dtype=np.float64)[:3, :3]
    return float(abs(np.linalg.det(m)) ** (1.0 / 3.0))


def _arc_fraction(points, offsets):
    """Per point, its arc length along its strand over the strand's length (0 where 0)."""
    seg = np.linalg.norm(np.diff(points, axis=0), axis=1)
    t = np.zeros(len(points), np.float64)
    for s in range(len(offsets) - 1):
        a, b = offsets[s], offsets[s + 1]
        if b - a < 2:
            continue
        cum = np.concatenate([[0.0], np.cumsum(seg[a:b - 1])])
        t[a:b] = cum / cum[-1] if cum[-1] > 0.0 else 0.0
    return t


def _clean(strands, report, what):
    """Drop strands with a NaN, infinite or negative radius or a non-finite point, and say so;
    a strand whose radii are all 0 is invisible (as in Cycles) and dropped without a message."""
    pts, rad, off = strands.points, strands.radius, strands.offsets
    bad_point = ~(np.isfinite(pts).all(axis=1) & np.isfinite(rad) & (rad >= 0.0))
    counts = np.diff(off)
    strand_of = np.repeat(np.arange(len(counts)), counts)
    bad = np.zeros(len(counts), bool)
    np.logical_or.at(bad, strand_of, bad_point)
    visible = np.zeros(len(counts), bool)
    np.logical_or.at(visible, strand_of, rad > 0.0)
    if bad.any():
        report.warn(f"{what}: {int(bad.sum())} of {len(counts)} strands have a NaN, infinite or "
                    "negative radius or position and are not exported")
    keep = ~bad & visible & (counts >= 2)
    if keep.all():
        return strands
    point_keep = np.repeat(keep, counts)
    new_counts = counts[keep]
    offsets = np.concatenate([[0], np.cumsum(new_counts)]).astype(np.int32)
    return Strands(pts[point_keep], rad[point_keep], offsets, strands.material[keep])


def _over_budget(report, what, num_strands, num_points, budget):
    need = strand_bytes(num_strands, num_points)
    if need <= budget:
        return False
    report.warn(f"{what}: {num_strands} strands of {num_points} points need "
                f"{need / 2**20:.0f} MiB, over the {budget / 2**20:.0f} MiB strand budget; "
                "not exported")
    return True


# ---- Cycles' smooth strands as round linear pieces ----
def catmull_rom_pieces(strands, pieces):
    """Each key interval of every strand cut into `pieces` linear pieces along the uniform
    Catmull-Rom spline through the keys (Cycles' thick hair: its keys are Catmull-Rom control
    points, the end keys repeated), radius interpolated by the same spline and kept >= 0. The
    strand still passes through its keys; pieces = 1 gives the keys back."""
    if pieces <= 1:
        return strands
    pts, rad, off = strands.points.astype(np.float64), strands.radius.astype(np.float64), \
        strands.offsets
    u = np.arange(pieces, dtype=np.float64) / pieces
    # basis of the uniform Catmull-Rom segment from P1 to P2 (rows: P0..P3) at each u
    b = 0.5 * np.stack([-u + 2 * u**2 - u**3, 2 - 5 * u**2 + 3 * u**3,
                        u + 4 * u**2 - 3 * u**3, -u**2 + u**3], axis=1)
    out_p, out_r, counts = [], [], []
    for s in range(len(off) - 1):
        p4 = np.concatenate([pts[off[s]:off[s + 1]], rad[off[s]:off[s + 1], None]], axis=1)
        n = len(p4)
        if n < 2:
            continue
        ext = np.concatenate([p4[:1], p4, p4[-1:]])          # repeat the end keys
        rows = [b @ ext[i:i + 4] for i in range(n - 1)]      # (pieces, 4) per interval
        rows.append(p4[-1:])
        q = np.concatenate(rows)
        out_p.append(q[:, :3])
        out_r.append(np.maximum(q[:, 3], 0.0))
        counts.append(len(q))
    offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int32)
    return Strands(np.concatenate(out_p).astype(np.float32),
                   np.concatenate(out_r).astype(np.float32), offsets, strands.material.copy())


# ---- Curves objects ----
def curves_object_strands(obj, matrix_world, report, budget=MAX_STRAND_BYTES):
    """The strands of an evaluated Curves object (obj.type == 'CURVES'), or None."""
    curves = obj.data
    num_points, num_strands = len(curves.points), len(curves.curves)
    if num_strands == 0 or _over_budget(report, f"Object '{obj.name}'", num_strands, num_points,
                                        budget):
        return None
    co = np.empty(num_points * 3, np.float32)
    curves.attributes["position"].data.foreach_get("vector", co)
    co = co.reshape(num_points, 3).astype(np.float64)
    offsets = np.empty(num_strands + 1, np.int32)
    curves.curve_offset_data.foreach_get("value", offsets)
    radius = np.full(num_points, DEFAULT_RADIUS, np.float32)
    attr = curves.attributes.get("radius")
    if attr is not None and attr.domain == "POINT" and attr.data_type == "FLOAT":
        attr.data.foreach_get("value", radius)
    material = np.zeros(num_strands, np.int32)
    attr = curves.attributes.get("material_index")
    if attr is not None and attr.domain == "CURVE" and attr.data_type == "INT":
        attr.data.foreach_get("value", material)
    m = np.array(matrix_world, dtype=np.float64)
    world = co @ m[:3, :3].T + m[:3, 3]
    strands = Strands(world.astype(np.float32),
                      (radius * _mean_scale(matrix_world)).astype(np.float32), offsets, material)
    return _clean(strands, report, f"Object '{obj.name}'")


# ---- Particle hair ----
def particle_strand_counts(psys, final=True, viewport_cache=False):
    """(strands, keys per strand, first particle index) as Cycles counts them. The keys are
    those the evaluated cache holds: a viewport depsgraph's hair has its Viewport Steps even
    for a final export (co_hair reads (0, 0, 0) past them: every strand ran on to the world's
    origin, difftest3)."""
    s = psys.settings
    parents, children = len(psys.particles), len(psys.child_particles)
    if not final:
        children = int(children * s.display_percentage / 100.0)
    first = parents if (s.child_type != "NONE" and children > 0) else 0
    steps = (1 << (s.render_step if final and not viewport_cache else s.display_step)) + 1
    if s.kink == "SPIRAL":
        steps += s.kink_extra_steps
    return parents + children - first, steps, first


def particle_hair_strands(obj, psys, matrix_world, report, budget=MAX_STRAND_BYTES, final=True,
                          viewport_cache=False):
    """The strands of one particle system of render type Path on an evaluated object, or None.
    `viewport_cache`: the object was evaluated by a viewport depsgraph (particle_strand_counts)."""
    s = psys.settings
    if s.type != "HAIR" or s.render_type != "PATH":
        return None
    what = f"Object '{obj.name}', particle hair '{psys.name}'"
    if final and viewport_cache and s.display_step != s.render_step:
        report.warn(f"{what}: exported from a viewport depsgraph, whose hair has the Viewport "
                    f"Steps ({s.display_step}), not the Render Steps ({s.render_step}) of a "
                    "final render: the strands' keys differ from Cycles'")
    num_strands, steps, first = particle_strand_counts(psys, final, viewport_cache)
    if num_strands == 0 or _over_budget(report, what, num_strands, num_strands * steps, budget):
        return None
    pts = np.empty((num_strands * steps, 3), np.float64)
    k = 0
    for p in range(first, first + num_strands):
        for step in range(steps):
            pts[k] = psys.co_hair(obj, particle_no=p, step=step)
            k += 1
    # co_hair is in the object's own world placement: back to object space (as Cycles does),
    # then to this instance's (a collection instance of a furry object sits elsewhere)
    own = np.array(obj.matrix_world, dtype=np.float64)
    to_inst = np.array(matrix_world, dtype=np.float64) @ np.linalg.inv(own)
    pts = pts @ to_inst[:3, :3].T + to_inst[:3, 3]
    offsets = (np.arange(num_strands + 1) * steps).astype(np.int32)
    t = _arc_fraction(pts, offsets)
    half = 0.5 * s.radius_scale
    radius = shape_radius(s.shape, half * s.root_radius, half * s.tip_radius, t)
    if s.use_close_tip:
        radius[offsets[1:] - 1] = 0.0
    # the radii follow the instance's scale (Cycles keeps the strands in object space under the
    # object's transform); t above is read in world space, the same fraction for a similarity
    radius = radius * _mean_scale(matrix_world)
    material = np.full(num_strands, max(int(s.material) - 1, 0), np.int32)
    strands = Strands(pts.astype(np.float32), radius.astype(np.float32), offsets, material)
    return _clean(strands, report, what)


def object_strands(obj, matrix_world, report, budget=MAX_STRAND_BYTES, final=True,
                   viewport_cache=False):
    """Every strand set an evaluated object renders as hair: its Curves data and its particle
    hair systems whose modifier shows for this kind of render."""
    out = []
    if obj.type == "CURVES":
        st = curves_object_strands(obj, matrix_world, report, budget)
        if st is not None:
            out.append(st)
    shown = {m.particle_system.name for m in getattr(obj, "modifiers", ())
             if m.type == "PARTICLE_SYSTEM" and (m.show_render if final else m.show_viewport)}
    for psys in getattr(obj, "particle_systems", ()):
        if psys.name in shown:
            st = particle_hair_strands(obj, psys, matrix_world, report, budget, final,
                                       viewport_cache)
            if st is not None:
                out.append(st)
    return out
