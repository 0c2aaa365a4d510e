// CpuExec against the plain references of exec_conformance.h, at several thread counts: every
// primitive must give the reference's exact result (the CPU executor is deterministic).
#include <gtest/gtest.h>

#include "backend/cpu/cpu_exec.h"
#include "exec_conformance.h"

using namespace lantern;

namespace {

void expect_conformant(int threads) {
    CpuExec ex(threads);
    const auto results = conformance::run_all(ex);
    EXPECT_GE(results.size(), 6u);
    for (const auto& r : results)
        EXPECT_TRUE(r.failure.empty()) << "CpuExec (" << threads << " threads), " << r.primitive
                                       << ": " << r.failure;
}

}  // namespace

TEST(ExecConformance, CpuOneThread) { expect_conformant(1); }
TEST(ExecConformance, CpuThreeThreads) { expect_conformant(3); }

TEST(ExecConformance, CpuRayQueries) {
    std::vector<std::string> warnings;
    HostScene scene(conformance::ray_scene());
    CpuBackend backend(scene.view(), 2, warnings);
    CpuExec ex(backend);
    std::mt19937 rng(5);
    for (int n : {0, 1, 7, 4001}) {
        const std::string f = conformance::check_rays(ex, scene.view(), scene.num_triangles(), n, rng);
        EXPECT_TRUE(f.empty()) << "CpuExec (" << backend.accel() << "): " << f;
    }
}

// The checks bite: a select that drops the order, or a sort that is not stable, fails them.
TEST(ExecConformance, ChecksCatchAnUnstableSort) {
    struct Unstable : CpuExec {
        using CpuExec::CpuExec;
        void sort_pairs(uint32_t* keys, int32_t* values, int n, int b, int e) {
            CpuExec::sort_pairs(keys, values, n, b, e);
            for (int k = 1; k < n; ++k)  // swap equal keys: still sorted, no longer stable
                if (keys[k] == keys[k - 1]) std::swap(values[k], values[k - 1]);
        }
    } ex(1);
    std::mt19937 rng(1);
    EXPECT_FALSE(conformance::check_sort(ex, 1001, 0, 3, 3, rng).empty());
    EXPECT_TRUE(conformance::check_sort(static_cast<CpuExec&>(ex), 1001, 0, 3, 3, rng).empty());
}
