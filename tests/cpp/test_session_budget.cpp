// The light vertex cache within its memory budget (integrator/wavefront_cache.h and the CPU
// session): the measured peak, transient copies included, stays within cache_budget_mb while a
// render that would pass it runs as several passes; a cache that cannot fit even one sample per
// pass is a clear error, never an allocation past the budget. And Session::image() while another
// thread steps a Session whose GPU renderer (a test double) fails.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "backend/cpu/embree_loader.h"
#include "backend/cuda/cuda_renderer.h"
#include "integrator/session.h"
#include "integrator/wavefront_cache.h"

using namespace lantern;

namespace {

// A closed 4 m cube around the camera; inside it a point light (or none), every wall `albedo`.
SceneInput cube_scene(int size, float albedo, Vec3 emission, bool light) {
    SceneInput in;
    in.width = in.height = size;
    in.screen[0] = -1.0f; in.screen[1] = 1.0f; in.screen[2] = -1.0f; in.screen[3] = 1.0f;
    in.clip_start = 0.01f;
    MaterialInput m;
    m.base_color = vec3(albedo);
    m.emission = emission;
    in.materials.push_back(m);
    MeshInput mesh;
    mesh.name = "cube";
    for (int k = 0; k < 8; ++k) {
        mesh.positions.push_back(k & 1 ? 2.0f : -2.0f);
        mesh.positions.push_back(k & 2 ? 2.0f : -2.0f);
        mesh.positions.push_back(k & 4 ? 2.0f : -2.0f);
    }
    const uint32_t quads[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                                  {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
    for (const auto& q : quads) {
        mesh.indices.insert(mesh.indices.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
        mesh.material_ids.insert(mesh.material_ids.end(), {0, 0});
    }
    in.meshes.push_back(mesh);
    if (light) {
        LightInput l;
        l.type = "point";
        l.position = vec3(0.3f, 0.5f, -0.5f);
        l.power = vec3(100.0f);
        l.soft_falloff = false;
        in.lights.push_back(l);
    }
    return in;
}

bool has_warning(const Session& s, const std::string& part) {
    for (const std::string& w : s.warnings())
        if (w.find(part) != std::string::npos) return true;
    return false;
}

}  // namespace

TEST(CacheBudget, GrowthIsExactAndStopsAtTheBudget) {
    const CacheCosts c = cache_costs(false);
    // room for 1000 more vertices than stored: exactly the stored ones plus the rate's share
    EXPECT_EQ(cache_grow_capacity(1000, 0, 100, 200, 1e9, c), size_t(1000 + 1050));
    // the copy's transient (old + new) past the budget throws, with the rate measured so far
    const double budget = 3000.0 * sizeof(LightVertex);
    EXPECT_THROW(cache_grow_capacity(1600, 1500, 100, 100, budget, c), CacheOverBudget);
    try {
        cache_grow_capacity(4000, 0, 100, 200, budget, c);
        ADD_FAILURE() << "no throw";
    } catch (const CacheOverBudget& e) {
        EXPECT_DOUBLE_EQ(e.vertices_per_path, 40.0);
    }
    // the bdpt index is inside the budget: fewer vertices fit, and fewer samples per pass
    const CacheCosts bdpt = cache_costs(true);
    EXPECT_LT(cache_max_vertices(budget, bdpt, 100), cache_max_vertices(budget, c, 100));
    bool warned = false;
    std::vector<std::string> w;
    const double b = 64.0 * (1 << 20);
    const int plain = cache_samples_per_pass(b, 1.0, c, 8, 64, 256, 256, "x", &warned, w);
    warned = false;
    const int indexed = cache_samples_per_pass(b, 1.0, bdpt, 8, 64, 256, 256, "x", &warned, w);
    EXPECT_LT(indexed, plain);
    EXPECT_GE(indexed, 1);
    // the initial capacity never passes the budget, however high the rate
    EXPECT_LE(cache_initial_capacity(1e6, 1000, budget, c), cache_max_vertices(budget, c, 1000));
}

TEST(CacheBudget, MeasuredPeakStaysWithinTheBudgetAndTheIterationSplits) {
    if (!embree_available()) GTEST_SKIP() << "Embree not loadable: " << embree_version();
    const SceneInput in = cube_scene(48, 0.8f, vec3(0.0f), true);
    for (const char* integ : {"lvc", "bdpt", "cis"}) {
        SessionSettings st;
        st.integrator = integ;
        st.spp_per_iteration = 8;
        st.max_depth = 8;
        st.seed = 3;
        st.cache_budget_mb = 2;
        Session s(in, st);
        ASSERT_TRUE(s.step());
        const SessionStats stats = s.stats();
        const int64_t budget = int64_t(2) << 20;
        EXPECT_EQ(s.spp(), 8);
        EXPECT_TRUE(has_warning(s, "run as passes")) << integ;
        // the meter saw at least the last pass's vertices, and never more than the budget
        EXPECT_GE(stats.cache_memory_peak, stats.cache_vertices * int64_t(sizeof(LightVertex)));
        EXPECT_GT(stats.cache_vertices, 48 * 48);  // a real cache: > 1 vertex per pixel
        EXPECT_LE(stats.cache_memory_peak, budget) << integ;
        // unsplit (the default budget), the same iteration's cache passes 2 MiB
        SessionSettings whole = st;
        whole.cache_budget_mb = 0;
        Session u(in, whole);
        ASSERT_TRUE(u.step());
        EXPECT_GT(u.stats().cache_vertices * int64_t(sizeof(LightVertex)), budget) << integ;
        EXPECT_FALSE(has_warning(u, "run as passes"));
        std::vector<float> img = s.image();
        double sum = 0;
        for (float v : img) sum += v;
        EXPECT_GT(sum, 0.0);
        EXPECT_EQ(stats.nonfinite_dropped, 0);
    }
}

TEST(CacheBudget, ACacheThatCannotFitOneSampleIsAClearError) {
    if (!embree_available()) GTEST_SKIP() << "Embree not loadable: " << embree_version();
    SessionSettings st;
    st.integrator = "lvc";
    st.spp_per_iteration = 4;
    st.max_depth = 8;
    st.cache_budget_mb = 1;  // 128 x 128 paths x ~4 vertices x 96 B = ~6 MB at one sample
    Session s(cube_scene(128, 0.8f, vec3(0.0f), true), st);
    try {
        s.step();
        ADD_FAILURE() << "the step rendered past its budget";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("cache_budget_mb"), std::string::npos) << e.what();
    }
    EXPECT_LE(s.stats().cache_memory_peak, int64_t(1) << 20);
    EXPECT_EQ(s.spp(), 0);
}

// ---- image() against a GPU renderer that fails on the stepping thread ----

namespace {

struct Control {
    std::mutex m;
    bool destroyed = false;
    int calls_after_destroy = 0;
};

// Adds `value` per sample to every pixel; throws on step `fail_at`.
class FakeGpu final : public CudaRenderer {
public:
    FakeGpu(std::shared_ptr<Control> c, size_t px3, int fail_at, double value)
        : c_(std::move(c)), sum_(px3, 0.0), fail_at_(fail_at), value_(value) {}
    ~FakeGpu() override {
        std::lock_guard<std::mutex> lock(c_->m);
        c_->destroyed = true;
    }
    bool step(const SessionSettings& settings, uint64_t& iteration, SessionStats&,
              const std::atomic<bool>&, std::vector<std::string>&) override {
        std::this_thread::sleep_for(std::chrono::microseconds(300));
        if (++steps_ == fail_at_) throw std::runtime_error("the test's GPU failed");
        {
            std::lock_guard<std::mutex> lock(c_->m);
            for (double& v : sum_) v += value_ * settings.spp_per_iteration;
            samples_ += settings.spp_per_iteration;
        }
        // the new sum is readable before the session hears of the step: a reader that paired
        // it with the session's own count would see 0.5 x (n + 1) / n
        std::this_thread::sleep_for(std::chrono::microseconds(300));
        ++iteration;
        return true;
    }
    std::vector<double> accum(int64_t* samples) override {
        std::lock_guard<std::mutex> lock(c_->m);
        if (c_->destroyed) ++c_->calls_after_destroy;
        *samples = samples_;
        return sum_;
    }
    std::string device_name() const override { return "test double"; }

private:
    std::shared_ptr<Control> c_;
    std::vector<double> sum_;
    int64_t samples_ = 0;
    int steps_ = 0, fail_at_;
    double value_;
};

}  // namespace

TEST(SessionGpuFailure, ImageWhileAFailingGpuStepIsReplacedByTheCpu) {
    if (!embree_available()) GTEST_SKIP() << "Embree not loadable: " << embree_version();
    // black emitting walls seen head-on: every CPU sample is exactly 0.5, as is the double's
    const SceneInput in = cube_scene(16, 0.0f, vec3(0.5f), false);
    SessionSettings st;
    st.spp_per_iteration = 2;
    st.max_depth = 1;
    auto ctl = std::make_shared<Control>();
    Session s(in, st, std::make_unique<FakeGpu>(ctl, size_t(16 * 16 * 3), 10, 0.5));
    ASSERT_EQ(s.backend_name(), "cuda");
    std::atomic<bool> done{false};
    std::atomic<int64_t> reads{0}, bad{0};
    std::thread reader([&] {
        while (!done.load()) {
            const std::vector<float> img = s.image();
            bool zero = true, half = true;
            for (float v : img) {
                zero &= v == 0.0f;
                half &= v == 0.5f;
            }
            bad += !(zero || half);
            ++reads;
        }
    });
    const int steps = 30;
    for (int k = 0; k < steps; ++k) EXPECT_TRUE(s.step());
    done = true;
    reader.join();
    EXPECT_GT(reads.load(), 0);
    EXPECT_EQ(bad.load(), 0) << "image() saw a sum and a sample count that do not match";
    EXPECT_TRUE(ctl->destroyed);
    EXPECT_EQ(ctl->calls_after_destroy, 0);
    EXPECT_EQ(s.backend_name(), "cpu");
    EXPECT_TRUE(has_warning(s, "the test's GPU failed"));
    EXPECT_EQ(s.spp(), steps * 2);
    for (float v : s.image()) ASSERT_EQ(v, 0.5f);
}
