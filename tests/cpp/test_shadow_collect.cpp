// The one-query shadow ray through media (accel/boundary_hits.h, integrator/pt_volume.h
// pt_shadow_transmittance): occluded_collect on Embree and the built-in BVH (one level) against
// a brute-force walk over every triangle of a soup (the BVH's watertight test, the same alpha
// test): blocked exactly when a shadow caster that is not a volume boundary lies on the
// segment, and otherwise every boundary on it recorded once, at its distance. Two levels give
// no answer (n -1: the caller's loop). Negative control: a collector that ignored boundaries (a
// plain occlusion query) differs from the reference on many rays.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "accel/tlas_build.h"
#include "backend/backend.h"
#include "backend/cpu/embree_loader.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "test_soup.h"

using namespace lantern;

namespace {

using CollectSoup = soup_test::TriangleSoup;

// n random triangles in the unit cube; random camera / shadow flags; every second a volume
// boundary (some casting no shadow), every seventh alpha-tested.
CollectSoup collect_soup(int n, uint64_t seed) {
    CollectSoup m;
    m.mats.resize(2);
    m.mats[1].transparency = 0.6f;
    Pcg32 rng = Pcg32::for_path(seed, 0, 0);
    auto u3 = [&] { return vec3(rng.uniform(), rng.uniform(), rng.uniform()); };
    for (int i = 0; i < n; ++i) {
        const Vec3 c = u3();
        for (int k = 0; k < 3; ++k) {
            m.p.push_back(c + (u3() - vec3(0.5f)) * 0.12f);
            m.idx.push_back(uint32_t(m.p.size() - 1));
        }
        uint8_t f = uint8_t(rng.next() % 4);
        if (f == 0 || i % 2 == 0) f |= kCastShadow;  // most cast shadows
        if (i % 2 == 0 && i % 10 != 0) f |= kVolumeBoundary;
        m.tri_mat.push_back(i % 7 == 0 ? 1 : 0);
        if (i % 7 == 0) f |= kAlphaTested;
        m.flags.push_back(f);
    }
    return m;
}

// The reference: every shadow caster on r's segment (the watertight test, the alpha test).
struct CollectRef {
    bool blocked = false;
    std::vector<std::pair<float, int32_t>> bounds;  // (t, prim), by t
};

CollectRef collect_ref(const CollectSoup& m, const SceneView& s, const Ray& r) {
    CollectRef ref;
    const BvhRay br = bvh_ray(r);
    for (int t = 0; t < int(m.flags.size()); ++t) {
        if (!(m.flags[t] & kCastShadow)) continue;
        const BvhTri tri{m.p[3 * t], t, m.p[3 * t + 1], m.flags[t], m.p[3 * t + 2], 0.0f};
        float th, u, v;
        if (!bvh_hit_triangle(br, tri, r.tmax, &th, &u, &v)) continue;
        if ((m.flags[t] & kAlphaTested) && !alpha_stops(s, t, Vec2{u, v}, r.o, r.d)) continue;
        if (m.flags[t] & kVolumeBoundary) ref.bounds.push_back({th, t});
        else ref.blocked = true;
    }
    std::sort(ref.bounds.begin(), ref.bounds.end());
    return ref;
}

void collect_check(bool embree) {
    const int n = 3000;
    const CollectSoup m = collect_soup(n, 21);
    const SceneView s = m.view();
    std::vector<std::string> w;
    std::unique_ptr<EmbreeAccel> e;
    std::unique_ptr<BvhAccel> b;
    if (embree) e = std::make_unique<EmbreeAccel>(s, w, nullptr);
    else b = std::make_unique<BvhAccel>(s, 1, w, nullptr);
    Pcg32 rng = Pcg32::for_path(7, 0, 0);
    const int rays = 6000;
    int blocked = 0, crossed = 0, overflow = 0, differ = 0, control = 0;
    for (int i = 0; i < rays; ++i) {
        float pdf;
        Ray r{Vec3{rng.uniform(), rng.uniform(), rng.uniform()},
              sample_uniform_sphere(rng.uniform2(), &pdf)};
        r.tmax = i % 5 == 0 ? 2.0f : 0.25f;
        const CollectRef ref = collect_ref(m, s, r);
        BoundaryHits x;
        const bool o = e ? e->occluded_collect(r, &x) : b->occluded_collect(r, &x);
        const bool plain = e ? e->occluded(r) : b->occluded(r);
        control += plain != ref.blocked;
        if (x.n < 0) {  // out of room: only where more than kMax boundaries lie on the segment
            ++overflow;
            EXPECT_GT(int(ref.bounds.size()), BoundaryHits::kMax) << "ray " << i;
            continue;
        }
        if (o != ref.blocked) {
            ++differ;  // (Embree's triangle test rounds otherwise at an edge)
            continue;
        }
        if (o) {
            ++blocked;
            continue;
        }
        crossed += x.n > 0;
        std::vector<std::pair<float, int32_t>> got;
        for (int k = 0; k < x.n; ++k) {
            EXPECT_EQ(m.flags[size_t(x.prim[k])] & (kCastShadow | kVolumeBoundary),
                      kCastShadow | kVolumeBoundary);
            got.push_back({x.t[k], x.prim[k]});
        }
        std::sort(got.begin(), got.end());
        if (got.size() != ref.bounds.size()) {
            ++differ;
            continue;
        }
        for (size_t k = 0; k < got.size(); ++k) {
            EXPECT_EQ(got[k].second, ref.bounds[k].second) << "ray " << i;
            EXPECT_NEAR(got[k].first, ref.bounds[k].first, 1e-5f * (got[k].first + 1.0f));
        }
    }
    EXPECT_GT(blocked, rays / 10);
    EXPECT_GT(crossed, rays / 10);
    EXPECT_LT(overflow, rays / 5);
    // the built-in BVH runs the reference's own triangle test: no difference at all
    EXPECT_LE(differ, embree ? rays / 500 : 0) << differ;
    EXPECT_GT(control, rays / 20) << "boundaries should block a plain occlusion query";
}

}  // namespace

TEST(ShadowCollect, EmbreeOneLevel) {
    if (!embree_available()) GTEST_SKIP() << embree_version();
    collect_check(true);
}

TEST(ShadowCollect, BvhOneLevel) { collect_check(false); }

// A stack of boundaries (planes z = 0.1 k, k = 1..12) and one solid at z = 0.35 beside the
// axis: within kMax crossings all recorded (each once), beyond no answer; the solid blocks.
TEST(ShadowCollect, StackAndOverflow) {
    CollectSoup m;
    m.mats.resize(1);
    auto quad = [&](float z, float x0, uint8_t f) {
        const Vec3 c[4] = {{x0, -1, z}, {x0 + 2, -1, z}, {x0 + 2, 1, z}, {x0, 1, z}};
        for (int h : {1, 2}) {
            for (int k : {0, h, h + 1}) {
                m.p.push_back(c[k]);
                m.idx.push_back(uint32_t(m.p.size() - 1));
            }
            m.flags.push_back(f);
            m.tri_mat.push_back(0);
        }
    };
    for (int k = 1; k <= 12; ++k) quad(0.1f * float(k), -1.0f, kCastShadow | kVolumeBoundary);
    quad(0.35f, 0.5f, kCastShadow);  // x in [0.5, 2.5]: the ray at x 0.6 meets it
    std::vector<std::string> w;
    for (bool embree : {false, true}) {
        if (embree && !embree_available()) continue;
        std::unique_ptr<EmbreeAccel> e;
        std::unique_ptr<BvhAccel> b;
        if (embree) e = std::make_unique<EmbreeAccel>(m.view(), w, nullptr);
        else b = std::make_unique<BvhAccel>(m.view(), 1, w, nullptr);
        auto q = [&](const Ray& r, BoundaryHits* x) {
            return e ? e->occluded_collect(r, x) : b->occluded_collect(r, x);
        };
        BoundaryHits x;
        const Vec3 up{0.0f, 0.0f, 1.0f};
        EXPECT_FALSE(q(Ray{vec3(0.05f, -0.3f, 0.0f), up, 0.0f, 0.55f}, &x)) << embree;
        ASSERT_EQ(x.n, 5) << embree;  // z 0.1 .. 0.5, one triangle of each quad
        std::vector<float> t(x.t, x.t + x.n);
        std::sort(t.begin(), t.end());
        for (int k = 0; k < 5; ++k) EXPECT_NEAR(t[k], 0.1f * float(k + 1), 1e-6f);
        q(Ray{vec3(0.05f, -0.3f, 0.0f), up, 0.0f, 2.0f}, &x);
        EXPECT_EQ(x.n, -1) << embree;  // 12 crossings: more than kMax
        EXPECT_TRUE(q(Ray{vec3(0.6f, -0.3f, 0.0f), up, 0.0f, 0.55f}, &x)) << embree;
        EXPECT_EQ(x.n >= 0 && x.n <= 3, true) << x.n;  // stopped at the solid (some recorded)
    }
}

// Two levels (motion blur, instances) gather nothing: n -1, the caller's closest-hit loop.
TEST(ShadowCollect, TwoLevelsNoAnswer) {
    const CollectSoup m = collect_soup(400, 22);
    std::vector<MeshRange> meshes;
    for (int k = 0; k < 4; ++k) meshes.push_back(MeshRange{k * 100, 100, 300 * k, 300});
    std::vector<std::string> w;
    for (bool embree : {false, true}) {
        if (embree && !embree_available()) continue;
        std::unique_ptr<EmbreeAccel> e;
        std::unique_ptr<BvhAccel> b;
        if (embree) e = std::make_unique<EmbreeAccel>(m.view(), w, &meshes);
        else b = std::make_unique<BvhAccel>(m.view(), 1, w, &meshes);
        BoundaryHits x;
        const Ray r{vec3(0.5f), normalize(vec3(1.0f, 0.3f, 0.2f)), 0.0f, 1.0f};
        (void)(e ? e->occluded_collect(r, &x) : b->occluded_collect(r, &x));
        EXPECT_EQ(x.n, -1);
    }
}
