// The built-in BVH over round linear curve segments (accel/curve_hit.h), beside the triangle BVH:
// flat nodes in depth-first order (an inner node's first child follows it, `second` names the
// other), leaves that index a segment array in leaf order; host+device closest-hit and any-hit
// traversal with a fixed stack. Hits follow the triangle BVH: tmin < t <= tmax. The builder
// (host only) is accel/curve_bvh_build.h.
#pragma once

#include <cstdint>

#include "accel/curve_hit.h"

namespace lantern {

// One segment: its end points and radii, and its index in the scene's order. flags: which ends
// join a neighbouring segment of the same strand (kCurveJoinStart, kCurveJoinEnd); a joined end
// has no sphere of its own (as Embree's RTC_CURVE_FLAG_NEIGHBOR_*, which Cycles sets), so a ray
// leaving a strand through its side does not enter the next segment's end sphere at the joint.
struct CurveSeg {
    Vec3 p0;
    float r0;
    Vec3 p1;
    float r1;
    int32_t index;
    int32_t flags = 0;
};

struct CurveBvhNode {
    Vec3 lo;
    int32_t second;  // inner: the second child's node; leaf: the first segment
    Vec3 hi;
    int32_t count;   // 0: inner node; else the leaf's segment count
};

// Motion blur (docs/motion_blur.md "Strands"): the segments' keys at num_steps steps evenly
// spread over the shutter, step k of segment i (CurveSeg::index) at keys[k * num_segs + i]; a
// segment flagged kCurveMoves is the lerp of the two steps around the ray's time, the others
// are their CurveSeg as it is. num_steps < 2: nothing moves.
struct CurveKeys {
    const CurveSeg* keys = nullptr;
    int32_t num_steps = 0;
    int32_t num_segs = 0;
};

// Segment g (CurveSeg::index into the keys) at `time` in [0, 1]: its keys lerped (radii too),
// its index and flags kept; g itself where it does not move.
LANTERN_HD inline CurveSeg curve_seg_at(const CurveSeg& g, const CurveKeys& k, float time) {
    if (!(g.flags & kCurveMoves) || k.num_steps < 2) return g;
    const int n = k.num_steps;
    const float x = fminf(fmaxf(time, 0.0f), 1.0f) * float(n - 1);
    const int s = x >= float(n - 1) ? n - 2 : int(x);
    const float f = x - float(s), e = 1.0f - f;
    const CurveSeg& a = k.keys[size_t(s) * size_t(k.num_segs) + size_t(g.index)];
    const CurveSeg& b = k.keys[size_t(s + 1) * size_t(k.num_segs) + size_t(g.index)];
    CurveSeg out = g;
    out.p0 = a.p0 * e + b.p0 * f;
    out.p1 = a.p1 * e + b.p1 * f;
    out.r0 = a.r0 * e + b.r0 * f;
    out.r1 = a.r1 * e + b.r1 * f;
    return out;
}

struct CurveBvhView {
    const CurveBvhNode* nodes = nullptr;
    const CurveSeg* segs = nullptr;
    int32_t num_nodes = 0;
    CurveKeys keys;  // moving segments' steps (motion blur); num_steps 0: none
};

struct CurveBvhHit {
    float t;
    float u;
    Vec3 n;
    int32_t seg;  // CurveSeg::index, -1 for none
};

// The traversal's stack: at most a tree's depth - 1 entries. The builder's median splits to
// leaves of 4 give depth 30 for 2^31 segments (curve_bvh_build.h: curve_bvh_depth_bound, checked
// there with a static_assert, and each built tree's depth against it with a clear error), so
// 32 entries hold any tree; 128 B of a GPU thread's stack, 64 was twice what a tree needs.
constexpr int kCurveBvhStack = 32;

// Slab test of o + t w against [lo, hi], with inv = 1 / w; the entry distance or kInf.
LANTERN_HD inline float curve_bvh_box(Vec3 o, Vec3 inv, Vec3 lo, Vec3 hi, float tmin, float tmax) {
    const float tx0 = (lo.x - o.x) * inv.x, tx1 = (hi.x - o.x) * inv.x;
    const float ty0 = (lo.y - o.y) * inv.y, ty1 = (hi.y - o.y) * inv.y;
    const float tz0 = (lo.z - o.z) * inv.z, tz1 = (hi.z - o.z) * inv.z;
    const float t0 = fmaxf(fmaxf(fminf(tx0, tx1), fminf(ty0, ty1)), fmaxf(fminf(tz0, tz1), tmin));
    const float t1 = fminf(fminf(fmaxf(tx0, tx1), fmaxf(ty0, ty1)), fminf(fmaxf(tz0, tz1), tmax));
    return t0 <= t1 ? t0 : kInf;
}

LANTERN_HD inline float curve_bvh_rcp(float v) {
    return fabsf(v) > 1e-30f ? 1.0f / v : copysignf(1e30f, v);
}

// Closest hit (any_hit false) or the first hit found (any_hit true: shadow rays); a moving
// segment (kCurveMoves) is met as it is at `time` (the nodes bound it over every step).
LANTERN_HD inline CurveBvhHit curve_bvh_intersect(const CurveBvhView& bvh, Vec3 o, Vec3 w,
                                                  float tmin, float tmax, bool any_hit = false,
                                                  float time = 0.0f) {
    CurveBvhHit best{tmax, 0.0f, vec3(0.0f), -1};
    if (bvh.num_nodes == 0) return best;
    const Vec3 inv = vec3(curve_bvh_rcp(w.x), curve_bvh_rcp(w.y), curve_bvh_rcp(w.z));
    int32_t stack[kCurveBvhStack];
    int sp = 0;
    int32_t node = 0;
    for (;;) {
        const CurveBvhNode& n = bvh.nodes[node];
        if (curve_bvh_box(o, inv, n.lo, n.hi, tmin, best.t) < kInf) {
            if (n.count > 0) {
                for (int32_t k = 0; k < n.count; ++k) {
                    const CurveSeg& g = bvh.segs[n.second + k];
                    const CurveSeg s = (g.flags & kCurveMoves) ? curve_seg_at(g, bvh.keys, time)
                                                               : g;
                    CurveHit h;
                    if (curve_hit_segment(o, w, s.p0, s.r0, s.p1, s.r1, tmin, best.t, &h,
                                          s.flags)) {
                        best = CurveBvhHit{h.t, h.u, h.n, s.index};
                        if (any_hit) return best;
                    }
                }
            } else {  // the builder keeps the depth within the stack (curve_bvh_build.h)
                stack[sp++] = n.second;
                node = node + 1;
                continue;
            }
        }
        if (sp == 0) break;
        node = stack[--sp];
    }
    return best;
}

}  // namespace lantern
