// The bumped Lambert (bsdf/lambert.h lambert_bumped_*): Cycles' diffuse convention. Its
// shadowing term against the published GGX masking computed here separately (Smith Lambda in
// double), the light's side alone (a view below N stays lit), the adjoint (importance
// transport swaps the directions), sample() against eval() and a chi-square of its sampler.
#include <gtest/gtest.h>

#include <cmath>

#include "bsdf/lambert.h"
#include "test_bsdf_helpers.h"

using namespace lantern;
using namespace lantern::test;

namespace {

// N_s tilted by delta from N (+Z) about the y axis, local to N's frame
Vec3 smooth_normal(double delta) {
    return vec3(float(-std::sin(delta)), 0.0f, float(std::cos(delta)));
}

// Conty Estevez et al. (Ray Tracing Gems 2019, ch. 12): G1 = 1 / (1 + Lambda) with the GGX
// Lambda = (sqrt(1 + alpha^2 tan^2 theta_i) - 1) / 2, alpha^2 = tan^2(delta) / 8 (at most 1),
// theta_i the light's angle to the unbent normal
double published_g(double delta, double theta_i) {
    const double a2 = std::min(std::pow(std::tan(delta), 2) / 8.0, 1.0);
    const double lambda = 0.5 * (std::sqrt(1.0 + a2 * std::pow(std::tan(theta_i), 2)) - 1.0);
    return 1.0 / (1.0 + lambda);
}

// a light direction at theta_i from N_s, in the plane of the tilt (azimuth sign: towards or
// away from the tilt), local to N's frame
Vec3 light_from_smooth(double delta, double theta_i, double side) {
    const double a = -delta + side * theta_i;  // angle from +Z in the x-z plane
    return vec3(float(std::sin(a)), 0.0f, float(std::cos(a)));
}

}  // namespace

TEST(BsdfLambertBumped, ShadowingIsThePublishedGgxMasking) {
    // slopes 0.125, 0.25, 0.5, 1 (tan delta) with the light 50 deg off N_s on either side; and
    // the darkening Cycles 5.0 was measured to apply (docs/nodes.md: 0.07 %, 0.27 %, 1.08 % at
    // the first three, bench/bump_oblique_cycles.py) within its 0.01 % rounding
    const double measured[] = {0.0007, 0.0027, 0.0108};
    const double slopes[] = {0.125, 0.25, 0.5, 1.0};
    const double theta = 50.0 * kPi / 180.0;
    for (int k = 0; k < 4; ++k) {
        const double delta = std::atan(slopes[k]);
        const Vec3 ns = smooth_normal(delta);
        for (double side : {-1.0, 1.0}) {
            const Vec3 l = light_from_smooth(delta, theta, side);
            if (!(l.z > 0.0f)) continue;  // slope 1, away from the tilt: below N
            const double g = bump_shadowing(ns, l), want = published_g(delta, theta);
            EXPECT_NEAR(g, want, 2e-6) << "slope " << slopes[k] << " side " << side;
            if (k < 3) EXPECT_NEAR(1.0 - g, measured[k], 1e-4) << "slope " << slopes[k];
        }
    }
    // unbent: 1 at every angle; light below N_s while above N: 0
    EXPECT_EQ(bump_shadowing(vec3(0.0f, 0.0f, 1.0f), dir_from_angles(1.5f, 0.3f)), 1.0f);
    const Vec3 ns = smooth_normal(0.4);
    EXPECT_EQ(bump_shadowing(ns, light_from_smooth(0.4, 1.65, 1.0)), 0.0f);
    EXPECT_GT(light_from_smooth(0.4, 1.65, 1.0).z, 0.0f);
}

TEST(BsdfLambertBumped, ReadsTheLightsSideOnly) {
    const Vec3 albedo{0.8f, 0.5f, 0.2f}, ns = smooth_normal(0.3);
    const Vec3 view_below = dir_from_angles(1.65f, 3.1f), light = dir_from_angles(0.6f, 0.2f);
    // radiance: the view (wo) below N is lit, by albedo / pi x G(light)
    BsdfEval e = lambert_bumped_eval(albedo, ns, ns, view_below, light, true);
    const float g = bump_shadowing(ns, light);
    ASSERT_GT(g, 0.9f);
    for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(e.f[c], albedo[c] * kInvPi * g);
    EXPECT_FLOAT_EQ(e.pdf_fwd_w, light.z * kInvPi);  // the cosine about N (camera sub-paths)
    // the light sub-path's sampler: the cosine about ng (here N_s, a flat surface), which
    // reaches a view below N
    EXPECT_FLOAT_EQ(e.pdf_rev_w, dot(view_below, ns) * kInvPi);
    ASSERT_GT(e.pdf_rev_w, 0.0f);
    // the light below N: black, whichever side the view is on
    EXPECT_TRUE(is_black(lambert_bumped_eval(albedo, ns, ns, light, view_below, true).f));
    // importance: the same BSDF with the directions swapped (wo the light's side)
    BsdfEval a = lambert_bumped_eval(albedo, ns, ns, light, view_below, false);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(a.f[c], e.f[c]);
    EXPECT_EQ(a.pdf_fwd_w, e.pdf_rev_w);
    EXPECT_EQ(a.pdf_rev_w, e.pdf_fwd_w);
    EXPECT_FALSE(lambert_bumped_sample(albedo, ns, ns, view_below, {0.3f, 0.6f}, false).valid);
    // unbent and the view above N: Lantern's Lambert, bit for bit
    const Vec3 wo = dir_from_angles(0.9f, 1.0f);
    const Vec3 z = vec3(0.0f, 0.0f, 1.0f);
    BsdfEval b = lambert_bumped_eval(albedo, z, z, wo, light, true);
    BsdfEval r = lambert_eval(albedo, wo, light);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(b.f[c], r.f[c]);
    EXPECT_EQ(b.pdf_fwd_w, r.pdf_fwd_w);
    EXPECT_EQ(b.pdf_rev_w, r.pdf_rev_w);
}

TEST(BsdfLambertBumped, SampleAgreesWithEvalInBothTransports) {
    const Vec3 albedo{0.8f, 0.5f, 0.2f}, ns = smooth_normal(0.5);
    for (bool radiance : {true, false}) {
        // radiance: a view below N; importance: the light above N and N_s (= ng, flat)
        const Vec3 wo = radiance ? dir_from_angles(1.75f, 3.1f) : dir_from_angles(0.7f, 0.4f);
        ASSERT_GT(dot(wo, ns), 0.0f);
        Chi2Result r = chi2_sphere(
            [&](Vec2 u, float, Vec3* wi) {
                BsdfSample s = lambert_bumped_sample(albedo, ns, ns, wo, u, radiance);
                *wi = s.wi;
                return s.valid;
            },
            [&](Vec3 wi) {  // radiance: the cosine about N, less where G is 0 (wi below N_s);
                            // importance: the cosine about ng
                if (!radiance) return double(pdf_cosine_hemisphere(dot(wi, ns)));
                const bool lit = bump_shadowing(ns, wi) > 0.0f;
                return lit ? double(pdf_cosine_hemisphere(wi.z)) : 0.0;
            },
            60000, 1, 16, 16, 32);  // a fine quadrature: the pdf has an edge (N_s)
        EXPECT_GT(r.p_value, 1e-4)
            << "radiance " << radiance << " chi2 " << r.chi2 << " dof " << r.dof;
        Pcg32 rng = Pcg32::for_path(3, 0, 0);
        int kept = 0, below_n = 0;
        for (int i = 0; i < 2000; ++i) {
            BsdfSample s = lambert_bumped_sample(albedo, ns, ns, wo, rng.uniform2(), radiance);
            if (!s.valid) continue;
            ++kept;
            below_n += s.wi.z < 0.0f;
            BsdfEval e = lambert_bumped_eval(albedo, ns, ns, wo, s.wi, radiance);
            EXPECT_NEAR(e.pdf_fwd_w, s.pdf_fwd_w, 1e-5f * (1 + s.pdf_fwd_w));
            EXPECT_NEAR(e.pdf_rev_w, s.pdf_rev_w, 1e-6f);
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(s.weight[c], e.f[c] * fabsf(s.wi.z) / e.pdf_fwd_w,
                            1e-5f * (1 + s.weight[c]));
            // the reverse: what the other transport's sampler gives for wo from wi
            BsdfEval back = lambert_bumped_eval(albedo, ns, ns, s.wi, wo, !radiance);
            EXPECT_NEAR(back.pdf_fwd_w, e.pdf_rev_w, 1e-6f);
            for (int c = 0; c < 3; ++c) EXPECT_EQ(back.f[c], e.f[c]);
        }
        EXPECT_GT(kept, 1500);
        if (!radiance) EXPECT_GT(below_n, 40);  // views below N are sampled
    }
}

TEST(BsdfLambertBumped, WhiteFurnaceAtMostOne) {
    // unbent: exactly the albedo (every sample weighs 1); tilted: the mean of G, below one
    Pcg32 rng = Pcg32::for_path(9, 0, 0);
    for (double delta : {0.0, 0.3, 0.9}) {
        const Vec3 ns = delta > 0.0 ? smooth_normal(delta) : vec3(0.0f, 0.0f, 1.0f);
        double sum = 0.0;
        const int n = 20000;
        for (int i = 0; i < n; ++i) {
            BsdfSample s =
                lambert_bumped_sample(vec3(1.0f), ns, ns, dir_from_angles(1.2f, 0.0f),
                                      rng.uniform2(), true);
            if (s.valid) sum += s.weight.x;
        }
        const double a = sum / n;
        if (delta == 0.0)
            EXPECT_EQ(a, 1.0);
        else
            EXPECT_LT(a, 1.0 - 1e-3) << "delta " << delta;
    }
}
