// Cosine-sampled lobes: Oren-Nayar (EON) and the Charlie sheen. Chi-square of sample() against
// eval()'s pdf, pdf integrates to one, weight == f cos / pdf, reciprocity, furnaces, hostile
// inputs.
#include <gtest/gtest.h>

#include "bsdf/oren_nayar.h"
#include "bsdf/sheen.h"
#include "test_bsdf_helpers.h"

using namespace lantern;
using namespace lantern::test;

namespace {

template <typename P, typename Eval, typename Sample>
void check_lobe(const P& p, Eval eval, Sample sample, const char* name) {
    for (float theta_o : {0.2f, 1.4f}) {
        Vec3 wo = dir_from_angles(theta_o, 0.4f);
        Chi2Result r = chi2_sphere(
            [&](Vec2 u, float, Vec3* wi) {
                BsdfSample s = sample(p, wo, u);
                *wi = s.wi;
                return s.valid;
            },
            [&](Vec3 wi) { return double(eval(p, wo, wi).pdf_fwd_w); }, 100000, 1, 16, 16, 4);
        EXPECT_GT(r.p_value, 1e-4) << name << " chi2 " << r.chi2 << " dof " << r.dof;
        EXPECT_NEAR(r.pdf_mass, 1.0, 2e-3) << name;
        EXPECT_EQ(r.valid_frac, 1.0) << name;
    }
    Rng rng = Rng::for_path(3, 0, 0);
    Vec3 wo = dir_from_angles(1.1f, 0.3f);
    for (int i = 0; i < 1000; ++i) {
        BsdfSample s = sample(p, wo, rng.uniform2());
        ASSERT_TRUE(s.valid);
        BsdfEval e = eval(p, wo, s.wi), back = eval(p, s.wi, wo);
        EXPECT_NEAR(e.pdf_fwd_w, s.pdf_fwd_w, 1e-4f * (1 + s.pdf_fwd_w));
        EXPECT_NEAR(e.pdf_rev_w, back.pdf_fwd_w, 1e-6f);
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(s.weight[c], e.f[c] * s.wi.z / e.pdf_fwd_w, 1e-4f * (1 + s.weight[c]));
            EXPECT_NEAR(e.f[c], back.f[c], 1e-5f * (1 + e.f[c])) << name << " reciprocity";
        }
    }
}

template <typename P, typename Sample>
float albedo(const P& p, Sample sample, Vec3 wo) {
    Rng rng = Rng::for_path(5, 0, 0);
    const int n = 40000;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        BsdfSample s = sample(p, wo, rng.uniform2());
        if (s.valid) sum += s.weight.x;
    }
    return float(sum / n);
}

}  // namespace

TEST(BsdfOrenNayar, SamplingPdfsReciprocity) {
    for (float r : {0.0f, 0.5f, 1.0f})
        check_lobe(OrenNayarParams{{0.8f, 0.5f, 0.2f}, r}, oren_nayar_eval, oren_nayar_sample,
                   "oren_nayar");
}

TEST(BsdfOrenNayar, WhiteFurnaceIsEnergyPreserving) {
    for (float r : {0.0f, 0.3f, 1.0f})
        for (float theta_o : {0.0f, 0.8f, 1.3f, 1.565f}) {
            Vec3 wo = dir_from_angles(theta_o, 0.0f);
            float a = albedo(OrenNayarParams{vec3(1.0f), r}, oren_nayar_sample, wo);
            // EON preserves energy up to its polynomial fit of E_FON (~1e-2 at grazing)
            EXPECT_NEAR(a, 1.0f, 1.5e-2f) << "r " << r << " theta " << theta_o;
            float grey = albedo(OrenNayarParams{vec3(0.5f), r}, oren_nayar_sample, wo);
            EXPECT_LT(grey, 0.5f + 1.5e-2f);
        }
    // r = 0 is Lambert exactly
    Vec3 wo = dir_from_angles(0.7f, 0.1f), wi = dir_from_angles(0.3f, 2.0f);
    EXPECT_FLOAT_EQ(oren_nayar_eval({vec3(0.6f), 0.0f}, wo, wi).f.x, 0.6f * kInvPi);
}

TEST(BsdfSheen, SamplingPdfsReciprocity) {
    for (float r : {0.0f, 0.5f, 1.0f})
        check_lobe(SheenParams{{1.0f, 0.7f, 0.3f}, r}, sheen_eval, sheen_sample, "sheen");
}

TEST(BsdfSheen, WhiteFurnaceBelowOne) {
    for (float r : {0.0f, 0.3f, 0.4f, 0.46f, 0.6f, 1.0f})
        for (float theta_o : {0.0f, 0.8f, 1.3f, 1.565f, 1.5707f}) {
            float a = albedo(SheenParams{vec3(1.0f), r}, sheen_sample, dir_from_angles(theta_o, 0));
            EXPECT_LE(a, 1.0f) << "r " << r << " theta " << theta_o;
            EXPECT_GT(a, 0.0f);
        }
}

TEST(BsdfDiffuseLobes, HostileInputsStayFinite) {
    Rng rng = Rng::for_path(9, 0, 0);
    for (float r : {-1.0f, 0.0f, 1.0f, 3.0f})
        for (Vec3 wo : {vec3(0, 0, 1), vec3(1, 0, 0), normalize(vec3(1, 0, 1e-7f)),
                        normalize(vec3(1, 0, -0.2f))})
            for (int i = 0; i < 50; ++i) {
                Vec3 wi = normalize(vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f,
                                         rng.uniform() * (i % 2 ? 1e-7f : 1.0f)));
                OrenNayarParams on{vec3(1.0f), r};
                SheenParams sh{vec3(1.0f), r};
                BsdfEval e = oren_nayar_eval(on, wo, wi);
                EXPECT_TRUE(finite_eval(e.f, e.pdf_fwd_w, e.pdf_rev_w));
                e = sheen_eval(sh, wo, wi);
                EXPECT_TRUE(finite_eval(e.f, e.pdf_fwd_w, e.pdf_rev_w));
                BsdfSample s = oren_nayar_sample(on, wo, rng.uniform2());
                EXPECT_TRUE(is_finite(s.weight) && is_finite(s.wi));
                s = sheen_sample(sh, wo, rng.uniform2());
                EXPECT_TRUE(is_finite(s.weight) && is_finite(s.wi));
                e = sheen_eval(sh, wo, wo);
                EXPECT_TRUE(finite_eval(e.f, e.pdf_fwd_w, e.pdf_rev_w));
            }
}
