// The GPU's per-thread scratch plan (integrator/thread_scratch.h) and its cache budget
// (wavefront_cache.h gpu_cache_budget), run on the CPU executor's arrays: the CUDA renderer
// calls the same code, so what it allocates, when, and what the budget leaves are checked here
// line for line (the device's reads of the buffers are test_program_regs.cpp's).
#include <gtest/gtest.h>

#include <vector>

#include "backend/cpu/cpu_exec.h"
#include "integrator/thread_scratch.h"
#include "integrator/wavefront_cache.h"

using namespace lantern;

namespace {

// n materials, all plain diffuse; material_bits none.
std::vector<Material> plain(int n) {
    std::vector<Material> m(static_cast<size_t>(n));
    for (Material& x : m) {
        x = Material{};
        x.type = kMaterialDiffuse;
        x.tex_flags = 0;
        x.mix_count = 0;
    }
    return m;
}

SceneView view_of(std::vector<Material>& m, uint32_t bits) {
    SceneView v{};
    v.materials = m.data();
    v.num_materials = int32_t(m.size());
    v.material_bits = bits;
    return v;
}

}  // namespace

TEST(ThreadScratch, AllocatesOnlyWhatTheSceneAndIntegratorUse) {
    const int threads = 1000;
    MemoryMeter meter;
    std::vector<Material> mats = plain(3);
    SceneView host = view_of(mats, 0u), dev = host;
    ThreadScratch<CpuExec> sc;
    sc.bind(&meter);
    EXPECT_FALSE(sc.prepare_scene(host, dev, threads));  // a plain scene: nothing
    EXPECT_FALSE(sc.prepare_integrator("lvc", dev, threads));
    EXPECT_EQ(sc.bytes(), 0);
    EXPECT_EQ(dev.device_threads, 0u);
    EXPECT_EQ(dev.program_regs, nullptr);

    // cis: its candidates at its first step, once
    EXPECT_TRUE(sc.prepare_integrator("cis", dev, threads));
    EXPECT_EQ(sc.cis_candidates.capacity(), size_t(2 * kCisCandidates * threads));
    EXPECT_EQ(dev.cis_candidates, sc.cis_candidates.data());
    EXPECT_EQ(dev.device_threads, uint32_t(threads));
    EXPECT_FALSE(sc.prepare_integrator("cis", dev, threads));
    EXPECT_EQ(sc.bytes(), int64_t(2 * kCisCandidates * threads * sizeof(float)));
    EXPECT_EQ(meter.current, sc.bytes());
}

TEST(ThreadScratch, ProgramsAndTexturedMixLeaves) {
    const int threads = 512;
    MemoryMeter meter;
    std::vector<Material> mats = plain(3);
    mats[2].type = kMaterialMix;  // a mix of 0 and 1
    mats[2].mix_count = 2;
    mats[2].mix_child[0] = 0;
    mats[2].mix_child[1] = 1;
    SceneView host = view_of(mats, kScenePrograms), dev = host;
    EXPECT_FALSE(scene_has_textured_mix_leaf(host));  // the leaves are the scene's as they are
    ThreadScratch<CpuExec> sc;
    sc.bind(&meter);
    EXPECT_TRUE(sc.prepare_scene(host, dev, threads));
    EXPECT_EQ(sc.program_regs.capacity(), size_t(kProgramRegs * threads));
    EXPECT_EQ(sc.mix_leaves.capacity(), 0u);
    EXPECT_EQ(dev.program_regs, sc.program_regs.data());
    EXPECT_EQ(dev.mix_leaves, nullptr);

    mats[1].tex_flags = kTexBaseColor;  // a textured leaf: its resolved copy per thread
    EXPECT_TRUE(scene_has_textured_mix_leaf(host));
    SceneView plain_host = view_of(mats, 0u), dev2 = plain_host;
    ThreadScratch<CpuExec> sc2;
    sc2.bind(&meter);
    EXPECT_TRUE(sc2.prepare_scene(plain_host, dev2, threads));
    EXPECT_EQ(sc2.program_regs.capacity(), 0u);
    EXPECT_EQ(sc2.mix_leaves.capacity(), size_t(kMixLeaves * threads));
    EXPECT_EQ(dev2.mix_leaves, sc2.mix_leaves.data());
    EXPECT_EQ(sc2.bytes(), int64_t(kMixLeaves * threads * sizeof(Material)));
}

TEST(ThreadScratch, GpuCacheBudget) {
    const int64_t gib = int64_t(1) << 30;
    // half of the free memory less the reservation
    EXPECT_DOUBLE_EQ(gpu_cache_budget(10 * gib, 2 * gib, 0, 1.0), 4.0 * gib);
    // at most 8 GiB, and the scale after an out-of-memory halving
    EXPECT_DOUBLE_EQ(gpu_cache_budget(100 * gib, 0, 0, 1.0), 8.0 * gib);
    EXPECT_DOUBLE_EQ(gpu_cache_budget(100 * gib, 0, 0, 0.5), 4.0 * gib);
    // a reservation past what was free leaves nothing, never a negative budget
    EXPECT_DOUBLE_EQ(gpu_cache_budget(gib, 2 * gib, 0, 1.0), 0.0);
    // cache_budget_mb overrides, scaled too
    EXPECT_DOUBLE_EQ(gpu_cache_budget(gib, 2 * gib, 300, 1.0), 300.0 * (1 << 20));
    EXPECT_DOUBLE_EQ(gpu_cache_budget(gib, 0, 300, 0.5), 150.0 * (1 << 20));
}
