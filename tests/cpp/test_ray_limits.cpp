// Rays and triangles at the edge of what the CPU accelerators take (scene/scene_limits.h):
// EmbreeAccel::prepare() moves a ray from beyond kMaxCoordinate into range and refuses
// non-finite ones, so Embree's `ray.valid()` assert is never reached; huge triangles are not
// taken for degenerate; normalize() survives an overflowing squared length. A regression here
// aborts the test binary (Embree's assert), which ctest reports as a failure.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "backend/cpu/bvh_accel.h"
#include "backend/cpu/embree_accel.h"
#include "backend/cpu/embree_loader.h"
#include "scene/scene_limits.h"

using namespace lantern;

namespace {

struct Quad {  // two triangles in the plane z = 0, x and y in [-h, h]
    std::vector<Vec3> p;
    std::vector<uint32_t> idx{0, 1, 2, 0, 2, 3}, tri_mat{0, 0};
    std::vector<uint8_t> flags{kVisibleCamera | kCastShadow, kVisibleCamera | kCastShadow};
    std::vector<Material> mats{Material{}};
    explicit Quad(float h) : p{{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}} {}
    SceneView view() const {
        SceneView s;
        s.positions = p.data(), s.indices = idx.data(), s.tri_flags = flags.data();
        s.num_triangles = 2;
        s.materials = mats.data(), s.num_materials = 1;
        s.tri_material = tri_mat.data();
        return s;
    }
};

const float kNaN = std::numeric_limits<float>::quiet_NaN();
const Vec3 kCube[2] = {vec3(-kMaxCoordinate), vec3(kMaxCoordinate)};

}  // namespace

TEST(RayLimits, PrepareLeavesRaysInRangeAlone) {
    float o[3], tn, tf, shift;
    Ray r{{1, 2, 3}, {0, 0, -1}, 0.5f, 10.0f};
    ASSERT_TRUE(EmbreeAccel::prepare(r, kCube, o, &tn, &tf, &shift));
    EXPECT_EQ(o[0], 1.0f);
    EXPECT_EQ(o[2], 3.0f);
    EXPECT_EQ(tn, 0.5f);
    EXPECT_EQ(tf, 10.0f);
    EXPECT_EQ(shift, 0.0f);
}

TEST(RayLimits, PrepareMovesAFarOriginToTheCube) {
    float o[3], tn, tf, shift;
    Ray r{{0, 0, 2e19f}, {0, 0, -1}, 0.0f, kInf};
    ASSERT_TRUE(EmbreeAccel::prepare(r, kCube, o, &tn, &tf, &shift));
    EXPECT_FLOAT_EQ(o[2], kMaxCoordinate);
    EXPECT_LE(std::fabs(o[0]), kMaxCoordinate);
    EXPECT_NEAR(double(shift), 2e19 - 1e18, 1e13);
    EXPECT_EQ(tn, 0.0f);
    // pointing away from the cube, or a range that ends before it: nothing to trace
    Ray away{{0, 0, 2e19f}, {0, 0, 1}, 0.0f, kInf};
    EXPECT_FALSE(EmbreeAccel::prepare(away, kCube, o, &tn, &tf, &shift));
    Ray short_range{{0, 0, 2e19f}, {0, 0, -1}, 0.0f, 1e18f};
    EXPECT_FALSE(EmbreeAccel::prepare(short_range, kCube, o, &tn, &tf, &shift));
}

TEST(RayLimits, PrepareMovesAFarOriginToTheSceneBox) {
    float o[3], tn, tf, shift;
    const Vec3 box[2] = {{-1, -1, -1}, {1, 1, 1}};
    Ray r{{0.5f, 0, 2e19f}, {0, 0, -1}, 0.0f, kInf};
    ASSERT_TRUE(EmbreeAccel::prepare(r, box, o, &tn, &tf, &shift));
    EXPECT_FLOAT_EQ(o[0], 0.5f);
    EXPECT_NEAR(o[2], 1.0f, 1e-6f);
    EXPECT_EQ(shift, float(2e19 - 1.0));
    const Vec3 empty[2] = {vec3(1), vec3(-1)};
    EXPECT_FALSE(EmbreeAccel::prepare(r, empty, o, &tn, &tf, &shift));
    Ray beside{{5, 0, 2e19f}, {0, 0, -1}, 0.0f, kInf};  // passes the box
    EXPECT_FALSE(EmbreeAccel::prepare(beside, box, o, &tn, &tf, &shift));
}

TEST(RayLimits, PrepareRefusesNonFiniteRays) {
    float o[3], tn, tf, shift;
    const Ray bad[] = {{{kNaN, 0, 0}, {0, 0, 1}, 0, 1},
                       {{0, 0, 0}, {kNaN, 0, 1}, 0, 1},
                       {{0, 0, 0}, {0, 0, 1}, 0, kNaN},
                       {{0, 0, 0}, {0, 0, 1}, 0, -1},
                       {{0, 0, std::numeric_limits<float>::infinity()}, {0, 0, -1}, 0, kInf},
                       {{0, 0, 0}, {0, 0, 1e30f}, 0, 1}};
    for (const Ray& r : bad) EXPECT_FALSE(EmbreeAccel::prepare(r, kCube, o, &tn, &tf, &shift));
    Ray nan_tmin{{0, 0, 0}, {0, 0, 1}, kNaN, 1};  // tmin NaN: from 0
    ASSERT_TRUE(EmbreeAccel::prepare(nan_tmin, kCube, o, &tn, &tf, &shift));
    EXPECT_EQ(tn, 0.0f);
}

TEST(RayLimits, EmbreeTakesFarAndBrokenRays) {
    if (!embree_available()) GTEST_SKIP() << "Embree: " << embree_version();
    Quad q(1e6f);
    std::vector<std::string> warnings;
    EmbreeAccel accel(q.view(), warnings);
    // a camera 2e19 above the quad: the hit is the quad, at its true distance
    HitRecord h = accel.intersect(Ray{{0.5e6f, 0, 2e19f}, {0, 0, -1}, 0.0f, kInf},
                                  RayKind::kCamera);
    EXPECT_GE(h.prim, 0);
    EXPECT_NEAR(double(h.t), 2e19, 2e19 * 1e-6);
    EXPECT_TRUE(accel.occluded(Ray{{0.5e6f, 0, 2e19f}, {0, 0, -1}, 0.0f, 3e19f}));
    EXPECT_FALSE(accel.occluded(Ray{{0.5e6f, 0, 2e19f}, {0, 0, -1}, 0.0f, 1e19f}));
    // beyond Embree's FLT_LARGE the unguarded call aborted; these must simply miss
    EXPECT_LT(accel.intersect(Ray{{0, 0, 1e30f}, {0, 1, 0}, 0, kInf}, RayKind::kIndirect).prim, 0);
    EXPECT_LT(accel.intersect(Ray{{kNaN, 0, 1}, {0, 0, -1}, 0, kInf}, RayKind::kIndirect).prim, 0);
    EXPECT_LT(accel.intersect(Ray{{0, 0, 1}, {0, 0, -1}, 0, kNaN}, RayKind::kIndirect).prim, 0);
    // a non-finite shadow ray carries no light; a far one that misses the cube is free
    EXPECT_TRUE(accel.occluded(Ray{{kNaN, 0, 1}, {0, 0, -1}, 0, 10}));
    EXPECT_FALSE(accel.occluded(Ray{{0, 0, 1e30f}, {0, 0, 1}, 0, kInf}));
}

TEST(RayLimits, BuiltInBvhTakesTheSameFarRays) {
    Quad q(1e6f);
    std::vector<std::string> warnings;
    BvhAccel accel(q.view(), 1, warnings);
    HitRecord h = accel.intersect(Ray{{0.5e6f, 0, 2e19f}, {0, 0, -1}, 0.0f, kInf},
                                  RayKind::kCamera);
    EXPECT_GE(h.prim, 0);
    EXPECT_NEAR(double(h.t), 2e19, 2e19 * 1e-6);
    EXPECT_LT(accel.intersect(Ray{{kNaN, 0, 1}, {0, 0, -1}, 0, kInf}, RayKind::kIndirect).prim, 0);
    EXPECT_TRUE(accel.occluded(Ray{{kNaN, 0, 1}, {0, 0, -1}, 0, 10}));
    EXPECT_FALSE(accel.occluded(Ray{{0, 0, 1e30f}, {0, 0, 1}, 0, kInf}));
}

TEST(RayLimits, HugeTrianglesAreNotDegenerate) {
    // edges of 2e10 m: the float cross product's squared length (1.6e41) overflows
    EXPECT_TRUE(std::isinf(length_sq(cross(Vec3{2e10f, 0, 0}, Vec3{0, 2e10f, 0}))));
    EXPECT_NEAR(triangle_area2({0, 0, 0}, {2e10f, 0, 0}, {0, 2e10f, 0}), 4e20, 4e20 * 1e-6);
    EXPECT_EQ(triangle_area2({0, 0, 0}, {1, 1, 1}, {2, 2, 2}), 0.0);
    EXPECT_NEAR(max_edge({0, 0, 0}, {3e12f, 0, 0}, {0, 4e12f, 0}), 5e12, 5e12 * 1e-6);
    if (!embree_available()) GTEST_SKIP() << "Embree: " << embree_version();
    Quad q(1e10f);
    std::vector<std::string> warnings;
    EmbreeAccel accel(q.view(), warnings);
    for (const std::string& w : warnings) EXPECT_EQ(w.find("degenerate"), std::string::npos) << w;
    HitRecord h = accel.intersect(Ray{{1e9f, 0, 1e9f}, {0, 0, -1}, 0, kInf}, RayKind::kCamera);
    EXPECT_GE(h.prim, 0);
    EXPECT_NEAR(h.t, 1e9f, 1e3f);
}

TEST(RayLimits, NormalizeSurvivesOverflowAndUnderflow) {
    Vec3 n = normalize(cross(Vec3{2e10f, 0, 0}, Vec3{0, 2e10f, 0}));
    EXPECT_FLOAT_EQ(n.z, 1.0f);
    EXPECT_FLOAT_EQ(n.x, 0.0f);
    Vec3 big = normalize(Vec3{3e30f, -4e30f, 0});
    EXPECT_NEAR(big.x, 0.6f, 1e-6f);
    EXPECT_NEAR(big.y, -0.8f, 1e-6f);
    Vec3 tiny = normalize(Vec3{0, 3e-30f, 4e-30f});
    EXPECT_NEAR(tiny.y, 0.6f, 1e-6f);
    EXPECT_NEAR(tiny.z, 0.8f, 1e-6f);
    // the fallbacks keep their old answer
    EXPECT_FLOAT_EQ(normalize(Vec3{0, 0, 0}).z, 1.0f);
    EXPECT_FLOAT_EQ(normalize(Vec3{kNaN, 0, 0}).z, 1.0f);
    // and ordinary vectors the old bits
    Vec3 v{0.3f, -1.7f, 2.9f};
    const float inv = 1.0f / std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    EXPECT_EQ(normalize(v).x, v.x * inv);
}
