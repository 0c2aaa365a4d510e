// What the wavefront needs from a backend: for_all(n, fn) runs fn(k) for every queue item k in
// [0, n) (any order, any thread: stages write only their own slots), intersect() finds the
// closest hit, occluded() tests a shadow segment, compact() keeps the live queue items in order.
// The CPU backend is a thread pool + Embree, or Lantern's own BVH (the CUDA backend's traversal)
// when Embree does not load or LANTERN_ACCEL=bvh asks for it; the CUDA backend launches the same
// stage functions as kernels.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "backend/cpu/bvh_accel.h"
#include "backend/cpu/curve_accel.h"
#include "backend/cpu/embree_accel.h"
#include "backend/cpu/thread_pool.h"

namespace lantern {

class CpuBackend {
public:
    // threads: 0 = hardware concurrency. Ray queries: Embree when it loads, else the built-in
    // BVH (with a note in `warnings`); env LANTERN_ACCEL = "bvh" or "embree" forces one
    // (cpu_accel.cpp).
    // `instances`: two-level structures, one bottom level per mesh range, so that
    // move_instance() places a mesh again without a build (accel/tlas_build.h).
    CpuBackend(const SceneView& s, int threads, std::vector<std::string>& warnings,
               const std::vector<MeshRange>* instances = nullptr);

    template <typename Fn>
    void for_all(int n, Fn&& fn, int grain = 256) {
        pool_->parallel_for(n, grain, [&](int b, int e) {
            for (int k = b; k < e; ++k) fn(k);
        });
    }
    // Stream compaction: the items of `queue` whose slot is alive, in queue order, written to
    // `next`; returns their count. The order is what keeps images independent of scheduling.
    int compact(const int32_t* queue, int n, const uint8_t* alive, int32_t* next) const {
        int m = 0;
        for (int k = 0; k < n; ++k) {
            if (alive[queue[k]]) next[m++] = queue[k];
        }
        return m;
    }
    HitRecord intersect(const Ray& r, RayKind kind) const {
        if (!curves_) return embree_ ? embree_->intersect(r, kind) : bvh_->intersect(r, kind);
        HitRecord h = embree_ ? embree_->intersect(r, kind) : bvh_->intersect(r, kind);
        curves_->closer(r, kind, &h);  // strands (curve_accel.h): the nearer hit wins
        return h;
    }
    bool occluded(const Ray& r) const {
        if (!curves_) return embree_ ? embree_->occluded(r) : bvh_->occluded(r);
        return (embree_ ? embree_->occluded(r) : bvh_->occluded(r)) || curves_->occluded(r);
    }
    // A shadow ray through media in one query (accel/boundary_hits.h): whether anything but a
    // volume boundary blocks r (strands always do); if not, the boundaries on it in *out.
    // out->n -1: no answer (the caller's closest-hit loop).
    bool occluded_collect(const Ray& r, BoundaryHits* out) const {
        const bool blocked =
            embree_ ? embree_->occluded_collect(r, out) : bvh_->occluded_collect(r, out);
        if (blocked || out->n < 0 || !curves_) return blocked;
        return curves_->occluded(r);
    }
    const char* accel() const { return embree_ ? "embree" : "bvh"; }
    // Mesh k placed by to_world (relative to its exported positions); false, nothing changed,
    // without two levels or for a singular transform (cpu_accel.cpp).
    bool move_instance(int k, const Transform& to_world);
    bool instanced() const { return embree_ ? embree_->two_level() : bvh_->two_level(); }
    // Bottom-level structures built so far (a flat structure counts one): a move adds none.
    int64_t bottom_builds() const {
        return embree_ ? embree_->bottom_builds() : bvh_->bottom_builds();
    }
    int threads() const { return pool_->size(); }
    ThreadPool& pool() { return *pool_; }  // CpuExec runs its primitives on it
    const char* name() const { return "cpu"; }

private:
    std::unique_ptr<EmbreeAccel> embree_;  // exactly one of these two is set
    std::unique_ptr<BvhAccel> bvh_;
    std::unique_ptr<CurveAccel> curves_;  // strands (scene/curves.h), null without
    std::unique_ptr<ThreadPool> pool_;
    std::vector<Vec3> mesh_box_;  // Embree with instances: each mesh's exported bounds
};

}  // namespace lantern
