// Two-level BVH (host+device): a top level over instances, each a bottom-level BVH (accel/bvh.h,
// one per mesh, built once) placed by a world-to-object transform. A ray enters an instance in
// its object space with the direction left unnormalised, so its t, and the hit's primitive and
// barycentrics, are the flattened scene's; shading reads the scene's world-space arrays as
// before. Moving an instance changes its transform and rebuilds only the top level (tlas_build.h).
#pragma once

#include "accel/bvh.h"
#include "scene/motion.h"

namespace lantern {

// One instance: world -> object (rows of a 3x4), the bottom level it places and its child mask
// (the OR of its triangles' flags | kBvhNonEmpty, or 0 when empty). identity: no transform.
// motion: its index in TlasView::motion.objects (motion blur, scene/motion.h), -1: to_object.
struct BvhInstance {
    float to_object[3][4];
    int32_t blas;
    int32_t identity;
    uint32_t mask;
    int32_t motion;
};

// Top-level nodes are BvhNodes whose leaves index leaf_inst (instance ids in leaf order).
struct TlasView {
    const BvhNode* nodes = nullptr;
    int32_t num_nodes = 0;
    const int32_t* leaf_inst = nullptr;
    const BvhInstance* instances = nullptr;
    const BvhView* blas = nullptr;  // bottom levels; their triangles carry scene triangle ids
    MotionView motion;              // moving instances' steps (scene/motion.h)
};

LANTERN_HD inline Ray tlas_object_ray(const BvhInstance& in, const Ray& r, float tmax,
                                      const MotionView& motion) {
    Ray o;
    o.tmin = r.tmin;
    o.tmax = tmax;
    if (in.identity) {
        o.o = r.o;
        o.d = r.d;
        return o;
    }
    const float(*m)[4] = in.to_object;
    Transform moved;  // a moving instance: world at the ray's time -> exported world
    if (in.motion >= 0) {
        if (!object_motion_to_exported(motion, motion.objects[in.motion], r.time, &moved)) {
            o.tmax = -1.0f;  // singular at this time: nothing to hit
            o.o = r.o;
            o.d = r.d;
            return o;
        }
        m = moved.m;
    }
    o.o = {m[0][0] * r.o.x + m[0][1] * r.o.y + m[0][2] * r.o.z + m[0][3],
           m[1][0] * r.o.x + m[1][1] * r.o.y + m[1][2] * r.o.z + m[1][3],
           m[2][0] * r.o.x + m[2][1] * r.o.y + m[2][2] * r.o.z + m[2][3]};
    o.d = {m[0][0] * r.d.x + m[0][1] * r.d.y + m[0][2] * r.d.z,
           m[1][0] * r.d.x + m[1][1] * r.d.y + m[1][2] * r.d.z,
           m[2][0] * r.d.x + m[2][1] * r.d.y + m[2][2] * r.d.z};
    return o;
}

// A deforming mesh's triangle at the ray's time (deformation blur, scene/motion.h).
struct BvhTriDeformed {
    const MotionView& mv;
    const DeformMesh& dm;
    float time;
    LANTERN_HD BvhTri operator()(const BvhTri& t) const {
        BvhTri o = t;
        Vec3 p[3];
        deform_triangle(mv, dm, t.prim, time, p);
        o.v0 = p[0];
        o.v1 = p[1];
        o.v2 = p[2];
        return o;
    }
};

// The top level's stack: its builder (median splits) stops at depth kTlasStackSize - 2, so 2^14
// leaves of kTlasLeaf (2) instances fit, and a scene of more than 32,768 instances has leaves
// of several (scanned in turn): the top level leaves at most kTlasStackSize entries pending
// (the CUDA backend's query, docs/cuda_backend.md "Strands and motion blur").
constexpr int kTlasStackSize = 16;
// One stack for both levels: the top level's pending entries below, the bottom level's above
// them, so a traversal holds kBvhStackSize entries (512 bytes for a closest hit, 256 for an
// any-hit one), not two stacks' 640. A bottom level may then use kBlasStackSize entries: its
// depth at most kBlasStackSize + 1 (build_tlas_scene guards it, tlas_build.cpp).
constexpr int kBlasStackSize = kBvhStackSize - kTlasStackSize;

// ---- Traversal ----
// The top level as bvh_traverse walks a BVH (bvh_walk: nearer child first, a fixed stack; an
// any-hit query culls at the push and keeps no distances); at a leaf each instance's bottom level
// is traversed with the ray shortened to the closest hit so far, on the same stack above the top
// level's entries. The accept functor sees the world-space ray's triangle (its ids are the
// scene's).
template <bool kAnyHit, typename Accept>
struct TlasLeaf {
    const TlasView& tl;
    const Ray& ray;
    uint32_t need;
    const Accept& accept;
    int32_t* stack_node;
    float* stack_dist;
    LANTERN_HD bool operator()(int32_t begin, uint32_t count, int sp, float& tmax,
                               BvhHit& hit) const {
        for (int32_t i = begin; i < begin + int32_t(count); ++i) {
            const BvhInstance& in = tl.instances[tl.leaf_inst[i]];
            if (!bvh_child_wanted(in.mask << 24, need)) continue;
            const Ray o = tlas_object_ray(in, ray, tmax, tl.motion);
            if (!(o.tmax >= o.tmin)) continue;
            const DeformMesh* dm =
                in.motion >= 0 ? deform_of(tl.motion, tl.motion.objects[in.motion]) : nullptr;
            int32_t* above = stack_node + sp;
            float* above_dist = kAnyHit ? stack_dist : stack_dist + sp;
            const BvhHit h =
                dm ? bvh_traverse_on<kAnyHit>(tl.blas[in.blas], o, need, accept,
                                              BvhTriDeformed{tl.motion, *dm, ray.time},
                                              BvhNoCollect(), above, above_dist)
                   : bvh_traverse_on<kAnyHit>(tl.blas[in.blas], o, need, accept,
                                              BvhTriAsStored(), BvhNoCollect(), above,
                                              above_dist);
            if (h.prim < 0) continue;
            hit = h;
            if (kAnyHit) return true;
            tmax = h.t;
        }
        return false;
    }
};

template <bool kAnyHit, typename Accept = BvhAcceptAll>
LANTERN_HD inline BvhHit tlas_traverse(const TlasView& tl, const Ray& ray, uint32_t need,
                                       const Accept& accept = Accept()) {
    if (tl.num_nodes == 0) return BvhHit{ray.tmax, -1, {0.0f, 0.0f}};
    int32_t stack_node[kBvhStackSize];  // [0, sp): the top level's; above: the bottom level's
    float stack_dist[kAnyHit ? 1 : kBvhStackSize];
    const TlasLeaf<kAnyHit, Accept> leaf{tl, ray, need, accept, stack_node, stack_dist};
    return bvh_walk<kAnyHit>(tl.nodes, bvh_ray(ray), need, ray.tmax, stack_node, stack_dist,
                             leaf);
}

template <typename Accept = BvhAcceptAll>
LANTERN_HD inline BvhHit tlas_intersect(const TlasView& tl, const Ray& ray, uint32_t need,
                                        const Accept& accept = Accept()) {
    return tlas_traverse<false>(tl, ray, need, accept);
}

template <typename Accept = BvhAcceptAll>
LANTERN_HD inline bool tlas_occluded(const TlasView& tl, const Ray& ray,
                                     uint32_t need = kBvhNeedShadow,
                                     const Accept& accept = Accept()) {
    return tlas_traverse<true>(tl, ray, need, accept).prim >= 0;
}

}  // namespace lantern
