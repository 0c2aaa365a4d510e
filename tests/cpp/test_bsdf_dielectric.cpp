// Dielectric: chi-square of the rough lobe (reflection + transmission over the whole sphere, wo
// outside and inside), weight == f |cos| / pdf, reverse pdfs, generalised reciprocity
// (radiance vs importance), furnaces, the smooth delta lobes and hostile inputs.
#include <gtest/gtest.h>

#include "bsdf/dielectric.h"
#include "test_bsdf_helpers.h"

using namespace lantern;
using namespace lantern::test;

TEST(BsdfDielectric, RoughSampleMatchesPdfChiSquare) {
    for (float rough : {0.3f, 0.7f})
        for (float eta : {1.5f, 0.7f})
            for (float theta_o : {0.4f, 1.3f, kPi - 0.6f}) {
                DielectricParams p = dielectric(rough, eta, Transport::Radiance);
                Vec3 wo = dir_from_angles(theta_o, 0.4f);
                Chi2Result r = chi2_sphere(
                    [&](Vec2 u, float uc, Vec3* wi) {
                        BsdfSample s = dielectric_sample(p, wo, u, uc);
                        *wi = s.wi;
                        return s.valid;
                    },
                    [&](Vec3 wi) { return double(dielectric_eval(p, wo, wi).pdf_fwd_w); }, 200000);
                EXPECT_GT(r.p_value, 1e-4) << "rough " << rough << " eta " << eta << " theta "
                                           << theta_o << " chi2 " << r.chi2 << " dof " << r.dof;
                expect_pdf_mass(r, "rough " + std::to_string(rough) + " eta " +
                                       std::to_string(eta) + " theta " + std::to_string(theta_o));
            }
}

TEST(BsdfDielectric, WeightPdfsAndGeneralisedReciprocity) {
    Pcg32 rng = Pcg32::for_path(3, 0, 0);
    for (float eta : {1.5f, 0.8f})
        for (float theta_o : {0.7f, kPi - 0.9f}) {
            DielectricParams rad = dielectric(0.4f, eta, Transport::Radiance);
            DielectricParams imp = dielectric(0.4f, eta, Transport::Importance);
            Vec3 wo = dir_from_angles(theta_o, 1.0f);
            for (int i = 0; i < 2000; ++i) {
                BsdfSample s = dielectric_sample(rad, wo, rng.uniform2(), rng.uniform());
                if (!s.valid) continue;
                BsdfEval e = dielectric_eval(rad, wo, s.wi);
                ASSERT_GT(e.pdf_fwd_w, 0.0f);
                EXPECT_NEAR(e.pdf_fwd_w, s.pdf_fwd_w, 1e-4f * s.pdf_fwd_w);
                EXPECT_NEAR(s.weight.x, e.f.x * std::fabs(s.wi.z) / e.pdf_fwd_w,
                            1e-4f * (1 + s.weight.x));
                BsdfEval back = dielectric_eval(rad, s.wi, wo);
                EXPECT_NEAR(e.pdf_rev_w, back.pdf_fwd_w, 1e-4f * (1 + back.pdf_fwd_w));
                // f_radiance(wo, wi) == f_importance(wi, wo); reflection is plainly symmetric
                float adj = dielectric_eval(imp, s.wi, wo).f.x;
                EXPECT_NEAR(e.f.x, adj, 2e-3f * (1 + e.f.x));
                if (s.wi.z * wo.z > 0.0f) EXPECT_NEAR(e.f.x, back.f.x, 2e-3f * (1 + e.f.x));
            }
        }
}

TEST(BsdfDielectric, RoughWhiteFurnace) {
    // Radiance transport (as Cycles: refraction not scaled by 1/eta^2): its weights average to
    // <= 1 from either side. Importance transport, its adjoint, from the optically thinner side
    // is <= 1 too (transmission into the denser side loses 1/eta^2).
    // cap 1e-6 (float rounding: the nearly smooth cases' weights are exactly 1 in float, se 0)
    // + z se (Bonferroni over the 48); a 1 % gain must fail where it nearly reaches 1.
    const double z = z_bonferroni(48);
    int caught = 0;
    for (float rough : {0.05f, 0.4f, 1.0f})
        for (float eta : {1.33f, 1.5f})
            for (float theta_o : {0.0f, 1.0f, 1.5f, kPi - 0.2f, kPi - 1.2f}) {
                Vec3 wo = dir_from_angles(theta_o, 0.0f);
                for (Transport mode : {Transport::Importance, Transport::Radiance}) {
                    if (mode == Transport::Importance && wo.z < 0.0f) continue;
                    DielectricParams p = dielectric(rough, eta, mode);
                    Pcg32 rng = Pcg32::for_path(7, 0, 0);
                    const int n = 50000;
                    MeanSe sum;
                    for (int i = 0; i < n; ++i) {
                        BsdfSample s = dielectric_sample(p, wo, rng.uniform2(), rng.uniform());
                        sum.add(s.valid ? s.weight.x : 0.0);
                    }
                    EXPECT_TRUE(mean_at_most(sum, 1.0, z, 1e-6, &caught))
                        << "rough " << rough << " eta " << eta << " theta " << theta_o;
                    if (rough <= 0.05f && mode == Transport::Radiance)  // nearly smooth: ~1
                        EXPECT_GT(sum.mean(), 0.95) << "eta " << eta << " theta " << theta_o;
                }
            }
    EXPECT_GE(caught, 1) << "no case within 1 % of 1: a 1 % energy gain would pass";
}

TEST(BsdfDielectric, SmoothReflectPlusTransmitIsExactlyOne) {
    for (float eta : {1.5f, 0.67f, 1.0f})
        for (float theta_o : {0.0f, 0.6f, 1.4f, kPi - 0.3f, kPi - 1.1f}) {
            DielectricParams imp = dielectric(0.0f, eta, Transport::Importance);
            DielectricParams rad = dielectric(0.0f, eta, Transport::Radiance);
            ASSERT_TRUE(dielectric_is_delta(imp));
            Vec3 wo = dir_from_angles(theta_o, 0.3f);
            float f = fresnel_dielectric(wo.z, eta);
            for (float uc : {0.0f, 0.999999f, f - 1e-6f, f + 1e-6f}) {
                BsdfSample s = dielectric_sample(rad, wo, {0.5f, 0.5f}, uc);
                if (!s.valid) continue;
                EXPECT_EQ(s.weight.x, 1.0f);
                bool reflected = s.wi.z * wo.z > 0.0f;
                EXPECT_FLOAT_EQ(s.pdf_fwd_w, reflected ? f : 1.0f - f);
                EXPECT_NEAR(length(s.wi), 1.0f, 1e-5f);
                if (!reflected) {  // Snell: n_o sin_o == n_i sin_i
                    float etap = wo.z > 0.0f ? eta : 1.0f / eta;
                    float sin_o = std::sqrt(1 - wo.z * wo.z),
                          sin_i = std::sqrt(1 - s.wi.z * s.wi.z);
                    EXPECT_NEAR(sin_o, etap * sin_i, 1e-5f);
                    // the adjoint: importance carries 1/eta'^2 where radiance carries 1
                    BsdfSample si = dielectric_sample(imp, wo, {0.5f, 0.5f}, uc);
                    EXPECT_FLOAT_EQ(si.weight.x, 1.0f / (etap * etap));
                }
            }
            BsdfEval e = dielectric_eval(imp, wo, vec3(-wo.x, -wo.y, wo.z));
            EXPECT_TRUE(is_black(e.f));
            EXPECT_EQ(e.pdf_fwd_w, 0.0f);
        }
    // index-matched: everything passes straight through
    BsdfSample s = dielectric_sample(dielectric(0.5f, 1.0f, Transport::Radiance),
                                     dir_from_angles(0.8f, 0.2f), {0.3f, 0.3f}, 0.5f);
    ASSERT_TRUE(s.valid);
    Vec3 wo = dir_from_angles(0.8f, 0.2f);
    EXPECT_NEAR(s.wi.x, -wo.x, 1e-5f);
    EXPECT_NEAR(s.wi.z, -wo.z, 1e-5f);
    EXPECT_NEAR(s.weight.x, 1.0f, 1e-6f);
}

TEST(BsdfDielectric, HostileInputsStayFinite) {
    Pcg32 rng = Pcg32::for_path(9, 0, 0);
    for (float rough : {0.0f, 0.032f, 0.2f, 1.0f})
        for (float eta : {1.0f, 1.0005f, 1.01f, 0.5f, 0.0f, 2.4f})
            for (Vec3 wo : {vec3(0, 0, 1), vec3(0, 0, -1), vec3(1, 0, 0),
                            normalize(vec3(1, 0, 1e-7f)), normalize(vec3(1, 0, -1e-7f))})
                for (Transport mode : {Transport::Radiance, Transport::Importance}) {
                    DielectricParams p = dielectric(rough, eta, mode);
                    for (int i = 0; i < 20; ++i) {
                        BsdfSample s = dielectric_sample(p, wo, rng.uniform2(), rng.uniform());
                        EXPECT_TRUE(is_finite(s.wi) && is_finite(s.weight) &&
                                    is_finite(s.pdf_fwd_w));
                        Vec3 wi = normalize(vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f,
                                                 (rng.uniform() - 0.5f) * (i % 2 ? 1e-6f : 1.0f)));
                        BsdfEval e = dielectric_eval(p, wo, wi);
                        EXPECT_TRUE(finite_eval(e.f, e.pdf_fwd_w, e.pdf_rev_w));
                        e = dielectric_eval(p, wo, s.wi);
                        EXPECT_TRUE(finite_eval(e.f, e.pdf_fwd_w, e.pdf_rev_w));
                    }
                }
}
