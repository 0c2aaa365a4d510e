// GGX distribution: D is normalised over projected area, visible normals integrate to one and
// sample_visible() matches pdf_visible() (chi-square), Fresnel limits, finite at hostile inputs.
#include <gtest/gtest.h>

#include "bsdf/fresnel.h"
#include "bsdf/microfacet.h"
#include "test_bsdf_helpers.h"

using namespace lantern;
using namespace lantern::test;

TEST(BsdfMicrofacet, VisibleNormalSamplingChiSquare) {
    for (float alpha : {0.2f, 0.5f, 1.0f})
        for (float theta_o : {0.2f, 1.2f, 1.5f}) {
            Ggx g = Ggx::isotropic(alpha);
            Vec3 wo = dir_from_angles(theta_o, 0.7f);
            Chi2Result r = chi2_sphere(
                [&](Vec2 u, float, Vec3* m) {
                    *m = g.sample_visible(wo, u);
                    return true;
                },
                [&](Vec3 m) { return double(g.pdf_visible(wo, m)); }, 200000, 1, 32, 32, 24);
            EXPECT_GT(r.p_value, 1e-4) << "alpha " << alpha << " theta " << theta_o << " chi2 "
                                       << r.chi2 << " dof " << r.dof;
            EXPECT_EQ(r.valid_frac, 1.0);
            expect_pdf_mass(r, "alpha " + std::to_string(alpha) + " theta " +
                                   std::to_string(theta_o));
        }
}

TEST(BsdfMicrofacet, ProjectedAreaOfDIsOne) {
    // int D(m) m.z dm = 1 over the hemisphere (midpoint rule in (cos, phi)), to 1e-4: alpha
    // 0.05's peak is alpha^2 wide in cos, so 40000 points (4000 read 0.99672, 20000 0.99987;
    // was within 1e-2)
    for (float alpha : {0.05f, 0.3f, 1.0f}) {
        Ggx g = Ggx::isotropic(alpha);
        const int n = 40000;
        double acc = 0.0;
        for (int i = 0; i < n; ++i) {
            double z = (i + 0.5) / n;
            acc += g.d(vec3(float(std::sqrt(1.0 - z * z)), 0.0f, float(z))) * z;
        }
        EXPECT_NEAR(acc * 2.0 * kPi / n, 1.0, 1e-4) << "alpha " << alpha;
    }
}

TEST(BsdfMicrofacet, HeightCorrelatedG2BoundedByG1) {
    Ggx g = Ggx::isotropic(0.4f);
    Vec3 wo = dir_from_angles(1.0f, 0.0f), wi = dir_from_angles(0.5f, 2.0f);
    EXPECT_LE(g.g2(wo, wi), std::min(g.g1(wo), g.g1(wi)) + 1e-6f);
    EXPECT_GE(g.g2(wo, wi), g.g1(wo) * g.g1(wi) - 1e-6f);  // correlation only helps
    EXPECT_NEAR(g.g1(vec3(0, 0, 1)), 1.0f, 1e-6f);
}

TEST(BsdfMicrofacet, FresnelLimits) {
    EXPECT_NEAR(fresnel_dielectric(1.0f, 1.5f), 0.04f, 1e-4f);
    EXPECT_EQ(fresnel_dielectric(0.7f, 1.0f), 0.0f);
    EXPECT_EQ(fresnel_dielectric(-0.1f, 1.5f), 1.0f);  // total internal reflection inside
    EXPECT_NEAR(fresnel_dielectric(0.0f, 1.5f), 1.0f, 1e-6f);
    EXPECT_NEAR(fresnel_conductor(0.6f, 1.0f, 0.0f), 0.0f, 1e-6f);
    EXPECT_NEAR(fresnel_conductor(0.6f, 1.5f, 0.0f), fresnel_dielectric(0.6f, 1.5f), 1e-5f);
    // gold-ish normal incidence: ((n-1)^2 + k^2) / ((n+1)^2 + k^2)
    float n = 0.2f, k = 3.0f;
    EXPECT_NEAR(fresnel_conductor(1.0f, n, k), (sqr(n - 1) + k * k) / (sqr(n + 1) + k * k), 1e-4f);
    Vec3 f0{0.9f, 0.6f, 0.3f}, tint{0.8f, 1.0f, 0.5f};
    Vec3 at0 = fresnel_f82_tint(1.0f, f0, tint), at90 = fresnel_f82_tint(0.0f, f0, tint);
    Vec3 at82 = fresnel_f82_tint(1.0f / 7.0f, f0, vec3(1.0f));
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(at0[c], f0[c], 1e-6f);
        EXPECT_NEAR(at90[c], 1.0f, 1e-6f);
        float schlick = f0[c] + (1 - f0[c]) * std::pow(6.0f / 7.0f, 5.0f);
        EXPECT_NEAR(at82[c], schlick, 1e-5f);  // tint 1 is plain Schlick
        EXPECT_NEAR(fresnel_f82_tint(1.0f / 7.0f, f0, tint)[c], tint[c] * schlick, 1e-5f);
    }
}

TEST(BsdfMicrofacet, HostileInputsStayFinite) {
    for (float alpha : {0.0f, 1e-4f, 1.0f}) {
        Ggx g = Ggx::isotropic(alpha);
        for (Vec3 w : {vec3(0, 0, 1), vec3(1, 0, 0), vec3(1, 0, 1e-7f), vec3(0.6f, 0, -0.8f)}) {
            w = normalize(w);
            Vec3 m = g.sample_visible(w, {0.3f, 0.9f});
            EXPECT_TRUE(is_finite(m));
            EXPECT_TRUE(is_finite(g.d(m)) && is_finite(g.pdf_visible(w, m)));
            EXPECT_TRUE(is_finite(g.g1(w)) && is_finite(g.g2(w, w)));
        }
        EXPECT_TRUE(is_finite(g.d(vec3(0, 0, 1))));
    }
}
