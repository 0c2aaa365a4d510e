// A ray against everything the built-in structures hold (host+device): the triangles through
// the one-level BVH (accel/bvh.h) or, where meshes move (motion blur), the two-level one
// (accel/tlas.h: moving instances, deformation), then the strands (accel/curve_query.h) with
// the ray cut at the triangles' hit, so that the nearer wins: what CpuBackend does with
// BvhAccel and CurveAccel's built-in path, composed once for the CUDA executor
// (backend/cuda/cuda_exec.cuh), whose copies of these arrays accel/scene_query_build.h makes.
// tests/cpp/test_scene_query.cpp checks it against CpuBackend (LANTERN_ACCEL=bvh) on the CPU.
#pragma once

#include "accel/bvh.h"
#include "accel/curve_query.h"
#include "accel/tlas.h"

namespace lantern {

// What a scene's rays meet besides the one-level BVH (the CUDA executor holds it on the device
// and its ray queries a pointer to it: null, the one-level BVH alone).
struct SceneQueryView {
    int32_t two_level = 0;  // 1: the triangles are tlas's (the one-level BVH is empty)
    TlasView tlas;
    CurveQueryView curves;  // curves.num_segs 0: no strands
};

// kind: 0 camera, 1 indirect, 2 shadow (the strands' split, curve_query.h); need: the
// triangles' (kBvhNeed*). A strand hit: prim first_prim + segment, uv (u along it, 0).
template <typename Accept = BvhAcceptAll>
LANTERN_HD inline BvhHit scene_query_closest(const BvhView& bvh, const SceneQueryView* x,
                                             const Ray& r, int kind, uint32_t need,
                                             const Accept& accept = Accept()) {
    if (!x) return bvh_intersect(bvh, r, need, accept);
    BvhHit h = x->two_level ? tlas_intersect(x->tlas, r, need, accept)
                            : bvh_intersect(bvh, r, need, accept);
    if (x->curves.num_segs > 0) {
        const float tmax = h.prim >= 0 ? h.t : r.tmax;
        if (tmax > r.tmin) {
            const CurveBvhHit c = curve_query_closest(x->curves, r, kind, tmax);
            if (c.seg >= 0) h = BvhHit{c.t, x->curves.first_prim + c.seg, {c.u, 0.0f}};
        }
    }
    return h;
}

template <typename Accept = BvhAcceptAll>
LANTERN_HD inline bool scene_query_occluded(const BvhView& bvh, const SceneQueryView* x,
                                            const Ray& r, int kind, uint32_t need,
                                            const Accept& accept = Accept()) {
    if (!x) return bvh_occluded(bvh, r, need, accept);
    if (x->two_level ? tlas_occluded(x->tlas, r, need, accept)
                     : bvh_occluded(bvh, r, need, accept))
        return true;
    return x->curves.num_segs > 0 && curve_query_occluded(x->curves, r, kind);
}

}  // namespace lantern
