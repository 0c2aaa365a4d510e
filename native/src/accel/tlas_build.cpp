#include "accel/tlas_build.h"
#include "scene/motion_build.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "backend/cpu/thread_pool.h"

namespace lantern {
namespace {

constexpr int kTlasLeaf = 2;           // instances per top-level leaf
constexpr int kSerialBuild = 1 << 16;  // meshes this large are built with every thread

struct Ref {
    Vec3 lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
    uint32_t mask = 0;
    int32_t index = 0;   // node, or first leaf_inst entry
    uint32_t count = 0;  // 0: inner node
};

void grow(Ref& r, Vec3 lo, Vec3 hi) {
    r.lo = {std::min(r.lo.x, lo.x), std::min(r.lo.y, lo.y), std::min(r.lo.z, lo.z)};
    r.hi = {std::max(r.hi.x, hi.x), std::max(r.hi.y, hi.y), std::max(r.hi.z, hi.z)};
}

void set_child(BvhNode& n, int c, const Ref& r) {
    float* xy = c == 0 ? n.xy0 : n.xy1;
    xy[0] = r.lo.x, xy[1] = r.hi.x, xy[2] = r.lo.y, xy[3] = r.hi.y;
    n.z01[2 * c] = r.lo.z, n.z01[2 * c + 1] = r.hi.z;
    n.child[c] = r.index;
    n.meta[c] = (r.count & kBvhCountMask) | (r.mask << 24);
}

struct TopBuilder {
    Tlas& tl;
    std::vector<int32_t>& ids;
    const std::vector<Vec3>& box;  // world lo, hi per instance
    Ref build(int b, int e, int depth) {
        Ref r;
        for (int i = b; i < e; ++i) {
            grow(r, box[2 * ids[i]], box[2 * ids[i] + 1]);
            r.mask |= tl.instances[ids[i]].mask;
        }
        if (e - b <= kTlasLeaf || depth >= kTlasStackSize - 2) {
            r.index = int32_t(tl.leaf_inst.size());
            r.count = uint32_t(e - b);
            for (int i = b; i < e; ++i) tl.leaf_inst.push_back(ids[i]);
            return r;
        }
        Ref cen;  // centroid bounds: split the longest axis at the median
        for (int i = b; i < e; ++i) {
            const Vec3 c = (box[2 * ids[i]] + box[2 * ids[i] + 1]) * 0.5f;
            grow(cen, c, c);
        }
        const Vec3 ext = cen.hi - cen.lo;
        const int axis = ext.x >= ext.y ? (ext.x >= ext.z ? 0 : 2) : (ext.y >= ext.z ? 1 : 2);
        const int mid = (b + e) / 2;
        std::nth_element(ids.begin() + b, ids.begin() + mid, ids.begin() + e,
                         [&](int32_t p, int32_t q) {
                             const float cp = box[2 * p][axis] + box[2 * p + 1][axis];
                             const float cq = box[2 * q][axis] + box[2 * q + 1][axis];
                             return cp < cq || (cp == cq && p < q);
                         });
        const int32_t node = int32_t(tl.nodes.size());
        tl.nodes.push_back(BvhNode{});
        const Ref left = build(b, mid, depth + 1), right = build(mid, e, depth + 1);
        BvhNode& n = tl.nodes[node];
        set_child(n, 0, left);
        set_child(n, 1, right);
        r.index = node;
        r.count = 0;
        return r;
    }
};

}  // namespace

bool invert_affine(const Transform& m, Transform* inv) {
    double a[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) a[r][c] = m.m[r][c];
    const double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                       a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                       a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    if (!(std::fabs(det) > 1e-30) || !std::isfinite(det)) return false;
    double b[3][3];
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {  // adjugate / det
            const int r1 = (c + 1) % 3, r2 = (c + 2) % 3, c1 = (r + 1) % 3, c2 = (r + 2) % 3;
            b[r][c] = (a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1]) / det;
        }
    }
    for (int r = 0; r < 3; ++r) {
        double t = 0.0;
        for (int c = 0; c < 3; ++c) {
            inv->m[r][c] = float(b[r][c]);
            t -= b[r][c] * double(m.m[c][3]);
        }
        inv->m[r][3] = float(t);
        if (!std::isfinite(t)) return false;
    }
    return true;
}

void transformed_box(const Vec3 box[2], const Transform& m, Vec3 out[2]) {
    const Vec3 lo = box[0], hi = box[1];
    out[0] = vec3(kInf);
    out[1] = vec3(-kInf);
    if (!(lo.x <= hi.x)) return;
    bool identity = true;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) identity &= m.m[r][c] == (r == c ? 1.0f : 0.0f);
    for (int c = 0; c < 8; ++c) {
        const Vec3 p{c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z};
        const Vec3 w = identity ? p : m.point(p);
        out[0] = {std::min(out[0].x, w.x), std::min(out[0].y, w.y), std::min(out[0].z, w.z)};
        out[1] = {std::max(out[1].x, w.x), std::max(out[1].y, w.y), std::max(out[1].z, w.z)};
    }
    if (!identity) {  // the corners were rounded: pad by a few ulps of the coordinates
        float far = 0.0f;
        for (int a = 0; a < 3; ++a)
            far = std::max({far, std::fabs(out[0][a]), std::fabs(out[1][a])});
        const float pad = 1e-6f * (max_component(out[1] - out[0]) + far);
        out[0] = out[0] - vec3(pad);
        out[1] = out[1] + vec3(pad);
    }
}

void instance_world_box(const Tlas& tl, int k, Vec3 box[2]) {
    const int32_t mi = tl.instances[k].motion;
    if (mi < 0) {
        transformed_box(&tl.blas_box[2 * k], tl.to_world[k], box);
        return;
    }
    motion_world_box(tl.motion, tl.motion.objects[mi], &tl.blas_box[2 * k], box);  // motion_build
}

void mesh_boxes(const SceneView& s, const std::vector<MeshRange>& meshes, std::vector<Vec3>& out) {
    out.assign(2 * meshes.size(), vec3(0.0f));
    for (size_t k = 0; k < meshes.size(); ++k) {
        Vec3 lo = vec3(kInf), hi = vec3(-kInf);
        const MeshRange& m = meshes[k];
        for (int t = m.tri_begin; t < m.tri_begin + m.tri_count; ++t) {
            for (int j = 0; j < 3; ++j) {
                const Vec3 p = s.positions[s.indices[3 * t + j]];
                if (!is_finite(p)) continue;
                lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
                hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
            }
        }
        out[2 * k] = lo;
        out[2 * k + 1] = hi;
    }
}

void build_tlas(Tlas& tl) {
    tl.nodes.clear();
    tl.leaf_inst.clear();
    std::vector<int32_t> ids;
    std::vector<Vec3> box(2 * tl.instances.size());
    for (size_t k = 0; k < tl.instances.size(); ++k) {
        instance_world_box(tl, int(k), &box[2 * k]);
        if (tl.instances[k].mask) ids.push_back(int32_t(k));
    }
    ++tl.tlas_builds;
    if (ids.empty()) return;  // no nodes: every ray misses
    TopBuilder b{tl, ids, box};
    tl.nodes.reserve(2 * ids.size());
    tl.nodes.push_back(BvhNode{});  // the root: node 0
    const Ref root = ids.size() <= size_t(kTlasLeaf) ? b.build(0, int(ids.size()), 0) : Ref{};
    if (root.count > 0) {  // one leaf: a root with one child
        set_child(tl.nodes[0], 0, root);
        set_child(tl.nodes[0], 1, Ref{});
        return;
    }
    tl.nodes.clear();  // the recursion pushes the root first
    b.build(0, int(ids.size()), 0);
}

bool set_instance_transform(Tlas& tl, int k, const Transform& to_world) {
    if (k < 0 || size_t(k) >= tl.instances.size()) return false;
    Transform inv;
    if (!invert_affine(to_world, &inv)) return false;
    bool identity = true;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) identity &= to_world.m[r][c] == (r == c ? 1.0f : 0.0f);
    BvhInstance& in = tl.instances[k];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) in.to_object[r][c] = identity ? (r == c ? 1.0f : 0.0f)
                                                                  : inv.m[r][c];
    in.identity = identity ? 1 : 0;
    tl.to_world[k] = to_world;
    return true;
}

Bvh build_blas(const SceneView& s, int threads, int max_stack,
               std::vector<std::string>& warnings) {
    BvhBuildOptions opt;
    opt.threads = threads;
    Bvh b = build_bvh(s, opt, warnings);
    if (b.stats.max_depth - 1 <= max_stack) return b;
    opt.sah_depth = std::max(0, max_stack - 32);  // depth <= sah_depth + 31 (bvh_builder.h)
    std::vector<std::string> again;  // the same notes as the first build's
    b = build_bvh(s, opt, again);
    if (b.stats.max_depth - 1 > max_stack)
        throw std::length_error("two-level BVH: a mesh's bottom level of depth " +
                                std::to_string(b.stats.max_depth) +
                                " is deeper than its traversal stack holds (" +
                                std::to_string(max_stack) + " entries)");
    return b;
}

void build_tlas_scene(Tlas& tl, const SceneView& s, const std::vector<MeshRange>& meshes,
                      int threads, std::vector<std::string>& warnings) {
    const size_t n = meshes.size();
    tl = Tlas{};
    tl.blas.resize(n);
    std::vector<std::vector<std::string>> notes(n);
    auto build_one = [&](size_t k, int nthreads) {
        const MeshRange& m = meshes[k];
        SceneView sub = s;
        sub.indices = s.indices + 3 * size_t(m.tri_begin);
        sub.tri_flags = s.tri_flags ? s.tri_flags + m.tri_begin : nullptr;
        sub.num_triangles = m.tri_count;
        tl.blas[k] = build_blas(sub, nthreads, kBlasStackSize, notes[k]);
        for (BvhTri& t : tl.blas[k].tris) t.prim += m.tri_begin;
    };
    for (size_t k = 0; k < n; ++k) {
        if (meshes[k].tri_count >= kSerialBuild) build_one(k, threads);
    }
    {
        ThreadPool pool(threads);
        pool.parallel_for(int(n), 1, [&](int b, int e) {
            for (int k = b; k < e; ++k) {
                if (meshes[k].tri_count < kSerialBuild) build_one(size_t(k), 1);
            }
        });
    }
    int64_t nonfinite = 0, degenerate = 0;
    tl.blas_views.resize(n);
    tl.blas_box.assign(2 * n, vec3(0.0f));
    tl.to_world.resize(n);
    tl.instances.resize(n);
    for (size_t k = 0; k < n; ++k) {
        const Bvh& b = tl.blas[k];
        nonfinite += b.stats.skipped_nonfinite;
        degenerate += b.stats.skipped_degenerate;
        tl.blas_views[k] = b.view();
        Vec3 lo = vec3(kInf), hi = vec3(-kInf);
        uint32_t mask = 0;
        for (const BvhTri& t : b.tris) {
            for (const Vec3& p : {t.v0, t.v1, t.v2}) {
                lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
                hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
            }
            mask |= t.flags;
        }
        tl.blas_box[2 * k] = lo;
        tl.blas_box[2 * k + 1] = hi;
        BvhInstance& in = tl.instances[k];
        in = BvhInstance{};
        in.blas = int32_t(k);
        in.motion = -1;
        in.mask = b.tris.empty() ? 0u : (mask | kBvhNonEmpty);
        Transform id{};
        for (int r = 0; r < 3; ++r) id.m[r][r] = 1.0f;
        set_instance_transform(tl, int(k), id);
    }
    tl.blas_builds += int64_t(n);
    tl.motion = s.motion;  // moving instances: placed per ray at its time (tlas.h)
    for (int j = 0; j < s.motion.num_objects; ++j) {
        const int mesh = s.motion.objects[j].mesh;
        if (mesh < 0 || size_t(mesh) >= n) continue;
        tl.instances[mesh].motion = j;
        tl.instances[mesh].identity = 0;
        if (const DeformMesh* dm = deform_of(s.motion, s.motion.objects[j])) {
            // deformation blur: its boxes hold its triangles at every step (deform_build.cpp)
            deform_refit(tl.blas[mesh].nodes, tl.blas[mesh].tris, s.motion, *dm,
                         &tl.blas_box[2 * mesh]);
            tl.blas_views[mesh] = tl.blas[mesh].view();
        }
    }
    if (nonfinite) {
        warnings.push_back(std::to_string(nonfinite) +
                           " triangle(s) with non-finite vertices were left out");
    }
    if (degenerate) {
        warnings.push_back(std::to_string(degenerate) +
                           " degenerate (zero-area) triangle(s) were left out");
    }
    build_tlas(tl);
}

}  // namespace lantern
