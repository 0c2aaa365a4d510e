// CpuBackend's choice of ray-query structure: Embree when it loads, Lantern's BVH otherwise.
// LANTERN_ACCEL=bvh forces the BVH (tests compare both); LANTERN_ACCEL=embree insists on Embree
// and fails with Embree's reason when it cannot load.
#include <cstdlib>
#include <stdexcept>

#include "backend/backend.h"
#include "backend/cpu/embree_loader.h"

namespace lantern {

CpuBackend::CpuBackend(const SceneView& s, int threads, std::vector<std::string>& warnings)
    : pool_(std::make_unique<ThreadPool>(threads)) {
    const char* env = std::getenv("LANTERN_ACCEL");
    const std::string want = env ? env : "";
    if (!want.empty() && want != "bvh" && want != "embree" && want != "auto") {
        throw std::invalid_argument("LANTERN_ACCEL must be 'bvh', 'embree' or 'auto', not '" +
                                    want + "'");
    }
    std::string why;
    if (want == "bvh") {
        why = "LANTERN_ACCEL=bvh";
    } else if (!embree_available()) {
        why = "Embree: " + embree_version();
        if (want == "embree") throw std::runtime_error("LANTERN_ACCEL=embree, but " + why);
    } else {
        try {
            embree_ = std::make_unique<EmbreeAccel>(s, warnings);
            return;
        } catch (const std::runtime_error& e) {
            if (want == "embree") throw;
            why = std::string("Embree failed: ") + e.what();
        }
    }
    warnings.push_back("CPU ray queries use the built-in BVH (" + why + ")");
    bvh_ = std::make_unique<BvhAccel>(s, pool_->size(), warnings);
}

}  // namespace lantern
