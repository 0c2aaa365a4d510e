// Binned SAH build (Wald 2007, "On fast construction of SAH-based bounding volume hierarchies"):
// the top of the tree is built on one thread with binning spread over the pool, its subtrees
// below a fixed size are built in parallel into their own node arrays and spliced in task order.
// Below depth options.sah_depth splits are object medians, so the depth (and the traversal stack)
// stays bounded for any input.
#include "accel/bvh_builder.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <numeric>

#include "backend/cpu/thread_pool.h"
#include "scene/scene_limits.h"

namespace lantern {
namespace {

constexpr int kMaxBins = 64;
constexpr int kParallelBinning = 1 << 16;

struct Aabb {
    Vec3 lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
    void grow(Vec3 p) { grow(p, p); }
    void grow(const Aabb& b) { grow(b.lo, b.hi); }
    void grow(Vec3 l, Vec3 h) {
        lo = {bvh_min(lo.x, l.x), bvh_min(lo.y, l.y), bvh_min(lo.z, l.z)};
        hi = {bvh_max(hi.x, h.x), bvh_max(hi.y, h.y), bvh_max(hi.z, h.z)};
    }
    float half_area() const {
        Vec3 e = hi - lo;
        if (!(e.x >= 0.0f)) return 0.0f;
        return e.x * e.y + e.y * e.z + e.z * e.x;
    }
};

struct PrimRef {
    Aabb box;
    int32_t tri;
    uint32_t flags;
    Vec3 centroid() const { return box.lo + box.hi; }  // twice the centre: only compared
};

struct Range {
    int32_t begin = 0, end = 0;
    Aabb box, cbox;  // bounds of the triangles and of their centroids
    uint32_t mask = 0;
    int32_t count() const { return end - begin; }
};

struct Bin {
    Aabb box, cbox;
    int32_t count = 0;
    uint32_t mask = 0;
    void add(const PrimRef& p) {
        box.grow(p.box);
        cbox.grow(p.centroid());
        ++count;
        mask |= p.flags;
    }
    void add(const Bin& b) {
        if (!b.count) return;
        box.grow(b.box);
        cbox.grow(b.cbox);
        count += b.count;
        mask |= b.mask;
    }
};

struct Link {
    int32_t child;
    uint32_t meta;
};

struct Task {  // a subtree to build on its own, and where its link goes
    Range range;
    int32_t depth, parent, slot;
};

bool usable_triangle(const SceneView& s, int t, bool* nonfinite) {
    Vec3 a = s.positions[s.indices[3 * t]], b = s.positions[s.indices[3 * t + 1]],
         c = s.positions[s.indices[3 * t + 2]];
    *nonfinite = !(is_finite(a) && is_finite(b) && is_finite(c));
    if (*nonfinite) return false;
    const double a2 = triangle_area2(a, b, c);  // double: float overflows past ~4e9 m edges
    return a2 > 0.0 && std::isfinite(a2);
}

void set_child_box(BvhNode& n, int c, const Aabb& b) {
    float* xy = c == 0 ? n.xy0 : n.xy1;
    xy[0] = b.lo.x, xy[1] = b.hi.x, xy[2] = b.lo.y, xy[3] = b.hi.y;
    n.z01[2 * c] = b.lo.z, n.z01[2 * c + 1] = b.hi.z;
}

class Builder {
public:
    Builder(std::vector<PrimRef>& refs, const BvhBuildOptions& o, ThreadPool& pool)
        : refs_(refs),
          pool_(pool),
          bins_(std::clamp(o.bins, 4, kMaxBins)),
          max_leaf_(std::clamp(o.max_leaf, 1, int(kBvhCountMask))),
          sah_depth_(std::clamp(o.sah_depth, 0, 32)),
          node_cost_(o.node_cost) {}

    // Builds the subtree of `r` into `out` (its root first). Children of at most `defer_size`
    // triangles go to `defer` instead, when it is given.
    Link build(const Range& r, int depth, std::vector<BvhNode>& out, std::vector<Task>* defer,
               int defer_size) {
        Range kids[2];
        if (!split(r, depth, kids)) return leaf(r);
        int32_t idx = int32_t(out.size());
        out.push_back(BvhNode{});
        for (int c = 0; c < 2; ++c) {
            set_child_box(out[idx], c, kids[c].box);
            Link l{-1, (kids[c].mask | kBvhNonEmpty) << 24};
            if (defer && kids[c].count() <= defer_size) {
                defer->push_back({kids[c], depth + 1, idx, c});
            } else {
                l = build(kids[c], depth + 1, out, defer, defer_size);
            }
            out[idx].child[c] = l.child;
            out[idx].meta[c] = l.meta;
        }
        return {idx, (r.mask | kBvhNonEmpty) << 24};
    }

    Link leaf(const Range& r) const {
        return {r.begin, uint32_t(r.count()) | ((r.mask | kBvhNonEmpty) << 24)};
    }

private:
    int bin_of(const PrimRef& p, int axis, float cmin, float scale) const {
        int b = int((p.centroid()[axis] - cmin) * scale);
        return std::clamp(b, 0, bins_ - 1);
    }

    // ---- Binned SAH split; false: make a leaf ----
    bool split(const Range& r, int depth, Range kids[2]) {
        const int n = r.count();
        if (n <= 1) return false;
        Vec3 c_ext = r.cbox.hi - r.cbox.lo;
        float ext[3], scale[3];
        bool spread = false;
        for (int a = 0; a < 3; ++a) {  // an axis bins only if its bin scale is finite
            scale[a] = float(bins_) * (1.0f - 1e-6f) / c_ext[a];
            ext[a] = (c_ext[a] > 0.0f && std::isfinite(scale[a])) ? c_ext[a] : 0.0f;
            if (ext[a] == 0.0f) scale[a] = 0.0f;
            spread |= ext[a] > 0.0f;
        }
        if (depth >= sah_depth_ || !spread) {
            if (n <= max_leaf_) return false;
            median_split(r, kids);
            return true;
        }
        float cmin[3] = {r.cbox.lo.x, r.cbox.lo.y, r.cbox.lo.z};
        Bin bins[3][kMaxBins];
        auto bin_chunk = [&](int b, int e, Bin(*out)[kMaxBins]) {
            for (int i = b; i < e; ++i) {
                for (int a = 0; a < 3; ++a)
                    out[a][bin_of(refs_[i], a, cmin[a], scale[a])].add(refs_[i]);
            }
        };
        if (n >= kParallelBinning && pool_.size() > 1) {
            const int chunk = 1 << 14, chunks = (n + chunk - 1) / chunk;
            std::vector<Bin> part(size_t(chunks) * 3 * kMaxBins);
            pool_.parallel_for(chunks, 1, [&](int cb, int ce) {
                for (int c = cb; c < ce; ++c) {
                    bin_chunk(r.begin + c * chunk, std::min(r.end, r.begin + (c + 1) * chunk),
                              reinterpret_cast<Bin(*)[kMaxBins]>(&part[size_t(c) * 3 * kMaxBins]));
                }
            });
            for (int c = 0; c < chunks; ++c)  // merged in chunk order: deterministic
                for (int a = 0; a < 3; ++a)
                    for (int k = 0; k < bins_; ++k)
                        bins[a][k].add(part[(size_t(c) * 3 + a) * kMaxBins + k]);
        } else {
            bin_chunk(r.begin, r.end, bins);
        }
        // cost of splitting after bin k: node_cost + (A_l N_l + A_r N_r) / A  [Wald 2007 (1)]
        float best = kInf;
        int best_axis = -1, best_k = -1;
        const float inv_area = 1.0f / r.box.half_area();
        for (int a = 0; a < 3; ++a) {
            if (!(ext[a] > 0.0f)) continue;
            float right_cost[kMaxBins];
            Bin acc;
            for (int k = bins_ - 1; k > 0; --k) {
                acc.add(bins[a][k]);
                right_cost[k] = acc.box.half_area() * float(acc.count);
            }
            acc = Bin{};
            for (int k = 0; k < bins_ - 1; ++k) {
                acc.add(bins[a][k]);
                float cost =
                    node_cost_ +
                    (acc.box.half_area() * float(acc.count) + right_cost[k + 1]) * inv_area;
                if (acc.count > 0 && acc.count < n && cost < best) {
                    best = cost, best_axis = a, best_k = k;
                }
            }
        }
        if (best_axis < 0) {  // no finite-cost split (huge coordinates): fall back to the median
            if (n <= max_leaf_) return false;
            median_split(r, kids);
            return true;
        }
        if (n <= max_leaf_ && best >= float(n)) return false;
        const int a = best_axis;
        PrimRef* mid = std::partition(
            refs_.data() + r.begin, refs_.data() + r.end,
            [&](const PrimRef& p) { return bin_of(p, a, cmin[a], scale[a]) <= best_k; });
        Bin left, right;
        for (int k = 0; k < bins_; ++k) (k <= best_k ? left : right).add(bins[a][k]);
        int32_t m = int32_t(mid - refs_.data());
        kids[0] = {r.begin, m, left.box, left.cbox, left.mask};
        kids[1] = {m, r.end, right.box, right.cbox, right.mask};
        return true;
    }

    void median_split(const Range& r, Range kids[2]) {
        Vec3 e = r.cbox.hi - r.cbox.lo;
        int a = (e.x >= e.y && e.x >= e.z) ? 0 : (e.y >= e.z ? 1 : 2);
        int32_t m = r.begin + r.count() / 2;
        std::nth_element(refs_.begin() + r.begin, refs_.begin() + m, refs_.begin() + r.end,
                         [a](const PrimRef& p, const PrimRef& q) {
                             float cp = p.centroid()[a], cq = q.centroid()[a];
                             return cp < cq || (cp == cq && p.tri < q.tri);
                         });
        kids[0] = bounds(r.begin, m);
        kids[1] = bounds(m, r.end);
    }

    Range bounds(int32_t b, int32_t e) const {
        Bin acc;
        for (int32_t i = b; i < e; ++i) acc.add(refs_[i]);
        return {b, e, acc.box, acc.cbox, acc.mask};
    }

    std::vector<PrimRef>& refs_;
    ThreadPool& pool_;
    int bins_, max_leaf_, sah_depth_;
    float node_cost_;
};

void compute_stats(const Bvh& bvh, BvhStats& st) {
    st.nodes = int32_t(bvh.nodes.size());
    if (bvh.nodes.empty()) return;
    struct Item {
        int32_t node, depth;
    };
    std::vector<Item> stack{{0, 1}};
    const BvhNode& root = bvh.nodes[0];
    Aabb rb;
    for (int c = 0; c < 2; ++c) {
        if (!(root.meta[c] >> 24)) continue;
        const float* xy = c ? root.xy1 : root.xy0;
        rb.grow(Vec3{xy[0], xy[2], root.z01[2 * c]});
        rb.grow(Vec3{xy[1], xy[3], root.z01[2 * c + 1]});
    }
    const double inv_root = 1.0 / std::max(rb.half_area(), 1e-30f);
    st.sah_cost = 1.0;
    while (!stack.empty()) {
        Item it = stack.back();
        stack.pop_back();
        st.max_depth = std::max(st.max_depth, it.depth);
        const BvhNode& n = bvh.nodes[it.node];
        for (int c = 0; c < 2; ++c) {
            if (!(n.meta[c] >> 24)) continue;
            const float* xy = c ? n.xy1 : n.xy0;
            Aabb b;
            b.grow(Vec3{xy[0], xy[2], n.z01[2 * c]});
            b.grow(Vec3{xy[1], xy[3], n.z01[2 * c + 1]});
            uint32_t count = n.meta[c] & kBvhCountMask;
            if (count) {
                ++st.leaves;
                st.max_leaf_size = std::max(st.max_leaf_size, int32_t(count));
                st.sah_cost += double(b.half_area()) * inv_root * count;
            } else {
                st.sah_cost += double(b.half_area()) * inv_root;
                stack.push_back({n.child[c], it.depth + 1});
            }
        }
    }
}

}  // namespace

Bvh build_bvh(const SceneView& s, const BvhBuildOptions& options,
              std::vector<std::string>& warnings) {
    auto t0 = std::chrono::steady_clock::now();
    Bvh bvh;
    ThreadPool pool(options.threads);
    const int nt = s.num_triangles;

    // ---- References to the usable triangles, in scene order ----
    std::vector<PrimRef> all(size_t(std::max(nt, 0)));
    std::atomic<int> nonfinite{0}, degenerate{0};
    pool.parallel_for(nt, 1 << 14, [&](int b, int e) {
        int bad_nf = 0, bad_dg = 0;
        for (int t = b; t < e; ++t) {
            bool nf;
            PrimRef& p = all[t];
            p.tri = -1;
            if (!usable_triangle(s, t, &nf)) {
                (nf ? bad_nf : bad_dg)++;
                continue;
            }
            for (int k = 0; k < 3; ++k) p.box.grow(s.positions[s.indices[3 * t + k]]);
            p.tri = t;
            p.flags = s.tri_flags ? s.tri_flags[t] : uint32_t(kVisibleCamera | kCastShadow);
        }
        nonfinite += bad_nf;
        degenerate += bad_dg;
    });
    std::vector<PrimRef> refs;
    refs.reserve(all.size());
    Range root;
    Bin rootb;
    for (const PrimRef& p : all) {
        if (p.tri < 0) continue;
        refs.push_back(p);
        rootb.add(p);
    }
    std::vector<PrimRef>().swap(all);
    BvhStats& st = bvh.stats;
    st.skipped_nonfinite = nonfinite;
    st.skipped_degenerate = degenerate;
    st.triangles = int32_t(refs.size());
    if (st.skipped_nonfinite) {
        warnings.push_back(std::to_string(st.skipped_nonfinite) +
                           " triangle(s) with non-finite vertices were left out");
    }
    if (st.skipped_degenerate) {
        warnings.push_back(std::to_string(st.skipped_degenerate) +
                           " degenerate (zero-area) triangle(s) were left out");
    }
    root = {0, int32_t(refs.size()), rootb.box, rootb.cbox, rootb.mask};

    // ---- Top of the tree here; subtrees of at most defer_size triangles as tasks ----
    if (!refs.empty()) {
        Builder builder(refs, options, pool);
        std::vector<Task> tasks;
        const int defer_size = std::max(4096, root.count() / 64);  // not thread-dependent
        Link top = builder.build(root, 0, bvh.nodes, &tasks, defer_size);
        if (bvh.nodes.empty()) {  // the whole scene is one leaf: a root with one child
            bvh.nodes.push_back(BvhNode{});
            set_child_box(bvh.nodes[0], 0, root.box);
            bvh.nodes[0].child[0] = top.child;
            bvh.nodes[0].meta[0] = top.meta;
            bvh.nodes[0].child[1] = -1;
            bvh.nodes[0].meta[1] = 0;  // no kBvhNonEmpty: never entered
        }
        // ---- Subtrees in parallel (largest first), spliced in task order ----
        std::vector<std::vector<BvhNode>> sub(tasks.size());
        std::vector<Link> links(tasks.size());
        std::vector<int> order(tasks.size());
        std::iota(order.begin(), order.end(), 0);
        std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
            return tasks[a].range.count() > tasks[b].range.count();
        });
        pool.parallel_for(int(tasks.size()), 1, [&](int b, int e) {
            Builder local(refs, options, pool);
            for (int k = b; k < e; ++k) {
                const Task& t = tasks[order[k]];
                links[order[k]] = local.build(t.range, t.depth, sub[order[k]], nullptr, 0);
            }
        });
        for (size_t k = 0; k < tasks.size(); ++k) {
            Link l = links[k];
            if ((l.meta & kBvhCountMask) == 0) {  // an inner subtree: shift its node indices
                const int32_t offset = int32_t(bvh.nodes.size());
                for (BvhNode n : sub[k]) {
                    for (int c = 0; c < 2; ++c) {
                        if ((n.meta[c] >> 24) && (n.meta[c] & kBvhCountMask) == 0)
                            n.child[c] += offset;
                    }
                    bvh.nodes.push_back(n);
                }
                l.child = offset;
            }
            bvh.nodes[tasks[k].parent].child[tasks[k].slot] = l.child;
            bvh.nodes[tasks[k].parent].meta[tasks[k].slot] = l.meta;
        }
    }

    // ---- Triangles in leaf order ----
    bvh.tris.resize(refs.size());
    pool.parallel_for(int(refs.size()), 1 << 14, [&](int b, int e) {
        for (int i = b; i < e; ++i) {
            int t = refs[i].tri;
            BvhTri& tri = bvh.tris[i];
            tri.v0 = s.positions[s.indices[3 * t]];
            tri.v1 = s.positions[s.indices[3 * t + 1]];
            tri.v2 = s.positions[s.indices[3 * t + 2]];
            tri.prim = t;
            tri.flags = refs[i].flags;
            tri.pad = 0.0f;
        }
    });
    compute_stats(bvh, st);
    st.build_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return bvh;
}

}  // namespace lantern
