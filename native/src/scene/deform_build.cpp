// Deformation blur's host side (scene/motion.h DeformMesh, docs/motion_blur.md): a mesh's
// positions at the shutter's steps checked and laid out per triangle corner, and a bottom-level
// BVH's boxes refitted to hold its triangles at every step (the union over the steps: each
// interpolated triangle lies within the hull of its corners at the two steps around it).
#include <algorithm>
#include <cmath>
#include <string>

#include "accel/bvh_builder.h"
#include "accel/tlas_build.h"
#include "scene/motion_build.h"
#include "scene/scene.h"

namespace lantern {

bool build_deform(const MeshInput& m, const MeshRange& r, const std::vector<uint32_t>& indices,
                  std::vector<Vec3>& corners, DeformMesh* out, std::string* warning) {
    const std::string who = "mesh '" + m.name + "'";
    const size_t per = m.positions.size();
    if (per == 0 || m.deform.size() % per != 0 || m.deform.size() / per < 2) {
        *warning = who + ": its deformation steps do not match its " + std::to_string(per / 3) +
                   " vertices (got " + std::to_string(m.deform.size() / 3) +
                   " positions); rendered without deformation motion blur";
        return false;
    }
    for (size_t k = 0; k < m.deform.size(); ++k) {
        if (!std::isfinite(m.deform[k])) {
            *warning = who + ": a position at deformation step " + std::to_string(k / per) +
                       " is not finite; rendered without deformation motion blur";
            return false;
        }
    }
    const int steps = int(m.deform.size() / per);
    bool moves = false;
    for (size_t k = per; k < m.deform.size() && !moves; ++k)
        moves = m.deform[k] != m.deform[k % per];
    if (!moves) return false;  // steps that do not move: still, nothing to say
    out->tri_begin = r.tri_begin;
    out->tri_count = r.tri_count;
    out->first = int32_t(corners.size());
    out->num_steps = steps;
    for (int k = 0; k < steps; ++k) {
        const float* p = m.deform.data() + size_t(k) * per;
        for (int t = r.tri_begin; t < r.tri_begin + r.tri_count; ++t) {
            for (int j = 0; j < 3; ++j) {
                const size_t v = indices[3 * size_t(t) + j] - uint32_t(r.vert_begin);
                corners.push_back({p[3 * v], p[3 * v + 1], p[3 * v + 2]});
            }
        }
    }
    return true;
}

namespace {

struct Box {
    Vec3 lo = vec3(kInf), hi = vec3(-kInf);
    void add(Vec3 p) {
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    void add(const Box& b) {
        if (b.lo.x <= b.hi.x) add(b.lo), add(b.hi);
    }
};

Box refit(std::vector<BvhNode>& nodes, const std::vector<BvhTri>& tris, const MotionView& mv,
          const DeformMesh& dm, int node, int depth) {
    BvhNode& n = nodes[node];
    Box both;
    for (int c = 0; c < 2; ++c) {
        if (!(n.meta[c] >> 24)) continue;  // an empty child (no kBvhNonEmpty): never entered
        const uint32_t count = n.meta[c] & kBvhCountMask;
        Box b;
        if (count == 0) {
            if (depth < kBvhStackSize) b = refit(nodes, tris, mv, dm, n.child[c], depth + 1);
        } else {
            for (int32_t i = n.child[c]; i < n.child[c] + int32_t(count); ++i) {
                const int tri = tris[i].prim;
                if (tri < dm.tri_begin || tri >= dm.tri_begin + dm.tri_count) continue;
                for (int k = 0; k < dm.num_steps; ++k) {
                    const Vec3* p = mv.deform_corners + dm.first +
                                    3 * (k * dm.tri_count + (tri - dm.tri_begin));
                    for (int j = 0; j < 3; ++j) b.add(p[j]);
                }
            }
        }
        if (!(b.lo.x <= b.hi.x)) continue;
        float* xy = c == 0 ? n.xy0 : n.xy1;
        xy[0] = std::min(xy[0], b.lo.x), xy[1] = std::max(xy[1], b.hi.x);
        xy[2] = std::min(xy[2], b.lo.y), xy[3] = std::max(xy[3], b.hi.y);
        n.z01[2 * c] = std::min(n.z01[2 * c], b.lo.z);
        n.z01[2 * c + 1] = std::max(n.z01[2 * c + 1], b.hi.z);
        b.add(Vec3{xy[0], xy[2], n.z01[2 * c]});
        b.add(Vec3{xy[1], xy[3], n.z01[2 * c + 1]});
        both.add(b);
    }
    return both;
}

}  // namespace

void deform_refit(std::vector<BvhNode>& nodes, const std::vector<BvhTri>& tris,
                  const MotionView& mv, const DeformMesh& dm, Vec3 box[2]) {
    if (nodes.empty()) return;
    const Box b = refit(nodes, tris, mv, dm, 0, 0);
    Box all;
    all.add(b);
    all.add(box[0]);
    all.add(box[1]);
    box[0] = all.lo;
    box[1] = all.hi;
}

}  // namespace lantern
