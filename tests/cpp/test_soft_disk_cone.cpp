// Next-event estimation's sampling of a soft-falloff point or spot light (Blender's default: a
// disk of radius r through the centre, facing the receiver) by the solid angle the disk
// subtends (sample_light, scene/lights.h), against an area sampler of the same disk written
// here: samples on the facing disk with the pdf light_pdf_w gives their hits and the area
// density soft_cone_area_pdf gives the bidirectional weights, the same estimates (the analytic
// irradiance I / (d^2 + r^2), the area sampler's mean for a spot's cone), and the variance near
// the bulb that made fireflies in fog (docs/volumes.md).
#include <gtest/gtest.h>

#include <cmath>

#include "core/rng.h"
#include "scene/lights.h"
#include "scene/scene.h"

using namespace lantern;

namespace {

constexpr float kR = 0.1f;  // Blender's default bulb radius

HostScene soft_scene(const char* type) {
    SceneInput in;
    LightInput l;
    l.type = type;
    l.position = {0.3f, -0.2f, 1.5f};
    l.radius = kR;
    l.power = {60, 60, 60};
    l.soft_falloff = true;
    if (std::string(type) == "spot") {  // pointing down (identity rotation: local -Z)
        l.spot_size = 1.6f;
        l.spot_blend = 0.4f;
        for (int k = 0; k < 16; ++k) l.to_world[k] = (k % 5 == 0) ? 1.0f : 0.0f;
        l.to_world[3] = 0.3f;
        l.to_world[7] = -0.2f;
        l.to_world[11] = 1.5f;
    }
    in.lights.push_back(l);
    return HostScene(in);
}

struct Estimate {
    double mean, se;
};

// The reference: the disk facing p sampled uniformly by area (pdf 1 / (pi r^2) converted to
// solid angle), the spot's cone applied along the sampled ray.
LightSample area_sample(const Light& l, Vec3 p, Vec2 u) {
    LightSample ls{};
    const Vec3 dir = normalize(l.position - p);
    const Frame f = Frame::from_normal(-dir);
    const Vec2 q = sample_concentric_disk(u);
    const Vec3 y = l.position + (f.s * q.x + f.t * q.y) * l.radius;
    const float dy2 = length_sq(y - p);
    ls.wi = (y - p) / std::sqrt(dy2);
    ls.dist = std::sqrt(dy2);
    ls.pdf_w = pdf_a_to_w(1.0f / (kPi * l.radius * l.radius), dy2, dot(ls.wi, dir));
    ls.p_light = y;
    ls.n_light = -dir;
    ls.le = l.radiance * (l.type == kLightSpot ? spot_attenuation(l, -ls.wi) : 1.0f);
    ls.valid = ls.pdf_w > 0.0f;
    return ls;
}

// The mean of f(sample) over n samples of light l from p, cone (sample_light) or area sampler.
template <class F>
Estimate estimate(const SceneView& v, const Light& l, Vec3 p, bool cone, F f, int n = 20000) {
    Pcg32 rng = Pcg32::for_path(cone ? 17 : 18, 0, 0);
    double sum = 0.0, sum2 = 0.0;
    for (int i = 0; i < n; ++i) {
        const LightSample ls = cone ? sample_light(v, l, p, rng.uniform2(), 0.0f)
                                    : area_sample(l, p, rng.uniform2());
        const double x = ls.valid && ls.pdf_w > 0.0f ? f(ls) : 0.0;
        sum += x;
        sum2 += x * x;
    }
    const double m = sum / n;
    return {m, std::sqrt(std::max(0.0, sum2 / n - m * m) / n)};
}

// Receivers at distance d from the centre c, along a fixed oblique direction.
Vec3 receiver(const Light& l, float d) {
    return l.position + normalize(vec3(0.3f, -0.5f, -0.8f)) * d;
}

}  // namespace

// Every sample lies on the disk through c facing p, its pdf is what light_pdf_w returns for
// the hit there (the MIS weights of light hits use it), its area density what
// soft_cone_area_pdf returns (the bidirectional weights where a light path made the point),
// and a ray along it hits that disk at its distance.
TEST(SoftDiskCone, SamplesOnTheFacingDiskWithTheHitsPdf) {
    for (const char* type : {"point", "spot"}) {
        HostScene s = soft_scene(type);
        const SceneView v = s.view();
        const Light& l = v.lights[0];
        for (float d : {0.002f, 0.03f, 0.1f, 0.5f, 20.0f}) {
            const Vec3 p = receiver(l, d), axis = normalize(p - l.position);
            Pcg32 rng = Pcg32::for_path(3, 0, 0);
            for (int i = 0; i < 500; ++i) {
                const LightSample ls = sample_light(v, l, p, rng.uniform2(), 0.0f);
                ASSERT_TRUE(ls.valid) << type << " d " << d;
                const Vec3 q = ls.p_light - l.position;
                EXPECT_LE(length(q), kR * (1.0f + 1e-3f)) << type << " d " << d;
                EXPECT_NEAR(dot(q, axis), 0.0f, 1e-5f * (1.0f + d)) << type << " d " << d;
                EXPECT_NEAR(length(ls.p_light - p), ls.dist, 1e-4f * ls.dist);
                const float pdf = light_pdf_w(l, p, ls.wi, ls.dist, ls.n_light);
                EXPECT_NEAR(pdf, ls.pdf_w, 1e-5f * ls.pdf_w) << type << " d " << d;
                const float pdf_a = ls.pdf_w * fabsf(dot(ls.wi, ls.n_light)) / (ls.dist * ls.dist);
                EXPECT_NEAR(soft_cone_area_pdf(l, p, ls.wi), pdf_a, 1e-4f * pdf_a)
                    << type << " d " << d;
                const LightHit h = intersect_light(l, p, ls.wi, 0.0f, kInf);
                ASSERT_TRUE(h.hit || length(q) > kR * 0.999f) << type << " d " << d;
                if (h.hit) {
                    EXPECT_NEAR(h.t, ls.dist, 1e-3f * ls.dist);
                    EXPECT_NEAR(h.le.x, ls.le.x, 1e-4f * h.le.x);
                }
            }
        }
    }
}

// A receiver facing the light: irradiance I / (d^2 + r^2) (Blender's soft falloff), within
// 1 cm of the centre and 2 m away, by both samplers; the area sampler's pdf put on the cone's
// samples (a wrong density) is caught; near the bulb the cone's standard error is a small
// fraction of the area sampler's, for a facing receiver and for a medium point (no cosine,
// where the cone's estimate of the disk's solid angle is exact).
TEST(SoftDiskCone, IrradianceAgreesWithAreaSamplingAtLowerVariance) {
    HostScene s = soft_scene("point");
    const SceneView v = s.view();
    const Light& l = v.lights[0];
    const double intensity = 60.0 / (4.0 * kPi);
    for (float d : {0.01f, 2.0f}) {
        const Vec3 p = receiver(l, d), n = normalize(l.position - p);
        const double exact = intensity / (double(d) * d + double(kR) * kR);
        auto facing = [&](const LightSample& ls) {
            return double(ls.le.x) * std::max(0.0f, dot(ls.wi, n)) / ls.pdf_w;
        };
        const Estimate cone = estimate(v, l, p, true, facing),
                       area = estimate(v, l, p, false, facing);
        EXPECT_NEAR(cone.mean, exact, 4.5 * cone.se + 1e-5 * exact) << "d " << d;
        EXPECT_NEAR(area.mean, exact, 4.5 * area.se + 1e-5 * exact) << "d " << d;
        // negative control: the cone's samples weighed by the area density
        auto wrong = [&](const LightSample& ls) {
            const float pa = pdf_a_to_w(1.0f / (kPi * kR * kR), ls.dist * ls.dist,
                                        fabsf(dot(ls.wi, ls.n_light)));
            return double(ls.le.x) * std::max(0.0f, dot(ls.wi, n)) / pa;
        };
        const Estimate bad = estimate(v, l, p, true, wrong);
        if (d < kR) EXPECT_GT(std::fabs(bad.mean - exact), 4.5 * bad.se + 0.05 * exact);
        std::printf("d %.2f: exact %.5g cone %.5g +- %.2g area %.5g +- %.2g wrong %.5g\n", d,
                    exact, cone.mean, cone.se, area.mean, area.se, bad.mean);
        if (d < kR) EXPECT_LT(cone.se, 0.1 * area.se) << cone.se << " vs " << area.se;
        // a medium point: the disk's solid angle times its radiance, 2 pi (1 - cos) L
        auto omni = [&](const LightSample& ls) { return double(ls.le.x) / ls.pdf_w; };
        const Estimate c2 = estimate(v, l, p, true, omni), a2 = estimate(v, l, p, false, omni);
        const double h = std::sqrt(double(d) * d + double(kR) * kR);
        const double solid = 2.0 * kPi * (1.0 - d / h) * l.radiance.x;
        EXPECT_NEAR(c2.mean, solid, 1e-4 * solid) << "d " << d;
        EXPECT_LT(c2.se, 1e-4 * solid);
        EXPECT_NEAR(a2.mean, solid, 4.5 * a2.se + 1e-5 * solid) << "d " << d;
    }
}

// A spot: its cone cuts through the disk seen from a receiver near the cone's edge; the cone
// sampler and the area sampler estimate the same light (spot_attenuation along each ray).
TEST(SoftDiskCone, SpotEdgeAgreesWithAreaSampling) {
    HostScene s = soft_scene("spot");
    const SceneView v = s.view();
    const Light& l = v.lights[0];
    // 0.05 m below the centre and 0.045 m aside (42 degrees off the axis): in the blend, and
    // within the disk's radius
    const Vec3 p = l.position + vec3(0.045f, 0.0f, -0.05f);
    auto omni = [&](const LightSample& ls) { return double(ls.le.x) / ls.pdf_w; };
    const Estimate cone = estimate(v, l, p, true, omni, 80000),
                   area = estimate(v, l, p, false, omni, 80000);
    const double se = std::hypot(cone.se, area.se);
    std::printf("spot edge: cone %.5g +- %.2g area %.5g +- %.2g\n", cone.mean, cone.se,
                area.mean, area.se);
    EXPECT_GT(cone.mean, 0.0);
    EXPECT_NEAR(cone.mean, area.mean, 4.5 * se);
    EXPECT_GT(std::fabs(1.05 * cone.mean - area.mean), 4.5 * se);  // 5 % off is resolved
}
