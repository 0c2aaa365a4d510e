// Strands in the scene (docs/curves.md): round linear segments (accel/curve_bvh.h's CurveSeg)
// whose primitive ids follow the triangles': prim = num_triangles + segment. The per-primitive
// arrays (tri_material, tri_flags, tri_light, ...) hold an entry for each segment too, so that
// sorting and per-hit flags read them as they read a triangle's. Host+device.
#pragma once

#include "accel/curve_bvh.h"
#include "scene/motion.h"

namespace lantern {

// A strand set that moves with its object (motion blur; docs/motion_blur.md "Strands of a
// turning object"): its segments stay where they were exported (their keys too, where the
// points also deform: lerped in that same exported frame) and the object's matrix at the
// shutter's steps carries them, as a moving mesh (scene/motion.h's ObjectMotion): at `time` the
// exported frame goes to world by motion_at(time) * base_inv, the rotation slerped. o.tri_begin
// and o.tri_count are the set's segment range in CurveView::segs (not triangles); o.mesh and
// o.deform are -1.
struct CurveSetMotion {
    ObjectMotion o;
    float radius_scale;  // the most the steps scale a length of the exported frame (>= 1)
};

struct CurveView {
    const CurveSeg* segs = nullptr;  // in primitive order: segs[k] is prim num_triangles + k
    int32_t num_segs = 0;
    CurveKeys keys;  // motion blur: the moving segments' steps (CurveSeg::flags kCurveMoves)
    const CurveSetMotion* sets = nullptr;  // moving sets, ordered by segment range, disjoint
    int32_t num_sets = 0;
};

// The moving set that holds segment seg, or null (a binary search over the few movers).
LANTERN_HD inline const CurveSetMotion* curve_set_of(const CurveView& c, int seg) {
    int lo = 0, hi = c.num_sets - 1;
    while (lo <= hi) {
        const int mid = (lo + hi) >> 1;
        const ObjectMotion& o = c.sets[mid].o;
        if (seg < o.tri_begin) {
            hi = mid - 1;
        } else if (seg >= o.tri_begin + o.tri_count) {
            lo = mid + 1;
        } else {
            return &c.sets[mid];
        }
    }
    return nullptr;
}

// Segment prim - num_triangles as a ray at `time` meets it (its keys lerped where it moves).
LANTERN_HD inline CurveSeg curve_seg_of(const CurveView& c, int seg, float time) {
    return curve_seg_at(c.segs[seg], c.keys, time);
}

// The surface of segment g at the point x on it: the outward normal of the sphere whose centre
// lies where the normal line meets the axis (accel/curve_hit.h's parametrisation), found from
// x alone, so that every ray-query structure's hit gives the same frame. tangent: the axis.
LANTERN_HD inline Vec3 curve_normal_at(const CurveSeg& g, Vec3 x, Vec3* tangent) {
    const Vec3 axis = g.p1 - g.p0;
    const float len = length(axis);
    const Vec3 d = len > 0.0f ? axis / len : vec3(0.0f, 0.0f, 1.0f);
    *tangent = d;
    const float sin_b = len > 0.0f ? clampf((g.r0 - g.r1) / len, -0.999999f, 0.999999f) : 0.0f;
    const float cos_b = sqrtf(1.0f - sin_b * sin_b);
    const Vec3 q = x - g.p0;
    const float s = dot(q, d);
    const Vec3 radial = q - d * s;
    const float rho = length(radial);
    const float u = len > 0.0f ? clampf((s - rho * sin_b / cos_b) / len, 0.0f, 1.0f) : 0.0f;
    Vec3 n = x - (g.p0 + axis * u);
    const float nl = length(n);
    if (nl > 0.0f && is_finite(n)) return n / nl;
    return rho > 0.0f ? radial / rho : Frame::from_normal(d).s;  // on the axis: any normal
}

}  // namespace lantern
