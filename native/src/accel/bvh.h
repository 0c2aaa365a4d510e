// The GPU backend's BVH: flat binary nodes that hold both children's boxes (one 64-byte fetch
// tests two boxes), leaves that index a reordered triangle array, and host+device traversal
// (closest hit, any hit) with a fixed stack and the watertight ray-triangle test of Woop et al.
// Hits follow Embree: tmin < t <= tmax, uv = barycentrics of vertices 1 and 2. The builder is
// accel/bvh_builder.h; docs/bvh.md explains the choices.
#pragma once

#include <cstdint>

#include "core/math.h"
#include "scene/alpha.h"
#include "scene/scene_view.h"

namespace lantern {

// One inner node: the boxes of its two children, laid out as three float4 (x and y of child 0,
// x and y of child 1, z of both) plus one int4 of links, so a GPU thread reads a node with four
// 16-byte loads (Aila & Laine 2009). A child is an inner node (count 0: child = node index) or a
// leaf (child = first triangle in BvhView::tris, count of them).
struct alignas(16) BvhNode {
    float xy0[4];  // child 0: lo.x, hi.x, lo.y, hi.y
    float xy1[4];  // child 1: lo.x, hi.x, lo.y, hi.y
    float z01[4];  // lo.z, hi.z of child 0, lo.z, hi.z of child 1
    int32_t child[2];
    uint32_t meta[2];  // low 24 bits: leaf triangle count (0: inner); high 8: child mask
};
static_assert(sizeof(BvhNode) == 64, "BvhNode must stay 64 bytes");

// Child mask (meta >> 24): the OR of TriangleFlags over the child's subtree, plus kBvhNonEmpty.
// A ray that needs flags `need` enters a child only if (mask & (need | kBvhNonEmpty)) is all of
// them, and accepts a triangle only if (flags & need) == need.
constexpr uint32_t kBvhNonEmpty = 0x80u;
constexpr uint32_t kBvhCountMask = 0x00FFFFFFu;

// A triangle in leaf order: its vertices, its index in the scene and its TriangleFlags.
struct alignas(16) BvhTri {
    Vec3 v0;
    int32_t prim;
    Vec3 v1;
    uint32_t flags;
    Vec3 v2;
    float pad;
};
static_assert(sizeof(BvhTri) == 48, "BvhTri must stay 48 bytes");

// What traversal needs: host or device pointers. num_nodes == 0: an empty scene (every ray misses).
struct BvhView {
    const BvhNode* nodes = nullptr;
    const BvhTri* tris = nullptr;
    int32_t num_nodes = 0;
    int32_t num_tris = 0;
};

// Flags a ray kind needs (cf. EmbreeAccel's per-kind structures): camera rays see only
// kVisibleCamera triangles, shadow rays only kCastShadow ones, indirect rays everything.
constexpr uint32_t kBvhNeedCamera = kVisibleCamera;
constexpr uint32_t kBvhNeedShadow = kCastShadow;
constexpr uint32_t kBvhNeedIndirect = 0;

// The stack holds at most depth - 1 entries; the builder keeps the depth at or below this.
constexpr int kBvhStackSize = 64;

struct BvhHit {
    float t;       // ray.tmax on a miss
    int32_t prim;  // scene triangle index, -1 for a miss
    Vec2 uv;       // barycentrics of vertices 1 and 2 (Embree's u, v)
};

// Per-ray constants: reciprocal direction (zero components replaced by +-1e-18, as Embree's
// rcp_safe, so 0 * inf never makes a NaN) and the shear of the watertight test.
struct BvhRay {
    Vec3 o, d, inv;
    float tmin, tmax;
    int kx, ky, kz;
    float sx, sy, sz;
};

// min/max as compares: one instruction on both sides (GCC calls libm for fminf without
// -ffinite-math-only). Inputs are never NaN for finite rays: boxes are finite, inv has no inf.
LANTERN_HD inline float bvh_min(float a, float b) {
    return a < b ? a : b;
}
LANTERN_HD inline float bvh_max(float a, float b) {
    return a > b ? a : b;
}

LANTERN_HD inline float bvh_safe_rcp(float v) {
    return 1.0f / (fabsf(v) < 1e-18f ? copysignf(1e-18f, v) : v);
}

LANTERN_HD inline BvhRay bvh_ray(const Ray& r) {
    BvhRay b;
    b.o = r.o;
    b.d = r.d;
    b.inv = {bvh_safe_rcp(r.d.x), bvh_safe_rcp(r.d.y), bvh_safe_rcp(r.d.z)};
    b.tmin = r.tmin;
    b.tmax = r.tmax;
    float ax = fabsf(r.d.x), ay = fabsf(r.d.y), az = fabsf(r.d.z);
    b.kz = (ax > ay) ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
    b.kx = b.kz == 2 ? 0 : b.kz + 1;
    b.ky = b.kx == 2 ? 0 : b.kx + 1;
    if (r.d[b.kz] < 0.0f) {  // keep the winding, so U, V, W have one sign convention
        int k = b.kx;
        b.kx = b.ky;
        b.ky = k;
    }
    b.sx = r.d[b.kx] / r.d[b.kz];
    b.sy = r.d[b.ky] / r.d[b.kz];
    b.sz = 1.0f / r.d[b.kz];
    return b;
}

// A product that is never fused into a multiply-add: nvcc contracts a * b - c * d into an FMA
// by default, and a fused edge function is no longer the exact negation of the neighbouring
// triangle's, so a ray through a shared edge could miss both. (The host build has no FMA.)
LANTERN_HD inline float bvh_mul(float a, float b) {
#ifdef __CUDA_ARCH__
    return __fmul_rn(a, b);
#else
    return a * b;
#endif
}

// ---- Watertight ray-triangle test [Woop, Benthin, Wald 2013, "Watertight Ray/Triangle
// Intersection", JCGT 2(1), fig. 6] ----
// Accepts tmin < t <= tmax. Edges shared by two triangles are hit by exactly one or both, never
// neither; an edge function that rounds to exactly zero is recomputed in double, as the paper does.
LANTERN_HD inline bool bvh_hit_triangle(const BvhRay& r, const BvhTri& tri, float tmax,
                                        float* t_out, float* u_out, float* v_out) {
    Vec3 a = tri.v0 - r.o, b = tri.v1 - r.o, c = tri.v2 - r.o;
    float ax = a[r.kx] - bvh_mul(r.sx, a[r.kz]), ay = a[r.ky] - bvh_mul(r.sy, a[r.kz]);
    float bx = b[r.kx] - bvh_mul(r.sx, b[r.kz]), by = b[r.ky] - bvh_mul(r.sy, b[r.kz]);
    float cx = c[r.kx] - bvh_mul(r.sx, c[r.kz]), cy = c[r.ky] - bvh_mul(r.sy, c[r.kz]);
    float u = bvh_mul(cx, by) - bvh_mul(cy, bx);  // weight of v0
    float v = bvh_mul(ax, cy) - bvh_mul(ay, cx);  // weight of v1
    float w = bvh_mul(bx, ay) - bvh_mul(by, ax);  // weight of v2
    if (u == 0.0f || v == 0.0f || w == 0.0f) {
        u = float(double(cx) * double(by) - double(cy) * double(bx));
        v = float(double(ax) * double(cy) - double(ay) * double(cx));
        w = float(double(bx) * double(ay) - double(by) * double(ax));
    }
    if ((u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f)) return false;
    float det = u + v + w;
    if (det == 0.0f) return false;
    float az = r.sz * a[r.kz], bz = r.sz * b[r.kz], cz = r.sz * c[r.kz];
    float tt = u * az + v * bz + w * cz;
    float rcp = 1.0f / det;
    float t = tt * rcp;
    if (!(t > r.tmin && t <= tmax)) return false;  // also rejects NaN
    *t_out = t;
    *u_out = v * rcp;
    *v_out = w * rcp;
    return true;
}

// ---- Box test ----
// Both children at once. Embree's robust slab test: the entry distance is rounded down and the
// exit up by 2 ulps, so a ray that truly touches a box is never culled by rounding (flat boxes
// of axis-aligned walls included). Returns a 2-bit mask; d0, d1 receive the entry distances.
LANTERN_HD inline int bvh_hit_boxes(const BvhRay& r, const BvhNode& n, float tmax, float* d0,
                                    float* d1) {
    constexpr float kDown = 1.0f - 2.0f * 5.9604645e-8f, kUp = 1.0f + 2.0f * 5.9604645e-8f;
    float lx0 = (n.xy0[0] - r.o.x) * r.inv.x, hx0 = (n.xy0[1] - r.o.x) * r.inv.x;
    float ly0 = (n.xy0[2] - r.o.y) * r.inv.y, hy0 = (n.xy0[3] - r.o.y) * r.inv.y;
    float lz0 = (n.z01[0] - r.o.z) * r.inv.z, hz0 = (n.z01[1] - r.o.z) * r.inv.z;
    float lx1 = (n.xy1[0] - r.o.x) * r.inv.x, hx1 = (n.xy1[1] - r.o.x) * r.inv.x;
    float ly1 = (n.xy1[2] - r.o.y) * r.inv.y, hy1 = (n.xy1[3] - r.o.y) * r.inv.y;
    float lz1 = (n.z01[2] - r.o.z) * r.inv.z, hz1 = (n.z01[3] - r.o.z) * r.inv.z;
    float n0 =
        bvh_max(bvh_max(bvh_min(lx0, hx0), bvh_min(ly0, hy0)), bvh_max(bvh_min(lz0, hz0), r.tmin));
    float f0 =
        bvh_min(bvh_min(bvh_max(lx0, hx0), bvh_max(ly0, hy0)), bvh_min(bvh_max(lz0, hz0), tmax));
    float n1 =
        bvh_max(bvh_max(bvh_min(lx1, hx1), bvh_min(ly1, hy1)), bvh_max(bvh_min(lz1, hz1), r.tmin));
    float f1 =
        bvh_min(bvh_min(bvh_max(lx1, hx1), bvh_max(ly1, hy1)), bvh_min(bvh_max(lz1, hz1), tmax));
    *d0 = n0 * kDown;
    *d1 = n1 * kDown;
    return (n0 * kDown <= f0 * kUp ? 1 : 0) | (n1 * kDown <= f1 * kUp ? 2 : 0);
}

LANTERN_HD inline bool bvh_child_wanted(uint32_t meta, uint32_t need) {
    uint32_t want = need | kBvhNonEmpty;
    return ((meta >> 24) & want) == want;
}

// ---- Traversal ----
// Depth-first, nearer child first; a leaf child is intersected at once, the farther inner child
// goes on the stack with its entry distance, and popped entries beyond the closest hit are
// dropped. any_hit: return at the first accepted triangle (occlusion). A triangle flagged
// kAlphaTested counts only where accept(prim, u, v) says so (scene/alpha.h).
struct BvhAcceptAll {
    LANTERN_HD bool operator()(int32_t, float, float) const { return true; }
};
// The triangle a leaf's entry stands for: itself (a deforming mesh's is placed at the ray's
// time instead: tlas.h).
struct BvhTriAsStored {
    LANTERN_HD const BvhTri& operator()(const BvhTri& t) const { return t; }
};
// What a traversal does with an accepted triangle before it counts as a hit: nothing (every
// query but one); accel/boundary_hits.h's collector passes over volume boundaries (pass()
// true: recorded, the traversal goes on).
struct BvhNoCollect {
    static constexpr bool kOn = false;
    LANTERN_HD bool pass(uint32_t, int32_t, float, float, float) const { return false; }
};

//
// The stack: stack_node, and for a closest-hit query stack_dist (the pending entries' entry
// distances, dropped at the pop beyond the closest hit so far). An any-hit query's ray never
// shortens before it returns, so its entries are culled at the push instead, against the same
// tmax, and it keeps no distances: the same nodes in the same order, half the stack (the CUDA
// backend's kernels hold it in their frames, docs/cuda_backend.md "Strands and motion blur").
//
// bvh_walk is the walk both levels share (bvh_traverse_on below, tlas_traverse in tlas.h): the
// nodes, the order, the stack; a leaf child's entries [begin, begin + count) are handed to
// leaf(begin, count, sp, tmax, hit) at once, which may shorten tmax and set hit, and returns
// true where an any-hit query is done (sp: the entries pending on the stack, tlas.h's bottom
// level continuing above them).
template <bool kAnyHit, typename Leaf>
LANTERN_HD inline BvhHit bvh_walk(const BvhNode* nodes, const BvhRay& r, uint32_t need,
                                  float tmax, int32_t* stack_node, float* stack_dist,
                                  const Leaf& leaf) {
    BvhHit hit{tmax, -1, {0.0f, 0.0f}};
    int sp = 0;
    int32_t cur = 0;
    for (;;) {
        const BvhNode& n = nodes[cur];
        float d[2];
        int mask = bvh_hit_boxes(r, n, tmax, &d[0], &d[1]);
        if (!bvh_child_wanted(n.meta[0], need)) mask &= ~1;
        if (!bvh_child_wanted(n.meta[1], need)) mask &= ~2;
        int first = (mask == 3 && d[1] < d[0]) ? 1 : 0;
        int32_t next = -1;
        for (int k = 0; k < 2; ++k) {
            int c = first ^ k;
            if (!(mask & (1 << c))) continue;
            if (k == 1 && d[c] > tmax) continue;  // the nearer leaf may have shortened the ray
            uint32_t count = n.meta[c] & kBvhCountMask;
            if (count == 0) {  // inner child: descend into the nearer, push the farther
                if (next < 0) {
                    next = n.child[c];
                } else if (kAnyHit) {
                    if (d[c] <= tmax) stack_node[sp++] = n.child[c];
                } else {
                    stack_node[sp] = n.child[c];
                    stack_dist[sp] = d[c];
                    ++sp;
                }
                continue;
            }
            if (leaf(n.child[c], count, sp, tmax, hit)) return hit;
        }
        if (next < 0) {
            if (kAnyHit) {
                if (sp == 0) return hit;
                next = stack_node[--sp];
            } else {
                while (sp > 0) {
                    --sp;
                    if (stack_dist[sp] <= tmax) {
                        next = stack_node[sp];
                        break;
                    }
                }
                if (next < 0) return hit;
            }
        }
        cur = next;
    }
}

// A bottom level's leaf: its triangles, each tested against the ray shortened so far.
template <bool kAnyHit, typename Accept, typename TriAt, typename Collect>
struct BvhTriLeaf {
    const BvhView& bvh;
    const BvhRay& r;
    uint32_t need;
    const Accept& accept;
    const TriAt& tri_at;
    const Collect& collect;
    LANTERN_HD bool operator()(int32_t begin, uint32_t count, int, float& tmax,
                               BvhHit& hit) const {
        for (int32_t i = begin; i < begin + int32_t(count); ++i) {
            const BvhTri& tri = tri_at(bvh.tris[i]);
            if ((tri.flags & need) != need) continue;
            float t, u, v;
            if (!bvh_hit_triangle(r, tri, tmax, &t, &u, &v)) continue;
            if ((tri.flags & kAlphaTested) && !accept(tri.prim, u, v)) continue;
            if (Collect::kOn && collect.pass(tri.flags, tri.prim, t, u, v)) continue;
            hit = {t, tri.prim, {u, v}};
            if (kAnyHit) return true;
            tmax = t;
        }
        return false;
    }
};

// bvh_traverse_on walks on a stack the caller holds (tlas.h: the bottom level continues on the
// top level's), of at least the tree's depth - 1 entries (stack_dist unused for kAnyHit).
template <bool kAnyHit, typename Accept, typename TriAt, typename Collect>
LANTERN_HD inline BvhHit bvh_traverse_on(const BvhView& bvh, const Ray& ray, uint32_t need,
                                         const Accept& accept, const TriAt& tri_at,
                                         const Collect& collect, int32_t* stack_node,
                                         float* stack_dist) {
    if (bvh.num_nodes == 0) return BvhHit{ray.tmax, -1, {0.0f, 0.0f}};
    const BvhRay r = bvh_ray(ray);
    const BvhTriLeaf<kAnyHit, Accept, TriAt, Collect> leaf{bvh, r, need, accept, tri_at, collect};
    return bvh_walk<kAnyHit>(bvh.nodes, r, need, ray.tmax, stack_node, stack_dist, leaf);
}

template <bool kAnyHit, typename Accept = BvhAcceptAll, typename TriAt = BvhTriAsStored,
          typename Collect = BvhNoCollect>
LANTERN_HD inline BvhHit bvh_traverse(const BvhView& bvh, const Ray& ray, uint32_t need,
                                      const Accept& accept = Accept(),
                                      const TriAt& tri_at = TriAt(),
                                      const Collect& collect = Collect()) {
    int32_t stack_node[kBvhStackSize];
    float stack_dist[kAnyHit ? 1 : kBvhStackSize];
    return bvh_traverse_on<kAnyHit>(bvh, ray, need, accept, tri_at, collect, stack_node,
                                    stack_dist);
}

// Closest hit of `ray` in (tmin, tmax] among triangles with all of `need`'s flags.
template <typename Accept = BvhAcceptAll>
LANTERN_HD inline BvhHit bvh_intersect(const BvhView& bvh, const Ray& ray, uint32_t need,
                                       const Accept& accept = Accept()) {
    return bvh_traverse<false>(bvh, ray, need, accept);
}

// Whether any triangle with `need`'s flags lies on the segment (tmin, tmax].
template <typename Accept = BvhAcceptAll>
LANTERN_HD inline bool bvh_occluded(const BvhView& bvh, const Ray& ray,
                                    uint32_t need = kBvhNeedShadow,
                                    const Accept& accept = Accept()) {
    return bvh_traverse<true>(bvh, ray, need, accept).prim >= 0;
}

// The scene's stochastic alpha test as a BVH accept functor: bvh_intersect(bvh, ray, need,
// BvhAlphaTest{scene, ray}).
struct BvhAlphaTest {
    const SceneView& s;
    const Ray& ray;
    LANTERN_HD bool operator()(int32_t prim, float u, float v) const {
        return alpha_stops(s, prim, Vec2{u, v}, ray.o, ray.d);
    }
};

}  // namespace lantern
