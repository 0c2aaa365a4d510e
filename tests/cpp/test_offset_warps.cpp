// Ray offsets against real float hit points on triangles at small and large scales (the side of
// the plane judged in double precision), and the sphere solid-angle warp.
#include <gtest/gtest.h>

#include <cmath>

#include "core/offset.h"
#include "core/rng.h"
#include "core/sampling.h"

using namespace lantern;

namespace {

struct DVec {
    double x, y, z;
};
DVec dv(Vec3 v) { return {v.x, v.y, v.z}; }
DVec dsub(DVec a, DVec b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
DVec dcross(DVec a, DVec b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
double ddot(DVec a, DVec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// Fraction of offset origins that end strictly on the requested side of the triangle's plane.
double fraction_on_side(float scale, float sign) {
    Pcg32 rng = Pcg32::for_path(uint64_t(scale * 1000.0f), 1, 2);
    const int n = 20000;
    int good = 0;
    for (int i = 0; i < n; ++i) {
        // a triangle somewhere in a box of the given scale, away from the origin
        Vec3 c = vec3(rng.uniform() + 0.5f, rng.uniform() - 0.5f, rng.uniform() + 1.0f) * scale;
        Vec3 a = c + vec3(rng.uniform(), rng.uniform(), rng.uniform()) * (0.3f * scale);
        Vec3 b = c + vec3(-rng.uniform(), rng.uniform(), rng.uniform()) * (0.3f * scale);
        Vec3 d = c + vec3(rng.uniform(), -rng.uniform(), -rng.uniform()) * (0.3f * scale);
        Vec2 bc = sample_triangle(rng.uniform2());
        // the hit point as a renderer computes it: float barycentric interpolation
        Vec3 p = a * (1.0f - bc.x - bc.y) + b * bc.x + d * bc.y;
        Vec3 ng = normalize(cross(b - a, d - a));
        Vec3 q = offset_ray_origin(p, ng, ng * sign);
        DVec nd = dcross(dsub(dv(b), dv(a)), dsub(dv(d), dv(a)));
        double side = ddot(dsub(dv(q), dv(a)), nd);
        good += sign * side > 0.0;
    }
    return double(good) / n;
}

}  // namespace

TEST(Offset, OriginsLeaveTrianglePlanesAtSmallAndLargeScales) {
    for (float scale : {1e-3f, 1.0f, 1e4f}) {
        EXPECT_EQ(fraction_on_side(scale, 1.0f), 1.0) << "scale " << scale;
        EXPECT_EQ(fraction_on_side(scale, -1.0f), 1.0) << "scale " << scale;
    }
}

TEST(Offset, DisplacementIsSmall) {
    Vec3 n = normalize(vec3(0.2f, 0.3f, 0.9f));
    // far from the origin: at most 256 ulps per component, so relatively tiny
    Vec3 p = vec3(0.37f, -1.3f, 2.9f) * 1e4f;
    EXPECT_LT(length(offset_ray_origin(p, n, n) - p) / length(p), 1e-4f);
    // near the origin (|p| < 1/32): a fixed step of 1/65536 along the normal
    Vec3 s = vec3(0.37f, -1.3f, 2.9f) * 1e-3f;
    EXPECT_LT(length(offset_ray_origin(s, n, n) - s), 2e-5f);
}

TEST(Sampling, SphereSolidAngleWarp) {
    const float dist = 3.0f, radius = 1.0f;
    const float cos_max = std::sqrt(1.0f - radius * radius / (dist * dist));
    const double solid_angle = 2.0 * kPi * (1.0 - cos_max);
    Pcg32 rng = Pcg32::for_path(2, 3, 4);
    for (int i = 0; i < 10000; ++i) {
        float pdf;
        Vec3 w = sample_sphere_solid_angle(rng.uniform2(), dist * dist, radius, &pdf);
        ASSERT_NEAR(pdf, 1.0 / solid_angle, 1e-4);
        // the ray from (0,0,-dist) towards the centre at the origin hits the sphere
        Vec3 o = vec3(0, 0, -dist);
        float b = dot(o, w), c = dot(o, o) - radius * radius;
        ASSERT_GE(b * b - c, -1e-4f);
    }
    float pdf = 1.0f;
    sample_sphere_solid_angle(rng.uniform2(), 0.25f, radius, &pdf);  // inside: no sample
    EXPECT_EQ(pdf, 0.0f);
}
