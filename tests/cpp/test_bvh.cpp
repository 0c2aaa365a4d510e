// The GPU backend's BVH (accel/) alone: edges and vertices are watertight, every ray matches
// brute force, tmax at a hit, origins on surfaces, empty and single-triangle scenes, a bounded
// depth and a deterministic build. Against Embree ray by ray: test_bvh_embree.cpp; the meshes
// and the comparison harness: test_bvh_helpers.h.
#include <gtest/gtest.h>

#include "accel/tlas_build.h"
#include "test_bvh_helpers.h"

using namespace lantern;
using namespace lantern::bvh_test;

// Rays from inside closed meshes through shared edges and vertices: watertight, so never a miss.
TEST(Bvh, EdgesAndVerticesAreWatertight) {
    Mesh m = sphere(4);
    std::vector<std::string> w;
    Bvh bvh = build_bvh(m.view(), {}, w);
    std::unique_ptr<EmbreeAccel> e;
    if (embree_available()) e = std::make_unique<EmbreeAccel>(m.view(), w);
    Vec3 origins[3] = {{0, 0, 0}, {0.1f, -0.2f, 0.05f}, {-0.3f, 0.3f, 0.3f}};
    int checked = 0, embree_misses = 0;
    for (Vec3 o : origins) {
        for (int t = 0; t < m.count(); ++t) {
            for (int k = 0; k < 3; ++k) {
                Vec3 a = m.p[m.idx[3 * t + k]], b = m.p[m.idx[3 * t + (k + 1) % 3]];
                for (Vec3 target : {a, (a + b) * 0.5f, a * 0.25f + b * 0.75f}) {
                    Ray r{o, normalize(target - o), 0.0f, kInf};
                    BvhHit h = bvh_intersect(bvh.view(), r, 0);
                    ASSERT_GE(h.prim, 0) << "miss through an edge or vertex of triangle " << t;
                    EXPECT_NEAR(h.t, length(target - o), 1e-5f);
                    if (e) {  // Embree (robust mode) is not watertight at vertices: count its
                              // misses
                        HitRecord he = e->intersect(r, RayKind::kIndirect);
                        if (he.prim < 0)
                            ++embree_misses;
                        else
                            EXPECT_TRUE(close_t(he.t, h.t)) << he.t << " vs " << h.t;
                    }
                    ++checked;
                }
            }
        }
    }
    EXPECT_GT(checked, 100000);
    std::printf("%d rays through edges and vertices: BVH 0 misses, Embree %d\n", checked,
                embree_misses);
    ::testing::Test::RecordProperty("embree_misses", embree_misses);
    // axis-aligned walls: rays through the room's corners, edges and quad diagonals
    Mesh c = cornell();
    Bvh cb = build_bvh(c.view(), {}, w);
    for (float x : {0.0f, 0.5f, 1.0f})
        for (float y : {0.0f, 0.25f, 1.0f})
            for (float z : {0.0f, 1.0f}) {
                Vec3 o{0.3f, 0.7f, 0.6f}, target{x, y, z};
                BvhHit h = bvh_intersect(cb.view(), Ray{o, normalize(target - o), 0.0f, kInf}, 0);
                ASSERT_GE(h.prim, 0);
                EXPECT_LE(h.t, length(target - o) * (1 + 1e-5f));
            }
}

// ---- BVH alone ----

// Every ray against brute force over the same triangle test: the same t exactly.
TEST(Bvh, MatchesBruteForce) {
    for (int which = 0; which < 3; ++which) {
        Mesh m = which == 0 ? cornell() : which == 1 ? sphere(3) : soup(20000, 0.05f, 11, true);
        std::vector<std::string> w;
        Bvh bvh = build_bvh(m.view(), {}, w);
        EXPECT_LE(bvh.stats.max_leaf_size, 8);
        Pcg32 rng = Pcg32::for_path(12, which, 0);
        const int n = which == 2 ? 1500 : 20000;
        int inexact = 0;
        for (int i = 0; i < n; ++i) {
            Vec3 o = Vec3{rng.uniform(), rng.uniform(), rng.uniform()} * 2.4f - vec3(1.2f);
            if (which != 1) o = o * 0.5f + vec3(0.5f);
            Ray r{o, uniform_dir(rng.uniform2()), 0.0f,
                  rng.uniform() < 0.5f ? kInf : rng.uniform()};
            for (uint32_t need : {0u, kBvhNeedCamera, kBvhNeedShadow}) {
                BvhRay br = bvh_ray(r);
                float best = r.tmax;
                int prim = -1;
                for (const BvhTri& tri : bvh.tris) {
                    float t, u, v;
                    if ((tri.flags & need) == need && bvh_hit_triangle(br, tri, best, &t, &u, &v))
                        best = t, prim = tri.prim;
                }
                BvhHit h = bvh_intersect(bvh.view(), r, need);
                ASSERT_EQ(h.prim < 0, prim < 0) << "ray " << i << " need " << need;
                if (prim >= 0 && h.t != best) {  // a tie within rounding culled by a box
                    ++inexact;
                    EXPECT_LE(std::abs(h.t - best), 1e-6f * best) << "ray " << i;
                }
                EXPECT_EQ(bvh_occluded(bvh.view(), r, need), prim >= 0);
            }
        }
        std::printf("mesh %d: %d of %d closest hits a rounding error away from brute force\n",
                    which, inexact, 3 * n);
        EXPECT_LE(inexact, 3 * n / 1000);
    }
}

// tmax exactly at a hit still hits; just short of it does not; tmin at the hit excludes it.
TEST(Bvh, SegmentEnds) {
    Mesh m = sphere(4);
    std::vector<std::string> w;
    Bvh bvh = build_bvh(m.view(), {}, w);
    Pcg32 rng = Pcg32::for_path(13, 0, 0);
    for (int i = 0; i < 20000; ++i) {
        Ray r{Vec3{rng.uniform(), rng.uniform(), rng.uniform()} * 0.8f - vec3(0.4f),
              uniform_dir(rng.uniform2()), 0.0f, kInf};
        BvhHit h = bvh_intersect(bvh.view(), r, 0);
        ASSERT_GE(h.prim, 0);  // inside a closed sphere
        Ray at = r;
        at.tmax = h.t;
        BvhHit h2 = bvh_intersect(bvh.view(), at, 0);
        EXPECT_EQ(h2.t, h.t);
        EXPECT_TRUE(bvh_occluded(bvh.view(), at, 0));
        at.tmax = std::nextafter(h.t, 0.0f);
        EXPECT_FALSE(bvh_occluded(bvh.view(), at, 0));
        Ray past = r;
        past.tmin = h.t;
        BvhHit h3 = bvh_intersect(bvh.view(), past, 0);
        EXPECT_TRUE(h3.prim < 0 || h3.t > h.t);
    }
}

// Origins on a surface: with the shared offset rule the source triangle is never hit again;
// without it (tmin 0) a self-hit can only be at a rounding-sized distance.
TEST(Bvh, OriginOnSurface) {
    Mesh m = cornell();
    Mesh s = sphere(4, {0.5f, 0.5f, 0.5f}, 0.2f);
    for (size_t k = 0; k < s.idx.size(); ++k) s.idx[k] += uint32_t(m.p.size());
    m.p.insert(m.p.end(), s.p.begin(), s.p.end());
    m.idx.insert(m.idx.end(), s.idx.begin(), s.idx.end());
    m.flags.insert(m.flags.end(), s.flags.begin(), s.flags.end());
    std::vector<std::string> w;
    Bvh bvh = build_bvh(m.view(), {}, w);
    Pcg32 rng = Pcg32::for_path(14, 0, 0);
    for (int i = 0; i < 50000; ++i) {
        int t = int(rng.next() % uint32_t(m.count()));
        Vec3 a = m.p[m.idx[3 * t]], b = m.p[m.idx[3 * t + 1]], c = m.p[m.idx[3 * t + 2]];
        Vec2 u = rng.uniform2();
        if (u.x + u.y > 1) u = {1 - u.x, 1 - u.y};
        Vec3 p = a + (b - a) * u.x + (c - a) * u.y, ng = normalize(cross(b - a, c - a));
        Vec3 d = uniform_dir(rng.uniform2());
        BvhHit raw = bvh_intersect(bvh.view(), Ray{p, d, 0.0f, kInf}, 0);
        if (raw.prim == t) EXPECT_LT(raw.t * std::abs(dot(d, ng)), 1e-6f);  // rounding of p
        Ray off{offset_ray_origin(p, ng, d), d, 0.0f, kInf};
        BvhHit h = bvh_intersect(bvh.view(), off, 0);
        EXPECT_NE(h.prim, t) << "self-hit at t=" << h.t;
    }
}

TEST(Bvh, EmptyAndSingleTriangle) {
    std::vector<std::string> w;
    Mesh empty;
    Bvh e = build_bvh(empty.view(), {}, w);
    EXPECT_EQ(e.view().num_nodes, 0);
    EXPECT_LT(bvh_intersect(e.view(), Ray{{0, 0, 0}, {0, 0, 1}}, 0).prim, 0);
    Mesh one;
    one.tri({0, 0, 1}, {1, 0, 1}, {0, 1, 1});
    Bvh b = build_bvh(one.view(), {}, w);
    BvhHit h = bvh_intersect(b.view(), Ray{{0.25f, 0.5f, 0}, {0, 0, 1}}, 0);
    EXPECT_EQ(h.prim, 0);
    EXPECT_EQ(h.t, 1.0f);
    EXPECT_FLOAT_EQ(h.uv.x, 0.25f);  // weight of vertex 1
    EXPECT_FLOAT_EQ(h.uv.y, 0.5f);   // weight of vertex 2
    EXPECT_LT(bvh_intersect(b.view(), Ray{{0.6f, 0.6f, 0}, {0, 0, 1}}, 0).prim, 0);
    one.flags[0] = kCastShadow;  // hidden from the camera
    Bvh hidden = build_bvh(one.view(), {}, w);
    EXPECT_LT(bvh_intersect(hidden.view(), Ray{{0.25f, 0.5f, 0}, {0, 0, 1}}, kBvhNeedCamera).prim,
              0);
    EXPECT_TRUE(bvh_occluded(hidden.view(), Ray{{0.25f, 0.5f, 0}, {0, 0, 1}}));
}

// Triangles whose positions form a geometric series unbalance SAH; the depth stays within the
// traversal stack, and with object medians (forced early here) every triangle stays reachable.
TEST(Bvh, DepthStaysWithinStack) {
    Mesh m;
    for (int k = 0; k < 3000; ++k) {
        float x = std::exp2(-k / 150.0f), s = x * 1e-3f;  // down to 1e-6: no zero areas
        m.tri({x, 0, 0}, {x + s, 0, 0}, {x, s, 0});
    }
    std::vector<std::string> w;
    Bvh bvh = build_bvh(m.view(), {}, w);
    EXPECT_EQ(bvh.stats.triangles, m.count());
    EXPECT_LE(bvh.stats.max_depth, kBvhStackSize);
    BvhBuildOptions median;  // object medians from the second level on: still exact, still shallow
    median.sah_depth = 1;
    Bvh mb = build_bvh(m.view(), median, w);
    EXPECT_LE(mb.stats.max_depth, 1 + int(std::ceil(std::log2(m.count()))));
    for (int k = 0; k < m.count(); k += 7) {
        Vec3 a = m.p[3 * k], b = m.p[3 * k + 1], c = m.p[3 * k + 2];
        Vec3 target = (a + b + c) * (1.0f / 3.0f);
        for (const Bvh* b : {&bvh, &mb}) {
            BvhHit h = bvh_intersect(b->view(), Ray{target + Vec3{0, 0, 1}, {0, 0, -1}}, 0);
            EXPECT_EQ(h.prim, k);
        }
    }
}

TEST(Bvh, BuildIsDeterministic) {
    Mesh m = soup(60000, 0.02f, 15, true);
    std::vector<std::string> w;
    BvhBuildOptions one, many;
    one.threads = 1;
    many.threads = 4;
    Bvh a = build_bvh(m.view(), one, w), b = build_bvh(m.view(), many, w);
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    ASSERT_EQ(a.tris.size(), b.tris.size());
    EXPECT_EQ(0, std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(BvhNode)));
    EXPECT_EQ(0, std::memcmp(a.tris.data(), b.tris.data(), a.tris.size() * sizeof(BvhTri)));
    EXPECT_EQ(a.stats.leaves, b.stats.leaves);
}

// The two-level traversal keeps one stack: the top level's entries below, the bottom level's
// above (tlas.h), so a bottom level may use kBlasStackSize entries; build_blas keeps a bottom
// level within a bound. The geometric series above builds 20 levels deep with SAH: under a
// bound of 15 it is built again with object medians (within it, every triangle still found,
// closest and any-hit), under 5 it is a named error; and the two levels over it find what the
// flat BVH finds, on the shared stack.
TEST(Tlas, BottomLevelsStayWithinTheSharedStack) {
    Mesh m;
    for (int k = 0; k < 3000; ++k) {
        float x = std::exp2(-k / 150.0f), s = x * 1e-3f;
        m.tri({x, 0, 0}, {x + s, 0, 0}, {x, s, 0});
    }
    std::vector<std::string> w;
    const Bvh flat = build_bvh(m.view(), {}, w);
    ASSERT_GT(flat.stats.max_depth - 1, 15);  // the control: SAH alone is deeper than 15
    const Bvh kept = build_blas(m.view(), 1, kBlasStackSize, w);
    EXPECT_EQ(kept.nodes.size(), flat.nodes.size());  // within 48: SAH's, untouched
    const Bvh low = build_blas(m.view(), 1, 15, w);
    EXPECT_LE(low.stats.max_depth - 1, 15);
    EXPECT_EQ(low.stats.triangles, m.count());
    EXPECT_THROW(build_blas(m.view(), 1, 5, w), std::length_error);
    Tlas tl;
    build_tlas_scene(tl, m.view(), {MeshRange{0, m.count(), 0, 3 * m.count()}}, 1, w);
    ASSERT_EQ(tl.blas.size(), 1u);
    EXPECT_LE(tl.blas[0].stats.max_depth - 1, kBlasStackSize);
    const TlasView tv = tl.view();
    for (int k = 0; k < m.count(); k += 7) {
        Vec3 a = m.p[3 * k], b = m.p[3 * k + 1], c = m.p[3 * k + 2];
        const Ray r{(a + b + c) * (1.0f / 3.0f) + Vec3{0, 0, 1}, {0, 0, -1}};
        EXPECT_EQ(tlas_intersect(tv, r, 0).prim, k);
        EXPECT_EQ(bvh_intersect(low.view(), r, 0).prim, k);
        EXPECT_TRUE(tlas_occluded(tv, r, 0));
        EXPECT_TRUE(bvh_occluded(low.view(), r, 0));
        const Ray past{r.o + Vec3{2.0f, 0, 0}, {0, 0, -1}};  // beside every triangle
        EXPECT_FALSE(tlas_occluded(tv, past, 0));
        EXPECT_FALSE(bvh_occluded(low.view(), past, 0));
    }
}
