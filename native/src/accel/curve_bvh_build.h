// Host-only builder of the curve BVH (accel/curve_bvh.h): segments from strands (points, a radius
// per point, strand offsets), then median splits on the longest axis of the centroids' bounds
// down to leaves of at most kCurveLeaf segments, so the depth stays at 30 or less for any int32
// count (curve_bvh_depth_bound), within the traversal's stack (kCurveBvhStack); a tree deeper
// than that would be a builder fault, refused at the build with a clear error.
// Segments whose radii are not finite and >= 0 (or both 0) are left out (they have no surface).
#pragma once

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "accel/curve_bvh.h"

namespace lantern {

constexpr int kCurveLeaf = 4;

// The depth (in nodes, the root 1) of the median-split tree over n segments: halves (the larger
// one, ceil) down to a leaf of kCurveLeaf.
constexpr int curve_bvh_depth_bound(int64_t n) {
    return n <= kCurveLeaf ? 1 : 1 + curve_bvh_depth_bound(n - n / 2);
}
// a traversal's stack holds at most depth - 1 entries (one per inner ancestor)
static_assert(curve_bvh_depth_bound(INT32_MAX) - 1 <= kCurveBvhStack,
              "the curve BVH's traversal stack must hold the deepest tree the builder makes");

struct CurveBvh {
    std::vector<CurveBvhNode> nodes;
    std::vector<CurveSeg> segs;
    CurveKeys keys;  // the scene's (not owned): moving segments' steps
    int depth = 0;   // in nodes (the root 1; 0: empty)
    CurveBvhView view() const {
        return CurveBvhView{nodes.data(), segs.data(), int32_t(nodes.size()), keys};
    }
};

inline std::vector<CurveSeg> curve_segments(const float* points, const float* radius,
                                            const int32_t* offsets, int num_strands) {
    std::vector<CurveSeg> out;
    for (int s = 0; s < num_strands; ++s)
        for (int32_t i = offsets[s]; i + 1 < offsets[s + 1]; ++i) {
            CurveSeg g;
            g.p0 = vec3(points[3 * i], points[3 * i + 1], points[3 * i + 2]);
            g.p1 = vec3(points[3 * i + 3], points[3 * i + 4], points[3 * i + 5]);
            g.r0 = radius[i];
            g.r1 = radius[i + 1];
            g.index = i;  // the segment's first point
            if (!(g.r0 >= 0.0f && g.r1 >= 0.0f && g.r0 + g.r1 > 0.0f && is_finite(g.r0 + g.r1)) ||
                !is_finite(g.p0) || !is_finite(g.p1))
                continue;
            // joined to the previous segment of the strand (kept, consecutive points)
            if (!out.empty() && out.back().index == i - 1 && i > offsets[s]) {
                g.flags |= kCurveJoinStart;
                out.back().flags |= kCurveJoinEnd;
            }
            out.push_back(g);
        }
    return out;
}

inline void curve_seg_bounds(const CurveSeg& g, Vec3* lo, Vec3* hi) {
    *lo = vec3(fminf(g.p0.x - g.r0, g.p1.x - g.r1), fminf(g.p0.y - g.r0, g.p1.y - g.r1),
               fminf(g.p0.z - g.r0, g.p1.z - g.r1));
    *hi = vec3(fmaxf(g.p0.x + g.r0, g.p1.x + g.r1), fmaxf(g.p0.y + g.r0, g.p1.y + g.r1),
               fmaxf(g.p0.z + g.r0, g.p1.z + g.r1));
}

// A segment's box over the shutter: the union of its boxes at every step where it moves (a
// lerped segment's end spheres stay within the hull of the two steps' spheres: exact bounds).
inline void curve_seg_bounds(const CurveSeg& g, const CurveKeys& k, Vec3* lo, Vec3* hi) {
    curve_seg_bounds(g, lo, hi);
    if (!(g.flags & kCurveMoves) || k.num_steps < 2) return;
    for (int s = 0; s < k.num_steps; ++s) {
        Vec3 a, b;
        curve_seg_bounds(k.keys[size_t(s) * size_t(k.num_segs) + size_t(g.index)], &a, &b);
        *lo = vec3(fminf(lo->x, a.x), fminf(lo->y, a.y), fminf(lo->z, a.z));
        *hi = vec3(fmaxf(hi->x, b.x), fmaxf(hi->y, b.y), fmaxf(hi->z, b.z));
    }
}

namespace detail {
inline void curve_bvh_node(CurveBvh& bvh, int32_t begin, int32_t end, int depth) {
    bvh.depth = std::max(bvh.depth, depth);
    const int32_t me = int32_t(bvh.nodes.size());
    bvh.nodes.push_back(CurveBvhNode{});
    Vec3 lo = vec3(kInf), hi = vec3(-kInf), clo = vec3(kInf), chi = vec3(-kInf);
    for (int32_t i = begin; i < end; ++i) {
        Vec3 a, b;
        curve_seg_bounds(bvh.segs[i], bvh.keys, &a, &b);
        lo = vec3(fminf(lo.x, a.x), fminf(lo.y, a.y), fminf(lo.z, a.z));
        hi = vec3(fmaxf(hi.x, b.x), fmaxf(hi.y, b.y), fmaxf(hi.z, b.z));
        const Vec3 c = (a + b) * 0.5f;
        clo = vec3(fminf(clo.x, c.x), fminf(clo.y, c.y), fminf(clo.z, c.z));
        chi = vec3(fmaxf(chi.x, c.x), fmaxf(chi.y, c.y), fmaxf(chi.z, c.z));
    }
    bvh.nodes[me].lo = lo;
    bvh.nodes[me].hi = hi;
    if (end - begin <= kCurveLeaf) {
        bvh.nodes[me].second = begin;
        bvh.nodes[me].count = end - begin;
        return;
    }
    const Vec3 ext = chi - clo;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    const int32_t mid = begin + (end - begin) / 2;
    auto centre = [axis](const CurveSeg& g) {
        return g.p0[axis] + g.p1[axis];
    };
    std::nth_element(bvh.segs.begin() + begin, bvh.segs.begin() + mid, bvh.segs.begin() + end,
                     [&](const CurveSeg& a, const CurveSeg& b) { return centre(a) < centre(b); });
    curve_bvh_node(bvh, begin, mid, depth + 1);
    const int32_t second = int32_t(bvh.nodes.size());
    curve_bvh_node(bvh, mid, end, depth + 1);
    bvh.nodes[me].second = second;
    bvh.nodes[me].count = 0;
}
}  // namespace detail

// A tree the traversal's fixed stack cannot walk (depth - 1 > kCurveBvhStack) is an error at
// the build, never an overflow at a query.
inline void curve_bvh_check_depth(int depth) {
    if (depth - 1 > kCurveBvhStack)
        throw std::length_error("curve BVH of depth " + std::to_string(depth) +
                                " is deeper than its traversal stack holds (kCurveBvhStack " +
                                std::to_string(kCurveBvhStack) + " entries)");
}

// keys: the scene's steps of the moving segments (their CurveSeg::index), bounded over all.
inline CurveBvh build_curve_bvh(std::vector<CurveSeg> segs, CurveKeys keys = {}) {
    CurveBvh bvh;
    bvh.segs = std::move(segs);
    bvh.keys = keys;
    if (bvh.segs.empty()) return bvh;
    bvh.nodes.reserve(2 * (bvh.segs.size() / kCurveLeaf + 1));
    detail::curve_bvh_node(bvh, 0, int32_t(bvh.segs.size()), 1);
    curve_bvh_check_depth(bvh.depth);
    return bvh;
}

}  // namespace lantern
