// Two-level ray queries (accel/tlas.h, EmbreeAccel's instances) against the flattened scene:
// a mesh moved, rotated and scaled through CpuBackend::move_instance() gives the hits of a flat
// structure over the moved triangles (t, point, normal, primitive, to 1e-5 relative), on the
// built-in BVH and on Embree, without building a bottom level; and HostScene::move_mesh()
// writes the arrays a fresh scene of the moved mesh holds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "backend/backend.h"
#include "backend/cpu/embree_loader.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "test_soup.h"
#include "scene/scene.h"

using namespace lantern;

namespace {

using Soup = soup_test::TriangleSoup;

// Three meshes of n random triangles each in the unit cube; mixed visibility flags per mesh;
// every fifth triangle alpha-tested (alpha 0.4).
Soup soup(int n, uint64_t seed) {
    Soup m;
    m.mats.resize(2);
    m.mats[1].transparency = 0.6f;
    Pcg32 rng = Pcg32::for_path(seed, 0, 0);
    auto u3 = [&] { return vec3(rng.uniform(), rng.uniform(), rng.uniform()); };
    const uint8_t mesh_flags[3] = {kVisibleCamera | kCastShadow, kCastShadow, kVisibleCamera};
    for (int mesh = 0; mesh < 3; ++mesh) {
        MeshRange r{int32_t(m.flags.size()), n, int32_t(m.p.size()), 3 * n};
        for (int i = 0; i < n; ++i) {
            Vec3 c = u3();
            for (int k = 0; k < 3; ++k) {
                m.p.push_back(c + (u3() - vec3(0.5f)) * 0.15f);
                m.idx.push_back(uint32_t(m.p.size() - 1));
            }
            const bool alpha = i % 5 == 0;
            m.tri_mat.push_back(alpha ? 1 : 0);
            m.flags.push_back(uint8_t(mesh_flags[mesh] | (alpha ? kAlphaTested : 0)));
        }
        m.meshes.push_back(r);
    }
    return m;
}

// Rotation about a tilted axis, non-uniform scale (0.7, 1.3, 0.9), translation.
Transform moved_transform() {
    const double a = 0.6, c = std::cos(a), s = std::sin(a);
    const double rot[3][3] = {{c, -s, 0}, {s * 0.8, c * 0.8, -0.6}, {s * 0.6, c * 0.6, 0.8}};
    const double scale[3] = {0.7, 1.3, 0.9}, shift[3] = {0.2, -0.1, 0.15};
    Transform t{};
    for (int r = 0; r < 3; ++r) {
        for (int k = 0; k < 3; ++k) t.m[r][k] = float(rot[r][k] * scale[k]);
        t.m[r][3] = float(shift[r]);
    }
    return t;
}

Vec3 tri_normal(const SceneView& s, int32_t t) {
    const Vec3 a = s.positions[s.indices[3 * t]], b = s.positions[s.indices[3 * t + 1]],
               c = s.positions[s.indices[3 * t + 2]];
    return normalize(cross(b - a, c - a));
}

struct EnvGuard {
    explicit EnvGuard(const char* v) { setenv("LANTERN_ACCEL", v, 1); }
    ~EnvGuard() { unsetenv("LANTERN_ACCEL"); }
};

void check_moved_hits(const char* accel) {
    EnvGuard g(accel);
    Soup given = soup(300, 11);
    Soup moved = given;
    const Transform m = moved_transform();
    const MeshRange& r = given.meshes[1];
    for (int v = r.vert_begin; v < r.vert_begin + r.vert_count; ++v)
        moved.p[v] = m.point(given.p[v]);
    std::vector<std::string> w;
    const SceneView sg = given.view(), sm = moved.view();
    CpuBackend inst(sg, 2, w, &given.meshes), flat(sm, 2, w);
    ASSERT_STREQ(inst.accel(), accel);
    ASSERT_TRUE(inst.instanced());
    EXPECT_FALSE(flat.instanced());
    const int64_t builds = inst.bottom_builds();
    EXPECT_GE(builds, 3);
    ASSERT_TRUE(inst.move_instance(1, m));
    EXPECT_EQ(inst.bottom_builds(), builds) << "a move built a bottom level";
    Transform singular{};
    EXPECT_FALSE(inst.move_instance(1, singular));
    EXPECT_FALSE(flat.move_instance(1, m));

    Pcg32 rng = Pcg32::for_path(5, 0, 0);
    const int n = 6000;
    int hits[3] = {0, 0, 0}, on_moved = 0, ties = 0, occluded = 0;
    for (int i = 0; i < n; ++i) {
        float pdf;
        // half the rays aim at an interior point of a moved triangle
        auto u = [&] { return rng.uniform() * 1.6f - 0.3f; };
        Vec3 o{u(), u(), u()};
        Vec3 d = sample_uniform_sphere(rng.uniform2(), &pdf);
        if (i % 2 == 0) {
            const int t = r.tri_begin + int(rng.next() % uint32_t(r.tri_count));
            float b1 = 0.1f + 0.8f * rng.uniform(), b2 = (0.9f - b1) * rng.uniform() + 0.05f;
            const Vec3 a = sm.positions[sm.indices[3 * t]],
                       b = sm.positions[sm.indices[3 * t + 1]],
                       c = sm.positions[sm.indices[3 * t + 2]];
            d = (a * (1.0f - b1 - b2) + b * b1 + c * b2) - o;  // unnormalised on purpose
        }
        const Ray ray{o, d, 1e-4f, kInf};
        for (int k = 0; k < 3; ++k) {
            const HitRecord hf = flat.intersect(ray, RayKind(k));
            const HitRecord hi = inst.intersect(ray, RayKind(k));
            hits[k] += hf.prim >= 0;
            if (hf.prim != hi.prim) {  // only a tie of two triangles at one distance
                ASSERT_TRUE(hf.prim >= 0 && hi.prim >= 0) << accel << " ray " << i << " kind " << k
                    << " flat " << hf.prim << " t " << hf.t << " inst " << hi.prim << " t " << hi.t;
                EXPECT_NEAR(hf.t, hi.t, 1e-5f * hf.t) << accel << " ray " << i;
                ++ties;
                continue;
            }
            if (hf.prim < 0) continue;
            on_moved += hf.prim >= r.tri_begin && hf.prim < r.tri_begin + r.tri_count;
            // 1e-5 relative to the coordinates, over the cosine of incidence: a hit's error is
            // the triangle's rounding (an ulp of its vertices, in either space) divided by it
            const float cos_i = std::fabs(dot(normalize(ray.d), tri_normal(sm, hf.prim)));
            const float rel = 1e-5f / std::max(cos_i, 1e-3f);
            const Vec3 pf = ray.o + ray.d * hf.t, pi = ray.o + ray.d * hi.t;
            const float scale = length(pf) + length(ray.o) + 1.0f;
            EXPECT_NEAR(hi.t, hf.t, rel * scale / length(ray.d)) << accel << " ray " << i;
            EXPECT_LE(length(pi - pf), rel * scale) << accel << " ray " << i;
            EXPECT_NEAR(hi.uv.x, hf.uv.x, 10.0f * rel) << accel << " ray " << i;  // edges ~0.1
            EXPECT_NEAR(hi.uv.y, hf.uv.y, 10.0f * rel) << accel << " ray " << i;
            // the instanced mesh's normal: object-space normal through M^-T
            const Vec3 ng = tri_normal(sg, hi.prim), nf = tri_normal(sm, hf.prim);
            Vec3 ni = ng;
            if (hi.prim >= r.tri_begin && hi.prim < r.tri_begin + r.tri_count) {
                Transform inv;
                ASSERT_TRUE(invert_affine(m, &inv));
                ni = normalize(Vec3{inv.m[0][0] * ng.x + inv.m[1][0] * ng.y + inv.m[2][0] * ng.z,
                                    inv.m[0][1] * ng.x + inv.m[1][1] * ng.y + inv.m[2][1] * ng.z,
                                    inv.m[0][2] * ng.x + inv.m[1][2] * ng.y + inv.m[2][2] * ng.z});
            }
            // 1e-5 times the triangle's conditioning (longest edge^2 / twice its area)
            const Vec3 a = sm.positions[sm.indices[3 * hf.prim]],
                       b = sm.positions[sm.indices[3 * hf.prim + 1]],
                       c = sm.positions[sm.indices[3 * hf.prim + 2]];
            const float l2 = std::max({dot(b - a, b - a), dot(c - b, c - b), dot(a - c, a - c)});
            const float cond = l2 / length(cross(b - a, c - a));
            EXPECT_LE(length(ni - nf), 1e-5f * std::max(1.0f, cond)) << accel << " ray " << i;
        }
        Ray seg = ray;
        seg.tmax = 0.5f;
        const bool of = flat.occluded(seg);
        occluded += of;
        EXPECT_EQ(inst.occluded(seg), of) << accel << " ray " << i;
    }
    for (int k = 0; k < 3; ++k) EXPECT_GT(hits[k], n / 4) << accel << " kind " << k;
    EXPECT_GT(on_moved, n / 4) << accel;  // the moved mesh is really hit
    EXPECT_GT(occluded, n / 20) << accel;
    EXPECT_LE(ties, n / 1000) << accel;
}

}  // namespace

TEST(Instances, BuiltInBvhMovedMeshHitsAsTheFlatScene) { check_moved_hits("bvh"); }

TEST(Instances, EmbreeMovedMeshHitsAsTheFlatScene) {
    if (!embree_available()) GTEST_SKIP() << embree_version();
    check_moved_hits("embree");
}

// ---- HostScene::move_mesh ----

namespace {

SceneInput two_meshes(const Transform* moved) {
    SceneInput in;
    in.materials.resize(2);
    in.materials[1].emission = {1, 1, 1};
    for (int mesh = 0; mesh < 3; ++mesh) {
        MeshInput m;
        m.name = "m" + std::to_string(mesh);
        Pcg32 rng = Pcg32::for_path(uint64_t(mesh), 0, 0);
        for (int v = 0; v < 30; ++v) {
            Vec3 p{rng.uniform(), rng.uniform(), rng.uniform()};
            if (mesh == 0) p = p * 6.0f - vec3(2.5f);  // the scene's extent: the others inside
            Vec3 n = normalize(Vec3{rng.uniform() - 0.5f, rng.uniform() - 0.5f, 0.7f});
            Vec3 t = normalize(Vec3{1.0f, rng.uniform() - 0.5f, rng.uniform() - 0.5f});
            if (moved && mesh == 1) {  // as export/mesh.py places it (in double there)
                p = moved->point(p);
                Transform inv;
                invert_affine(*moved, &inv);
                n = normalize(Vec3{inv.m[0][0] * n.x + inv.m[1][0] * n.y + inv.m[2][0] * n.z,
                                   inv.m[0][1] * n.x + inv.m[1][1] * n.y + inv.m[2][1] * n.z,
                                   inv.m[0][2] * n.x + inv.m[1][2] * n.y + inv.m[2][2] * n.z});
                t = normalize(moved->vector(t));
            }
            m.positions.insert(m.positions.end(), {p.x, p.y, p.z});
            m.normals.insert(m.normals.end(), {n.x, n.y, n.z});
            m.tangents.insert(m.tangents.end(), {t.x, t.y, t.z, 1.0f});
        }
        for (uint32_t t = 0; t < 10; ++t) {
            m.indices.insert(m.indices.end(), {3 * t, 3 * t + 1, 3 * t + 2});
            m.material_ids.push_back(mesh == 2 ? 1u : 0u);  // mesh 2 emits
        }
        in.meshes.push_back(m);
    }
    return in;
}

}  // namespace

TEST(Instances, MoveMeshWritesTheArraysOfAFreshScene) {
    const Transform m = moved_transform();
    HostScene moved(two_meshes(nullptr)), fresh(two_meshes(&m));
    ASSERT_EQ(moved.mesh_ranges().size(), 3u);
    EXPECT_EQ(moved.mesh_ranges()[1].tri_begin, 10);
    for (int pass = 0; pass < 2; ++pass) {  // a second move starts from the given arrays too
        ASSERT_TRUE(moved.move_mesh(1, m));
    }
    const SceneView a = moved.view(), b = fresh.view();
    for (int v = 0; v < 90; ++v) {
        EXPECT_LE(length(a.positions[v] - b.positions[v]), 1e-5f) << v;
        EXPECT_LE(length(a.normals[v] - b.normals[v]), 1e-5f) << v;
        for (int c = 0; c < 4; ++c)
            EXPECT_NEAR(a.tangents[4 * v + c], b.tangents[4 * v + c], 1e-5f);
    }
    EXPECT_FALSE(moved.move_mesh(2, m)) << "an emitting mesh moved in place";
    Transform mirror{};
    mirror.m[0][0] = -1.0f, mirror.m[1][1] = 1.0f, mirror.m[2][2] = 1.0f;
    EXPECT_FALSE(moved.move_mesh(0, mirror));
    Transform far = m;
    far.m[0][3] = 50.0f;  // out of the sphere distant lights' paths cover
    EXPECT_FALSE(moved.move_mesh(0, far));
    EXPECT_FALSE(moved.move_mesh(3, m));
    EXPECT_LE(length(a.positions[0] - b.positions[0]), 1e-5f) << "a refused move changed mesh 0";
}
