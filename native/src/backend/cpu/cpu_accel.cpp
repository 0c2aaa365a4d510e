// CpuBackend's choice of ray-query structure: Embree when it loads, Lantern's BVH otherwise.
// LANTERN_ACCEL=bvh forces the BVH (tests compare both); LANTERN_ACCEL=embree insists on Embree
// and fails with Embree's reason when it cannot load.
#include <cstdlib>
#include <stdexcept>

#include "backend/backend.h"
#include "backend/cpu/embree_loader.h"

namespace lantern {

CpuBackend::CpuBackend(const SceneView& s, int threads, std::vector<std::string>& warnings,
                       const std::vector<MeshRange>* instances)
    : pool_(std::make_unique<ThreadPool>(threads)) {
    const char* env = std::getenv("LANTERN_ACCEL");
    const std::string want = env ? env : "";
    if (!want.empty() && want != "bvh" && want != "embree" && want != "auto") {
        throw std::invalid_argument("LANTERN_ACCEL must be 'bvh', 'embree' or 'auto', not '" +
                                    want + "'");
    }
    std::string why;
    // moving meshes (motion blur) need two levels (Session passes them): Embree's motion
    // instances (embree_instances.cpp) or the built-in TLAS (accel/tlas.h)
    if (want == "bvh") {
        why = "LANTERN_ACCEL=bvh";
    } else if (!embree_available()) {
        why = "Embree: " + embree_version();
        if (want == "embree") throw std::runtime_error("LANTERN_ACCEL=embree, but " + why);
    } else {
        try {
            embree_ = std::make_unique<EmbreeAccel>(s, warnings, instances);
            if (instances) mesh_boxes(s, *instances, mesh_box_);
            if (s.curves.num_segs > 0) curves_ = std::make_unique<CurveAccel>(s, true, warnings);
            return;
        } catch (const std::runtime_error& e) {
            embree_.reset();  // the strands' Embree geometry may be what failed
            curves_.reset();
            if (want == "embree") throw;
            why = std::string("Embree failed: ") + e.what();
        }
    }
    warnings.push_back("CPU ray queries use the built-in BVH (" + why + ")");
    bvh_ = std::make_unique<BvhAccel>(s, pool_->size(), warnings, instances);
    if (s.curves.num_segs > 0) curves_ = std::make_unique<CurveAccel>(s, false, warnings);
}

bool CpuBackend::move_instance(int k, const Transform& to_world) {
    if (!embree_) return bvh_->move(k, to_world);
    if (!embree_->two_level()) return false;
    Transform inv;
    if (k < 0 || 2 * size_t(k) >= mesh_box_.size() || !invert_affine(to_world, &inv))
        return false;
    float m[12];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) m[4 * r + c] = to_world.m[r][c];
    Vec3 b[2];  // the moved mesh's world box, for the far-ray bounds
    transformed_box(&mesh_box_[2 * k], to_world, b);
    return embree_->move(k, m, b);
}

}  // namespace lantern
