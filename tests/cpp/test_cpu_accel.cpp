// The CPU backend's ray-query structures through the interface the wavefront calls: BvhAccel
// (Lantern's BVH) against EmbreeAccel on a soup with mixed visibility flags and alpha-tested
// triangles, for every ray kind and for occlusion; and CpuBackend's choice (env LANTERN_ACCEL).
// test_bvh.cpp covers the traversal itself; here only the accel wrappers and the choice.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "backend/backend.h"
#include "backend/cpu/embree_loader.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "test_soup.h"

using namespace lantern;

namespace {

using Soup = soup_test::TriangleSoup;

// n random triangles in the unit cube; random visibility flags; every third alpha 0.4.
Soup soup(int n, uint64_t seed) {
    Soup m;
    m.mats.resize(2);
    m.mats[1].transparency = 0.6f;
    Pcg32 rng = Pcg32::for_path(seed, 0, 0);
    auto u3 = [&] { return vec3(rng.uniform(), rng.uniform(), rng.uniform()); };
    for (int i = 0; i < n; ++i) {
        Vec3 c = u3();
        for (int k = 0; k < 3; ++k) {
            m.p.push_back(c + (u3() - vec3(0.5f)) * 0.1f);
            m.idx.push_back(uint32_t(m.p.size() - 1));
        }
        uint8_t f = uint8_t(rng.next() % 4);
        m.tri_mat.push_back(i % 3 == 0 ? 1 : 0);
        if (i % 3 == 0) f |= kAlphaTested;
        m.flags.push_back(f);
    }
    return m;
}

struct EnvGuard {  // sets LANTERN_ACCEL for one scope
    explicit EnvGuard(const char* v) {
        if (v) setenv("LANTERN_ACCEL", v, 1);
        else unsetenv("LANTERN_ACCEL");
    }
    ~EnvGuard() { unsetenv("LANTERN_ACCEL"); }
};

bool has_bvh_note(const std::vector<std::string>& w) {
    for (const auto& s : w)
        if (s.find("built-in BVH") != std::string::npos) return true;
    return false;
}

}  // namespace

TEST(CpuAccel, BvhAccelMatchesEmbreeAccelForEveryRayKind) {
    if (!embree_available()) GTEST_SKIP() << embree_version();
    Soup m = soup(4000, 3);
    SceneView s = m.view();
    std::vector<std::string> w;
    EmbreeAccel e(s, w);
    BvhAccel b(s, 2, w);
    Pcg32 rng = Pcg32::for_path(9, 0, 0);
    const int n = 20000;
    int differ[3] = {0, 0, 0}, hits[3] = {0, 0, 0}, occl_differ = 0, occluded = 0;
    for (int i = 0; i < n; ++i) {
        float pdf;
        Ray r{Vec3{rng.uniform(), rng.uniform(), rng.uniform()},
              sample_uniform_sphere(rng.uniform2(), &pdf)};
        for (int k = 0; k < 3; ++k) {
            const RayKind kind = RayKind(k);
            HitRecord he = e.intersect(r, kind), hb = b.intersect(r, kind);
            hits[k] += he.prim >= 0;
            if (he.prim != hb.prim) {
                ++differ[k];
            } else if (he.prim >= 0) {
                EXPECT_NEAR(he.t, hb.t, 1e-5f * (he.t + 1.0f))  // scene size 1
                    << "ray " << i << " kind " << k;
            }
        }
        Ray seg = r;
        seg.tmax = 0.3f;
        bool oe = e.occluded(seg);
        occluded += oe;
        occl_differ += oe != b.occluded(seg);
    }
    // a closest hit may differ only by rounding at a shared edge or an alpha hash of a
    // different t: rare
    for (int k = 0; k < 3; ++k) {
        EXPECT_GT(hits[k], n / 4) << "kind " << k;
        EXPECT_LE(differ[k], n / 500) << "kind " << k << ": " << differ[k] << " of " << n;
    }
    EXPECT_GT(occluded, n / 10);
    EXPECT_LE(occl_differ, n / 500) << occl_differ;
}

TEST(CpuAccel, BackendChoosesAndForcesTheAccel) {
    Soup m = soup(50, 4);
    SceneView s = m.view();
    {
        EnvGuard g("bvh");
        std::vector<std::string> w;
        CpuBackend be(s, 1, w);
        EXPECT_STREQ(be.accel(), "bvh");
        EXPECT_TRUE(has_bvh_note(w));
    }
    {
        EnvGuard g(nullptr);
        std::vector<std::string> w;
        CpuBackend be(s, 1, w);
        EXPECT_STREQ(be.accel(), embree_available() ? "embree" : "bvh");
        EXPECT_EQ(has_bvh_note(w), !embree_available());
    }
    {
        EnvGuard g("kdtree");
        std::vector<std::string> w;
        EXPECT_THROW(CpuBackend(s, 1, w), std::invalid_argument);
    }
    if (!embree_available()) {
        EnvGuard g("embree");
        std::vector<std::string> w;
        EXPECT_THROW(CpuBackend(s, 1, w), std::runtime_error);
    }
}
