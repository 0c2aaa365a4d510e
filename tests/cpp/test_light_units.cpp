// Light units beyond the basics in test_core.cpp: the spot cone (Cycles' smoothstep over
// (cos - cos_half) / ((1 - cos_half) * blend)), the sun's irradiance S on a perpendicular
// surface, and the soft-falloff point light's irradiance I / (d^2 + r^2).
#include <gtest/gtest.h>

#include <cmath>

#include "core/rng.h"
#include "scene/lights.h"
#include "scene/scene.h"

using namespace lantern;

namespace {

// Monte Carlo irradiance at p with normal +Z from light 0 of the scene, through sample_light.
double irradiance(const SceneView& v, Vec3 p, int n = 40000) {
    Pcg32 rng = Pcg32::for_path(3, 1, 4);
    double e = 0.0;
    for (int i = 0; i < n; ++i) {
        LightSample ls = sample_light(v, v.lights[0], p, rng.uniform2(), 0.0f);
        if (!ls.valid || ls.wi.z <= 0.0f) continue;
        e += ls.le.x * ls.wi.z / ls.pdf_w;
    }
    return e / n;
}

}  // namespace

TEST(LightUnits, SpotConeIsCyclesSmoothstep) {
    SceneInput in;
    LightInput l;
    l.type = "spot";  // identity to_world: the cone points down local -Z = world -Z
    l.power = {10, 10, 10};
    l.spot_size = 1.0f;
    l.spot_blend = 0.5f;
    in.lights.push_back(l);
    HostScene s(in);
    const Light& light = s.view().lights[0];
    const float cos_half = std::cos(0.5f), smooth = (1.0f - cos_half) * 0.5f;
    EXPECT_NEAR(spot_attenuation(light, vec3(0, 0, -1)), 1.0f, 1e-6f);          // on the axis
    auto dir_at = [](float cos_t) { return vec3(std::sqrt(1 - cos_t * cos_t), 0, -cos_t); };
    EXPECT_EQ(spot_attenuation(light, dir_at(cos_half - 1e-3f)), 0.0f);         // outside
    EXPECT_NEAR(spot_attenuation(light, dir_at(cos_half + 0.5f * smooth)), 0.5f, 1e-3f);
    float t = 0.25f, expect = t * t * (3 - 2 * t);
    EXPECT_NEAR(spot_attenuation(light, dir_at(cos_half + t * smooth)), expect, 1e-3f);
    // a delta spot on the axis: intensity P / (4 pi) over d^2
    Pcg32 rng = Pcg32::for_path(0, 0, 0);
    LightSample ls = sample_light(s.view(), light, vec3(0, 0, -2), rng.uniform2(), 0.0f);
    ASSERT_TRUE(ls.valid);
    EXPECT_NEAR(ls.le.x, 10.0f / (4.0f * kPi * 4.0f), 1e-5f);
}

TEST(LightUnits, SunIrradianceIsStrength) {
    for (float angle : {0.0f, 0.1f, 0.5f}) {
        SceneInput in;
        LightInput l;
        l.type = "sun";
        l.direction = {0, 0, -1};  // travels down onto a surface facing +Z
        l.strength = {3, 3, 3};
        l.angle = angle;
        in.lights.push_back(l);
        HostScene s(in);
        EXPECT_NEAR(irradiance(s.view(), vec3(0, 0, 0)), 3.0, 3.0 * 1e-3) << "angle " << angle;
        if (angle > 0.0f) {
            float h = 0.5f * angle;
            EXPECT_NEAR(s.view().lights[0].radiance.x, 3.0f / (kPi * std::sin(h) * std::sin(h)),
                        1e-3f * s.view().lights[0].radiance.x);
        }
    }
}

TEST(LightUnits, SoftFalloffPointIrradiance) {
    const float d = 2.0f, r = 0.5f, P = 50.0f;
    SceneInput in;
    LightInput l;
    l.type = "point";
    l.position = {0, 0, d};
    l.radius = r;
    l.power = {P, P, P};
    l.soft_falloff = true;
    in.lights.push_back(l);
    HostScene s(in);
    const double intensity = P / (4.0 * kPi);
    EXPECT_NEAR(irradiance(s.view(), vec3(0, 0, 0)), intensity / (d * d + r * r),
                0.01 * intensity / (d * d + r * r));
}
