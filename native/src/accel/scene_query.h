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

// The composition over its parts (p: flat / tlas closest and any-hit, the strands' closest and
// any-hit), so that a device build can make each part a call of its own (cuda_exec.cuh: inlined
// at every query site, the traversals' stacks add up in a stage's frame).
// kind: 0 camera, 1 indirect, 2 shadow (the strands' split, curve_query.h); need: the
// triangles' (kBvhNeed*). A strand hit: prim first_prim + segment, uv (u along it, 0).
template <typename Parts>
LANTERN_HD inline BvhHit scene_query_closest_parts(const SceneQueryView& x, const Ray& r, int kind,
                                                   uint32_t need, const Parts& p) {
    BvhHit h = x.two_level ? p.tlas(x.tlas, r, need) : p.flat(r, need);
    if (x.curves.num_segs > 0) {
        const float tmax = h.prim >= 0 ? h.t : r.tmax;
        if (tmax > r.tmin) {
            const CurveBvhHit c = p.curve(x.curves, r, kind, tmax);
            if (c.seg >= 0) h = BvhHit{c.t, x.curves.first_prim + c.seg, {c.u, 0.0f}};
        }
    }
    return h;
}

template <typename Parts>
LANTERN_HD inline bool scene_query_occluded_parts(const SceneQueryView& x, const Ray& r, int kind,
                                                  uint32_t need, const Parts& p) {
    if (x.two_level ? p.tlas_any(x.tlas, r, need) : p.flat_any(r, need)) return true;
    return x.curves.num_segs > 0 && p.curve_any(x.curves, r, kind);
}

// The parts inlined, with an accept functor (the alpha test).
template <typename Accept>
struct SceneQueryInline {
    const BvhView& bvh;
    const Accept& accept;
    LANTERN_HD BvhHit flat(const Ray& r, uint32_t need) const {
        return bvh_intersect(bvh, r, need, accept);
    }
    LANTERN_HD bool flat_any(const Ray& r, uint32_t need) const {
        return bvh_occluded(bvh, r, need, accept);
    }
    LANTERN_HD BvhHit tlas(const TlasView& tl, const Ray& r, uint32_t need) const {
        return tlas_intersect(tl, r, need, accept);
    }
    LANTERN_HD bool tlas_any(const TlasView& tl, const Ray& r, uint32_t need) const {
        return tlas_occluded(tl, r, need, accept);
    }
    LANTERN_HD CurveBvhHit curve(const CurveQueryView& q, const Ray& r, int kind, float tmax) const {
        return curve_query_closest(q, r, kind, tmax);
    }
    LANTERN_HD bool curve_any(const CurveQueryView& q, const Ray& r, int kind) const {
        return curve_query_occluded(q, r, kind);
    }
};

// x null: the one-level BVH alone.
template <typename Accept = BvhAcceptAll>
LANTERN_HD inline BvhHit scene_query_closest(const BvhView& bvh, const SceneQueryView* x,
                                             const Ray& r, int kind, uint32_t need,
                                             const Accept& accept = Accept()) {
    if (!x) return bvh_intersect(bvh, r, need, accept);
    return scene_query_closest_parts(*x, r, kind, need, SceneQueryInline<Accept>{bvh, accept});
}

template <typename Accept = BvhAcceptAll>
LANTERN_HD inline bool scene_query_occluded(const BvhView& bvh, const SceneQueryView* x,
                                            const Ray& r, int kind, uint32_t need,
                                            const Accept& accept = Accept()) {
    if (!x) return bvh_occluded(bvh, r, need, accept);
    return scene_query_occluded_parts(*x, r, kind, need, SceneQueryInline<Accept>{bvh, accept});
}

}  // namespace lantern
