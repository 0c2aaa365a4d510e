// Transform motion blur's core (scene/motion.h, motion_build.cpp): a step decomposed and
// composed again is the matrix (mirrors too); between two steps of a turn about one axis the
// interpolation is the exact intermediate turn (slerp, as Cycles); and two-level ray queries at
// a time, on the built-in BVH and on Embree, hit what a flat structure over the triangles placed
// by the exact matrix at that time hits (primitive, t to 1e-4 relative), with the top level's
// motion bounds holding the instance throughout.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "backend/backend.h"
#include "backend/cpu/embree_loader.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "scene/motion_build.h"
#include "scene/scene.h"

using namespace lantern;

namespace {

// Row-major 4x4: a turn by angle a about z, scaled by s (per axis), then moved by t.
std::vector<float> turn(double a, const double s[3], const double t[3]) {
    const double c = std::cos(a), n = std::sin(a);
    const double r[3][3] = {{c, -n, 0}, {n, c, 0}, {0, 0, 1}};
    std::vector<float> m(16, 0.0f);
    for (int i = 0; i < 3; ++i) {
        for (int k = 0; k < 3; ++k) m[4 * i + k] = float(r[i][k] * s[k]);
        m[4 * i + 3] = float(t[i]);
    }
    m[15] = 1.0f;
    return m;
}

Transform composed(const MotionStep& st) { return motion_compose(st.q, st.t, st.u); }

struct MotionEnvGuard {
    explicit MotionEnvGuard(const char* v) { setenv("LANTERN_ACCEL", v, 1); }
    ~MotionEnvGuard() { unsetenv("LANTERN_ACCEL"); }
};

}  // namespace

TEST(Motion, DecomposeComposeRoundTrip) {
    Pcg32 rng = Pcg32::for_path(3, 0, 0);
    for (int k = 0; k < 200; ++k) {
        float m[16] = {0};
        for (int i = 0; i < 12; ++i) m[i] = 2.0f * rng.uniform() - 1.0f;
        if (k % 3 == 0) m[0] = -std::fabs(m[0]) - 0.5f, m[5] += 1.0f;  // some mirrors
        MotionStep st;
        if (!decompose_motion_step(m, &st)) continue;  // (a near-singular draw)
        const Transform c = composed(st);
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 4; ++j) EXPECT_NEAR(c.m[i][j], m[4 * i + j], 2e-5f) << k;
    }
    float singular[16] = {1, 0, 0, 0, 2, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};  // columns 0, 1 parallel
    MotionStep st;
    EXPECT_FALSE(decompose_motion_step(singular, &st));
    float nan[16] = {1, 0, 0, NAN, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    EXPECT_FALSE(decompose_motion_step(nan, &st));
}

TEST(Motion, SlerpIsTheIntermediateTurn) {
    const double s[3] = {1.5, 0.5, 2.0}, t0[3] = {0, 0, 0}, t1[3] = {2, -4, 6};
    MotionStep steps[2];
    ASSERT_TRUE(decompose_motion_step(turn(0.2, s, t0).data(), &steps[0]));
    ASSERT_TRUE(decompose_motion_step(turn(0.2 + 2.0, s, t1).data(), &steps[1]));
    for (float f : {0.0f, 0.25f, 0.5f, 0.9f, 1.0f}) {
        const double tf[3] = {2.0 * f, -4.0 * f, 6.0 * f};
        const std::vector<float> want = turn(0.2 + 2.0 * f, s, tf);
        const Transform got = motion_at(steps, 0, 2, f);
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 4; ++j) EXPECT_NEAR(got.m[i][j], want[4 * i + j], 2e-5f) << f;
    }
}

namespace {

void check_motion_hits(const char* accel) {
    MotionEnvGuard g(accel);
    if (std::string(accel) == "embree" && !embree_available()) GTEST_SKIP() << "no Embree";
    // two meshes of random triangles: mesh 0 still, mesh 1 turning and sliding over 3 steps
    Pcg32 rng = Pcg32::for_path(9, 0, 0);
    std::vector<Vec3> p;
    std::vector<uint32_t> idx, mat;
    std::vector<uint8_t> flags;
    std::vector<MeshRange> meshes;
    auto u3 = [&] { return vec3(rng.uniform(), rng.uniform(), rng.uniform()); };
    for (int mesh = 0; mesh < 2; ++mesh) {
        meshes.push_back({int32_t(flags.size()), 200, int32_t(p.size()), 600});
        for (int i = 0; i < 200; ++i) {
            const Vec3 c = u3();
            for (int k = 0; k < 3; ++k) {
                p.push_back(c + (u3() - vec3(0.5f)) * 0.2f);
                idx.push_back(uint32_t(p.size() - 1));
            }
            mat.push_back(0);
            flags.push_back(uint8_t(kVisibleCamera | kCastShadow));
        }
    }
    std::vector<Material> mats(1);
    const double s[3] = {1.0, 1.2, 0.8};
    std::vector<MotionStep> steps(3);
    std::vector<std::vector<float>> exact;
    auto world_at = [&](double f) {  // object-to-world at time f (exported at f = 0.5)
        const double t[3] = {0.6 * f, 0.1, -0.2 * f};
        return turn(-0.4 + 1.6 * f, s, t);
    };
    for (int k = 0; k < 3; ++k)
        ASSERT_TRUE(decompose_motion_step(world_at(0.5 * k).data(), &steps[k]));
    // the given (exported) positions: mesh 1's local triangles placed at f = 0.5
    const std::vector<float> base = world_at(0.5);
    Transform base_t = transform_from_rows(base.data()), base_inv;
    ASSERT_TRUE(transform_inverse(base_t, &base_inv));
    for (int v = meshes[1].vert_begin; v < meshes[1].vert_begin + meshes[1].vert_count; ++v)
        p[v] = base_t.point(p[v]);
    ObjectMotion o{};
    o.tri_begin = meshes[1].tri_begin, o.tri_count = meshes[1].tri_count;
    o.first_step = 0, o.num_steps = 3, o.mesh = 1, o.base = base_t, o.base_inv = base_inv;
    SceneView sv;
    sv.positions = p.data(), sv.indices = idx.data(), sv.tri_flags = flags.data();
    sv.num_triangles = int(flags.size());
    sv.materials = mats.data(), sv.num_materials = 1, sv.tri_material = mat.data();
    sv.motion.steps = steps.data(), sv.motion.objects = &o, sv.motion.num_objects = 1;
    std::vector<std::string> w;
    CpuBackend moving(sv, 2, w, &meshes);
    ASSERT_STREQ(moving.accel(), accel);
    int hits = 0, on_mover = 0, ties = 0, far = 0;
    for (float time : {0.0f, 0.3f, 0.5f, 0.77f, 1.0f}) {
        // the reference: mesh 1 placed by the exact matrix at `time` (a turn, not a slerp)
        std::vector<Vec3> q = p;
        const std::vector<float> wt = world_at(time);
        const Transform to = transform_mul(transform_from_rows(wt.data()), base_inv);
        for (int v = meshes[1].vert_begin; v < meshes[1].vert_begin + meshes[1].vert_count; ++v)
            q[v] = to.point(p[v]);
        SceneView sf = sv;
        sf.positions = q.data();
        sf.motion = MotionView{};
        CpuBackend flat(sf, 2, w);
        for (int i = 0; i < 1500; ++i) {
            float pdf;
            Vec3 o3 = u3() * 1.6f - vec3(0.3f);
            Vec3 d = sample_uniform_sphere(rng.uniform2(), &pdf);
            if (i % 2 == 0) {  // aim at a point of a moving triangle where it is at `time`
                const int t = o.tri_begin + int(rng.next() % uint32_t(o.tri_count));
                const Vec3 a = q[idx[3 * t]], b = q[idx[3 * t + 1]], c = q[idx[3 * t + 2]];
                d = (a + b + c) * (1.0f / 3.0f) - o3;
            }
            Ray ray{o3, d, 1e-4f, kInf};
            ray.time = time;
            const HitRecord hf = flat.intersect(ray, RayKind::kIndirect);
            const HitRecord hm = moving.intersect(ray, RayKind::kIndirect);
            hits += hf.prim >= 0;
            on_mover += hf.prim >= o.tri_begin;
            EXPECT_EQ(flat.occluded(ray), moving.occluded(ray)) << accel << " t " << time;
            if (hf.prim != hm.prim) {
                ASSERT_TRUE(hf.prim >= 0 && hm.prim >= 0)
                    << accel << " time " << time << " ray " << i << " flat " << hf.prim
                    << " moving " << hm.prim;
                EXPECT_NEAR(hf.t, hm.t, 1e-4f * hf.t);
                ++ties;
                continue;
            }
            // the same triangle at the same place: the two hit points apart along its normal
            // by float rounding only (Embree's instance maps through its own composition)
            if (hf.prim >= 0) {
                const int t = hf.prim;
                const Vec3 n = normalize(cross(q[idx[3 * t + 1]] - q[idx[3 * t]],
                                               q[idx[3 * t + 2]] - q[idx[3 * t]]));
                const float off = std::fabs((hf.t - hm.t) * dot(d, n));
                if (off > 3e-5f) ++far;
            }
        }
    }
    EXPECT_GT(on_mover, 2500);  // most aimed rays hit the moving mesh
    EXPECT_LT(ties, 20);
    EXPECT_EQ(far, 0) << accel << ": hits off the moved triangle's plane by over 3e-5";
    EXPECT_GT(hits, 3000);
}

}  // namespace

TEST(Motion, BuiltinBvhHitsTheMovedTriangles) { check_motion_hits("bvh"); }
TEST(Motion, EmbreeHitsTheMovedTriangles) { check_motion_hits("embree"); }
