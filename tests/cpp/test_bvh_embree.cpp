// The GPU backend's BVH (accel/) against Embree (EmbreeAccel): same hit or miss, same triangle
// (or the same distance when several lie there), t within 1e-5 relative, same occlusion, for
// every ray kind, on a room, a sphere, a triangle soup, degenerate and coincident triangles
// and alpha-tested ones (the helpers: test_bvh_helpers.h). A disagreement is allowed only where
// the ray passes within rounding of an edge or of the segment's end ("borderline"), and those
// must stay rare. Skips when Embree is missing.
#include <gtest/gtest.h>

#include "test_bvh_helpers.h"

using namespace lantern;
using namespace lantern::bvh_test;

TEST(Bvh, EmbreeCornellBox) {
    NEED_EMBREE();
    Mesh m = cornell();
    expect_agree(
        compare_many(m, 250000, random_rays({0.01f, 0.01f, 0.01f}, {0.99f, 0.99f, 0.99f}), 1));
    expect_agree(compare_many(
        m, 512 * 512, camera_rays({0.5f, 0.5f, -1.2f}, -0.1f, 1.1f, -0.1f, 1.1f, 0.0f, 512), 2));
}

TEST(Bvh, EmbreeSphere) {
    NEED_EMBREE();
    Mesh m = sphere(5);  // 20480 triangles
    expect_agree(
        compare_many(m, 250000, random_rays({-1.2f, -1.2f, -1.2f}, {1.2f, 1.2f, 1.2f}), 3));
    expect_agree(compare_many(
        m, 512 * 512, camera_rays({0.3f, 0.2f, 3.0f}, -1.1f, 1.1f, -1.1f, 1.1f, 0.0f, 512), 4));
}

TEST(Bvh, EmbreeTriangleSoup) {
    NEED_EMBREE();
    Mesh m = soup(100000, 0.03f, 5, true);
    expect_agree(
        compare_many(m, 150000, random_rays({-0.1f, -0.1f, -0.1f}, {1.1f, 1.1f, 1.1f}), 6));
    expect_agree(
        compare_many(m, 256 * 256, camera_rays({0.5f, 0.5f, -2.0f}, 0, 1, 0, 1, 0.0f, 256), 7));
}

TEST(Bvh, EmbreeDegenerateAndCoincident) {
    NEED_EMBREE();
    Mesh m = soup(20000, 0.05f, 8);
    const float nan = std::nanf(""), inf = std::numeric_limits<float>::infinity();
    for (int i = 0; i < 500; ++i) {  // degenerate and non-finite, mixed in
        Vec3 a = m.p[3 * i], b = m.p[3 * i + 1];
        m.tri(a, a, b);                                          // repeated vertex
        m.tri(a, a + Vec3{0.01f, 0, 0}, a + Vec3{0.02f, 0, 0});  // collinear
        m.tri(a, b, Vec3{nan, 0.5f, 0.5f});                      // NaN
        m.tri(a, Vec3{inf, 0, 0}, b);                            // infinite
    }
    for (int i = 0; i < 2000;
         ++i) {  // coincident: duplicates (rotated order) and coplanar overlaps
        Vec3 a = m.p[3 * i], b = m.p[3 * i + 1], c = m.p[3 * i + 2];
        m.tri(b, c, a);
        m.tri(a, (a + b) * 0.5f, c);
    }
    std::vector<std::string> w;
    Bvh bvh = build_bvh(m.view(), {}, w);
    EXPECT_EQ(bvh.stats.skipped_nonfinite, 1000);
    EXPECT_EQ(bvh.stats.skipped_degenerate, 1000);
    EXPECT_EQ(bvh.stats.triangles, 20000 + 4000);
    expect_agree(compare_many(m, 200000, random_rays({0, 0, 0}, {1, 1, 1}), 9));
}

// Alpha-tested triangles (scene/alpha.h): the BVH with BvhAlphaTest and Embree with its filter
// make the same decisions (one hash of ray and triangle), and a surface of alpha 0.3 stops
// 30% of the rays that reach it.
TEST(Bvh, AlphaTestAgreesWithEmbree) {
    if (!embree_available()) GTEST_SKIP() << embree_version();
    Mesh m = soup(3000, 0.08f, 21);
    std::vector<Material> mats(2);
    mats[1].transparency = 0.7f;  // alpha 0.3
    std::vector<uint32_t> tri_mat(m.count());
    for (int t = 0; t < m.count(); ++t) {
        tri_mat[t] = t % 2;
        if (t % 2) m.flags[t] |= kAlphaTested;
    }
    SceneView s = m.view();
    s.materials = mats.data();
    s.num_materials = 2;
    s.tri_material = tri_mat.data();
    std::vector<std::string> w;
    EmbreeAccel e(s, w);
    Bvh bvh = build_bvh(s, {}, w);
    Pcg32 rng = Pcg32::for_path(5, 0, 0);
    int differ = 0, n = 20000, alpha_first = 0, alpha_stopped = 0;
    for (int i = 0; i < n; ++i) {
        Ray r{Vec3{rng.uniform(), rng.uniform(), rng.uniform()}, uniform_dir(rng.uniform2())};
        BvhHit b = bvh_intersect(bvh.view(), r, kBvhNeedIndirect, BvhAlphaTest{s, r});
        HitRecord h = e.intersect(r, RayKind::kIndirect);
        if (b.prim != h.prim) ++differ;
        EXPECT_EQ(bvh_occluded(bvh.view(), r, kBvhNeedShadow, BvhAlphaTest{s, r}),
                  e.occluded(r)) << "ray " << i;
        // the first alpha-tested triangle along the ray, without the test: stopped or passed?
        BvhHit plain = bvh_intersect(bvh.view(), r, kBvhNeedIndirect);
        if (plain.prim >= 0 && plain.prim % 2) {
            ++alpha_first;
            alpha_stopped += b.prim == plain.prim;
        }
    }
    // a closest hit may differ only by rounding at a shared edge
    EXPECT_LE(differ, n / 1000) << differ << " of " << n;
    double p = double(alpha_stopped) / alpha_first;
    double sigma = std::sqrt(0.3 * 0.7 / alpha_first);
    std::printf("alpha 0.3: %d of %d first alpha hits stopped (%.4f, sigma %.4f)\n",
                alpha_stopped, alpha_first, p, sigma);
    EXPECT_GT(alpha_first, 2000);
    EXPECT_LT(std::abs(p - 0.3), 5 * sigma);
}
