// The strand query every ray-query structure without Embree runs (host+device): the scene's
// strands (scene/curves.h) per kind of ray in the built-in curve BVH (accel/curve_bvh.h), and
// each strand set that moves with its object (CurveSetMotion) behind a box over the shutter,
// entered through its matrix at the ray's time in its exported frame. On the CPU
// backend/cpu/curve_accel.cpp calls it over host arrays (accel/curve_query_build.h builds
// them); the CUDA backend over the same arrays copied to the device (curve_query_copied).
// Hits are entries only (accel/curve_hit.h), tmin < t <= tmax, as the triangle BVH's.
#pragma once

#include "accel/curve_bvh.h"
#include "scene/motion.h"

namespace lantern {

// Kinds of ray, as the curve structures split them: 0 camera, 1 indirect, 2 shadow.
constexpr int kCurveKinds = 3;

// A strand set moving with its object: its segments in its exported frame, one BVH per kind.
struct CurveMovingSet {
    ObjectMotion o;  // the set's CurveSetMotion::o (o.tri_begin: its first segment)
    Vec3 lo, hi;     // world bounds over the shutter (motion_world_box)
    CurveBvhView bvh[kCurveKinds];
};

struct CurveQueryView {
    CurveBvhView bvh[kCurveKinds];  // still strands; only bvh[0] where distinct is 1
    const CurveMovingSet* moving = nullptr;
    int32_t num_moving = 0;
    int32_t distinct = 1;  // 1: every kind of ray sees every strand (bvh[0] alone), else 3
    int32_t first_prim = 0;  // SceneView::num_triangles: a hit's prim is first_prim + seg
    int32_t num_segs = 0;    // 0: no strands (nothing to ask)
    MotionView motion;       // the scene's steps (the moving sets' matrices)
};

// kind: 0 camera, 1 indirect, 2 shadow -> the structure that kind of ray sees
LANTERN_HD inline int curve_query_kind(const CurveQueryView& q, int kind) {
    return q.distinct == 1 ? 0 : kind;
}

// The nearest hit of r on the moving sets closer than tmax (any_hit: the first found).
LANTERN_HD inline CurveBvhHit curve_query_moving(const CurveQueryView& q, const Ray& r, int ki,
                                                 float tmax, bool any_hit) {
    CurveBvhHit best{tmax, 0.0f, vec3(0.0f), -1};
    if (q.num_moving == 0) return best;
    const Vec3 inv = vec3(curve_bvh_rcp(r.d.x), curve_bvh_rcp(r.d.y), curve_bvh_rcp(r.d.z));
    for (int32_t j = 0; j < q.num_moving; ++j) {
        const CurveMovingSet& m = q.moving[j];
        if (m.bvh[ki].num_nodes == 0 ||
            !(curve_bvh_box(r.o, inv, m.lo, m.hi, r.tmin, best.t) < kInf))
            continue;
        // the ray in the set's exported frame at its time (the same t: an affine map)
        Transform x;
        if (!object_motion_to_exported(q.motion, m.o, r.time, &x)) continue;
        const CurveBvhHit h = curve_bvh_intersect(m.bvh[ki], x.point(r.o), x.vector(r.d),
                                                  r.tmin, best.t, any_hit, r.time);
        if (h.seg < 0) continue;
        best = h;
        if (any_hit) break;
    }
    return best;
}

// The nearest strand hit of r closer than tmax for kind (0 camera, 1 indirect, 2 shadow);
// seg -1: none.
LANTERN_HD inline CurveBvhHit curve_query_closest(const CurveQueryView& q, const Ray& r,
                                                  int kind, float tmax) {
    const int ki = curve_query_kind(q, kind);
    CurveBvhHit c = curve_bvh_intersect(q.bvh[ki], r.o, r.d, r.tmin, tmax, false, r.time);
    const CurveBvhHit m = curve_query_moving(q, r, ki, c.seg >= 0 ? c.t : tmax, false);
    return m.seg >= 0 ? m : c;
}

// Whether a strand that kind of ray sees lies on r within (tmin, tmax].
LANTERN_HD inline bool curve_query_occluded(const CurveQueryView& q, const Ray& r, int kind = 2) {
    const int ki = curve_query_kind(q, kind);
    return curve_bvh_intersect(q.bvh[ki], r.o, r.d, r.tmin, r.tmax, true, r.time).seg >= 0 ||
           curve_query_moving(q, r, ki, r.tmax, true).seg >= 0;
}

}  // namespace lantern
