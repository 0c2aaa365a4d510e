// A volume boundary (a material with a Volume and no Surface) drawn a hair inside its mesh.
//
// A fog box standing on a floor has its bottom face in the floor's plane. A ray reaching that
// plane finds both faces at one distance and the accelerator returns either. Where it returns the
// boundary, pt (and lt) cross it by restarting the ray past it (offset_ray_origin, a few ulps
// along the normal): past the floor's face too, so the ray goes on inside the floor's slab, and
// the floor renders dark in blotches (a Cycles comparison read 10 % dark, blocks at half). Cycles
// restarts at the hit point itself and skips only the primitive it left, so there the floor is
// found. Lantern's executors skip by distance, not by primitive; instead the boundary is moved
// inwards by a few times that offset, so no opaque face can lie between a boundary and a ray
// restarted from it, and the medium ends a fraction of a millimetre short of the floor (what a
// scene with the box lifted by that much renders, in Cycles as here).
//
// Moved: only a mesh with a boundary face that lies on another mesh's face (every vertex of a
// non-boundary triangle within kNear offsets of a boundary triangle's plane, their boxes
// overlapping), so media in the open keep their exact geometry (the analytic slab tests); of it
// the vertices that only volume-boundary triangles use (a mesh mixing surface and boundary faces
// keeps its shared vertices), along their angle-weighted normal, by a distance that takes every
// adjacent face plane inwards by at least kInset offsets (the largest offset at any of the
// mesh's moved vertices), and never more than 1e-3 of the mesh's extent.
#include <algorithm>
#include <cmath>
#include <vector>

#include "scene/scene.h"

namespace lantern {

namespace {

constexpr float kInset = 4.0f;  // offsets (core/offset.h) a boundary plane moves inwards
constexpr float kNear = 8.0f;   // offsets within which another face counts as on the boundary
// beyond this many (boundary x other) triangle pairs in one mesh's box the test is skipped and
// the mesh moved: the move is harmless, the test only keeps the geometry exact where it can
constexpr double kMaxPairs = 2e7;

// The largest distance offset_ray_origin moves a point at p along a unit normal, per component.
float offset_at(Vec3 p, float scale) {
    float o = 0.0f;
    for (float c : {p.x, p.y, p.z}) {
        const float a = std::fabs(c);
        // near the origin a fixed epsilon; else 256 ulps of the coordinate
        o = std::max(o, a < scale / 32.0f ? scale / 65536.0f : a * 256.0f * 0x1p-23f);
    }
    return o;
}

float angle_at(Vec3 a, Vec3 b, Vec3 c) {  // the triangle's angle at a
    const Vec3 u = b - a, v = c - a;
    const float lu = length(u), lv = length(v);
    if (!(lu > 0.0f) || !(lv > 0.0f)) return 0.0f;
    return std::acos(std::clamp(dot(u, v) / (lu * lv), -1.0f, 1.0f));
}

}  // namespace

bool HostScene::boundary_meets_a_face(const MeshRange& r, Vec3 lo, Vec3 hi, float eps,
                                      size_t ntri) const {
    auto tri_box = [&](size_t t, Vec3& a, Vec3& b) {
        a = vec3(kInf);
        b = vec3(-kInf);
        for (int k = 0; k < 3; ++k) {
            const Vec3 p = positions_[indices_[3 * t + size_t(k)]];
            a = {std::min(a.x, p.x), std::min(a.y, p.y), std::min(a.z, p.z)};
            b = {std::max(b.x, p.x), std::max(b.y, p.y), std::max(b.z, p.z)};
        }
    };
    auto overlaps = [&](Vec3 a0, Vec3 a1, Vec3 b0, Vec3 b1) {
        return a0.x <= b1.x + eps && b0.x <= a1.x + eps && a0.y <= b1.y + eps &&
               b0.y <= a1.y + eps && a0.z <= b1.z + eps && b0.z <= a1.z + eps;
    };
    // the other triangles (not this mesh's, not boundaries) near the mesh's box, with their boxes
    struct Near {
        size_t t;
        Vec3 lo, hi;
    };
    std::vector<Near> near;
    for (size_t t = 0; t < ntri; ++t) {
        if (tri_flags_[t] & kVolumeBoundary) continue;
        if (int(t) >= r.tri_begin && int(t) < r.tri_begin + r.tri_count) continue;
        Vec3 a, b;
        tri_box(t, a, b);
        if (overlaps(a, b, lo, hi)) near.push_back({t, a, b});
    }
    if (near.empty()) return false;
    if (double(near.size()) * double(r.tri_count) > kMaxPairs) return true;
    for (int bt = r.tri_begin; bt < r.tri_begin + r.tri_count; ++bt) {
        const size_t t = size_t(bt);
        if (!(tri_flags_[t] & kVolumeBoundary)) continue;
        const Vec3 p0 = positions_[indices_[3 * t]];
        Vec3 n = cross(positions_[indices_[3 * t + 1]] - p0, positions_[indices_[3 * t + 2]] - p0);
        const float l = length(n);
        if (!(l > 0.0f) || !std::isfinite(l)) continue;
        n = n * (1.0f / l);
        Vec3 a0, a1;
        tri_box(t, a0, a1);
        for (const Near& o : near) {
            if (!overlaps(a0, a1, o.lo, o.hi)) continue;
            bool on = true;
            for (int k = 0; k < 3 && on; ++k)
                on = std::fabs(dot(positions_[indices_[3 * o.t + size_t(k)]] - p0, n)) <= eps;
            if (on) return true;
        }
    }
    return false;
}

void HostScene::inset_volume_boundaries() {
    if (media_.empty() || tri_flags_.empty()) return;
    const size_t nv = positions_.size();
    // 1: used by a boundary triangle, 2: used by another
    std::vector<uint8_t> use(nv, 0);
    for (size_t t = 0; t < indices_.size() / 3; ++t) {  // triangles (not strands)
        const uint8_t bit = (tri_flags_[t] & kVolumeBoundary) ? 1 : 2;
        for (int k = 0; k < 3; ++k) use[indices_[3 * t + size_t(k)]] |= bit;
    }
    bool any = false;
    for (uint8_t u : use) any = any || u == 1;
    if (!any) return;
    // angle-weighted outward normals of the moved vertices, and each face's unit normal
    std::vector<Vec3> n(nv, vec3(0.0f));
    for (size_t t = 0; t < indices_.size() / 3; ++t) {  // triangles (not strands)
        if (!(tri_flags_[t] & kVolumeBoundary)) continue;
        const uint32_t i[3] = {indices_[3 * t], indices_[3 * t + 1], indices_[3 * t + 2]};
        const Vec3 p[3] = {positions_[i[0]], positions_[i[1]], positions_[i[2]]};
        const Vec3 ng = cross(p[1] - p[0], p[2] - p[0]);
        const float l = length(ng);
        if (!(l > 0.0f) || !std::isfinite(l)) continue;
        for (int k = 0; k < 3; ++k)
            if (use[i[k]] == 1)
                n[i[k]] = n[i[k]] + ng * (angle_at(p[k], p[(k + 1) % 3], p[(k + 2) % 3]) / l);
    }
    for (Vec3& v : n) {
        const float l = length(v);
        v = l > 0.0f && std::isfinite(l) ? v * (1.0f / l) : vec3(0.0f);
    }
    // per vertex the smallest cosine between its direction and an adjacent face's normal: a
    // move of d along the direction takes that face's plane in by d x cosine
    std::vector<float> cos_min(nv, 1.0f);
    for (size_t t = 0; t < indices_.size() / 3; ++t) {  // triangles (not strands)
        if (!(tri_flags_[t] & kVolumeBoundary)) continue;
        const uint32_t* i = &indices_[3 * t];
        const Vec3 ng = cross(positions_[i[1]] - positions_[i[0]], positions_[i[2]] - positions_[i[0]]);
        const float l = length(ng);
        if (!(l > 0.0f) || !std::isfinite(l)) continue;
        for (int k = 0; k < 3; ++k)
            if (use[i[k]] == 1) cos_min[i[k]] = std::min(cos_min[i[k]], dot(n[i[k]], ng * (1.0f / l)));
    }
    const size_t ntri = indices_.size() / 3;
    for (const MeshRange& r : mesh_ranges_) {
        Vec3 lo = vec3(kInf), hi = vec3(-kInf);
        float off = 0.0f;
        bool moves = false;
        for (int v = r.vert_begin; v < r.vert_begin + r.vert_count; ++v) {
            const Vec3 p = positions_[size_t(v)];
            if (use[size_t(v)] != 1 || !std::isfinite(p.x + p.y + p.z)) continue;
            moves = true;
            lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
            hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
            off = std::max(off, offset_at(p, view_.offset_scale));
        }
        if (!moves || !boundary_meets_a_face(r, lo, hi, kNear * off, ntri)) continue;
        const float d = std::min(kInset * off, 1e-3f * length(hi - lo));
        for (int v = r.vert_begin; v < r.vert_begin + r.vert_count; ++v) {
            const size_t k = size_t(v);
            // a fold (cosine <= 1/3: a spike, a sheet's rim) moves by three times d at most
            if (use[k] == 1) positions_[k] = positions_[k] - n[k] * (d / std::max(cos_min[k], 1.0f / 3.0f));
        }
    }
}

}  // namespace lantern
