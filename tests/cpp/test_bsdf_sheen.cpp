// The LTC microfiber sheen (bsdf/sheen.h; Zeltner, Burley & Chiang 2022, Cycles' Principled
// sheen): chi-square of sample() against eval()'s pdf in both transports, the pdf's mass, the
// density against a linearly transformed cosine written here from its definition (a 3 x 3
// matrix and its Jacobian, in double), the lobe's albedo against the fit's R and the white
// furnace, the adjoint (importance = radiance with the directions swapped), the fit's rows
// against entries of the published table, hostile inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "bsdf/principled.h"
#include "bsdf/sheen.h"
#include "test_bsdf_helpers.h"
#include "test_material_helpers.h"

using namespace lantern;
using namespace lantern::test;

namespace {

struct Lobe {
    float ltc[3 * kSheenLtcN];
    SheenParams p;
    Lobe(Vec3 color, float roughness) {
        sheen_ltc_rows(roughness, ltc);
        p = SheenParams{color, ltc};
    }
};

const float kRough[] = {0.1f, 0.3f, 0.5f, 1.0f};
const float kTheta[] = {0.0f, 0.6f, 1.2f, 1.5f};

// D of the transformed cosine by its definition: with Minv the 3 x 3 inverse transform in the
// frame of v (x towards v's projection), w_o = Minv w / |Minv w|, D(w) = D_o(w_o) |det Minv| /
// |Minv w|^3 and D_o the clamped cosine / pi. a, b from sheen_ltc_at (the fit's reading is
// checked against the published numbers below); the matrix algebra is this test's own.
double ltc_reference(double a, double b, Vec3 v, Vec3 w) {
    const double len = std::hypot(double(v.x), double(v.y));
    const double tx = len > 1e-12 ? v.x / len : 1.0, ty = len > 1e-12 ? v.y / len : 0.0;
    // rows: the frame (T, B, N) then Minv = [[a, 0, b], [0, a, 0], [0, 0, 1]]
    const double frame[3][3] = {{tx, ty, 0.0}, {-ty, tx, 0.0}, {0.0, 0.0, 1.0}};
    const double minv[3][3] = {{a, 0.0, b}, {0.0, a, 0.0}, {0.0, 0.0, 1.0}};
    double local[3], o[3];
    for (int r = 0; r < 3; ++r)
        local[r] = frame[r][0] * w.x + frame[r][1] * w.y + frame[r][2] * w.z;
    for (int r = 0; r < 3; ++r)
        o[r] = minv[r][0] * local[0] + minv[r][1] * local[1] + minv[r][2] * local[2];
    const double det = minv[0][0] * (minv[1][1] * minv[2][2] - minv[1][2] * minv[2][1]) -
                       minv[0][1] * (minv[1][0] * minv[2][2] - minv[1][2] * minv[2][0]) +
                       minv[0][2] * (minv[1][0] * minv[2][1] - minv[1][1] * minv[2][0]);
    const double n = std::sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
    const double cos_o = o[2] / n;
    if (!(cos_o > 0.0)) return 0.0;
    return cos_o / M_PI * std::fabs(det) / (n * n * n);
}

}  // namespace

// Entries of the published fit (Cycles' table_sheen_ltc as bpy 5.0.1 ships it), at grid nodes
// and between them: the reading of the rows (roughness j / 31, cosine i / 31) is the grid's.
TEST(BsdfSheen, FitRowsAreThePublishedTable) {
    float t[3 * kSheenLtcN];
    sheen_ltc_rows(1.0f, t);  // the last row of each table
    EXPECT_FLOAT_EQ(t[0], 0.72363f);                   // a, cos 0
    EXPECT_FLOAT_EQ(t[2 * kSheenLtcN + 0], 0.74973f);  // R, cos 0
    EXPECT_FLOAT_EQ(t[2 * kSheenLtcN + 31], 0.34187f); // R, cos 1
    sheen_ltc_rows(21.0f / 31.0f, t);                  // row 21 of a
    EXPECT_NEAR(t[0], 0.38874f, 1e-6f);
    EXPECT_NEAR(t[7], 0.56050f, 1e-6f);
    sheen_ltc_rows(1.5f / 31.0f, t);  // halfway between rows 1 and 2 of a
    EXPECT_NEAR(t[1], 0.5f * (0.01741f + 0.01895f), 1e-6f);
    // below the fit (roughness 0): Cycles' clamp to 1e-3 leaves a lobe of almost nothing
    sheen_ltc_rows(0.0f, t);
    for (int i = 0; i < kSheenLtcN; ++i) EXPECT_LT(t[2 * kSheenLtcN + i], 2e-3f);
    // and the lookup between cosines is linear, clamped at the ends
    sheen_ltc_rows(1.0f, t);
    const SheenLtc mid = sheen_ltc_at(t, 0.5f / 31.0f);
    EXPECT_NEAR(mid.r, 0.5f * (0.74973f + 0.73527f), 1e-6f);
    EXPECT_FLOAT_EQ(sheen_ltc_at(t, 1.5f).r, 0.34187f);
}

TEST(BsdfSheen, DensityIsTheTransformedCosine) {
    Pcg32 rng = Pcg32::for_path(11, 0, 0);
    for (float r : kRough) {
        Lobe l(vec3(1.0f), r);
        for (float theta_o : kTheta) {
            const Vec3 v = dir_from_angles(theta_o, 0.7f);
            const SheenLtc fit = sheen_ltc_at(l.ltc, v.z);
            for (int i = 0; i < 200; ++i) {
                const Vec3 w = normalize(vec3(rng.uniform() * 2 - 1, rng.uniform() * 2 - 1,
                                              rng.uniform()));
                const double ref = ltc_reference(fit.a, fit.b, v, w);
                const double got = sheen_ltc_d(fit, v, w);
                EXPECT_NEAR(got, ref, 1e-4 * (1.0 + ref)) << "r " << r << " theta " << theta_o;
            }
        }
    }
}

TEST(BsdfSheen, SamplingMatchesPdfBothTransports) {
    for (Transport mode : {Transport::Radiance, Transport::Importance})
        for (float r : {0.1f, 0.5f, 1.0f})
            for (float theta_o : {0.3f, 1.0f, 1.45f}) {
                Lobe l(vec3(1.0f, 0.7f, 0.3f), r);
                const Vec3 wo = dir_from_angles(theta_o, 0.4f);
                Chi2Result c = chi2_sphere(
                    [&](Vec2 u, float, Vec3* wi) {
                        BsdfSample s = sheen_sample(l.p, wo, u, mode);
                        *wi = s.wi;
                        return s.valid;
                    },
                    [&](Vec3 wi) { return double(sheen_eval(l.p, wo, wi, mode).pdf_fwd_w); },
                    100000, 1, 16, 16, 24);
                EXPECT_GT(c.p_value, 1e-4) << "r " << r << " theta " << theta_o << " chi2 "
                                           << c.chi2 << " dof " << c.dof;
                // the lobe is all above the surface: mass 1. At roughness 0.1 its spike at the
                // horizon (width ~a = 0.04-0.06) needs a finer rule than the helper's 768^2
                // (which reads 1.0007-1.0009 there): 3072^2, within 2e-4
                if (r >= 0.5f) {
                    expect_pdf_mass(c, "sheen");
                } else {
                    const double mass = pdf_mass_on_sphere(
                        [&](Vec3 wi) { return double(sheen_eval(l.p, wo, wi, mode).pdf_fwd_w); },
                        3072);
                    EXPECT_NEAR(mass, 1.0, 2e-4) << "r " << r << " theta " << theta_o;
                }
                EXPECT_EQ(c.valid_frac, 1.0);
            }
    // negative control: a pdf that leans the other way (b negated) fails the same test
    Lobe l(vec3(1.0f), 0.5f);
    const Vec3 wo = dir_from_angles(1.0f, 0.4f);
    Chi2Result c = chi2_sphere(
        [&](Vec2 u, float, Vec3* wi) {
            BsdfSample s = sheen_sample(l.p, wo, u, Transport::Radiance);
            *wi = s.wi;
            return s.valid;
        },
        [&](Vec3 wi) {
            SheenLtc f = sheen_ltc_at(l.ltc, wo.z);
            f.b = -f.b;
            return double(sheen_ltc_d(f, wo, wi));
        },
        100000, 1, 16, 16, 4);
    EXPECT_LT(c.p_value, 1e-4) << "a mirrored lobe passed the chi-square";
}

// sample() and eval() agree; the reverse pdf is the forward pdf from the other side; importance
// transport is radiance with the directions swapped (the adjoint: camera and light sub-paths
// evaluate one function); the lobe itself is not reciprocal (an LTC), which this shows too.
TEST(BsdfSheen, SampleEvalAndAdjointAgree) {
    Pcg32 rng = Pcg32::for_path(3, 0, 0);
    int asymmetric = 0;
    for (float r : kRough) {
        Lobe l(vec3(1.0f, 0.7f, 0.3f), r);
        const Vec3 wo = dir_from_angles(1.1f, 0.3f);
        for (int i = 0; i < 500; ++i)
            for (Transport mode : {Transport::Radiance, Transport::Importance}) {
                BsdfSample s = sheen_sample(l.p, wo, rng.uniform2(), mode);
                ASSERT_TRUE(s.valid);
                const BsdfEval e = sheen_eval(l.p, wo, s.wi, mode);
                const Transport other = mode == Transport::Radiance ? Transport::Importance
                                                                    : Transport::Radiance;
                const BsdfEval adj = sheen_eval(l.p, s.wi, wo, other);
                const BsdfEval back = sheen_eval(l.p, s.wi, wo, mode);
                EXPECT_NEAR(e.pdf_fwd_w, s.pdf_fwd_w, 1e-5f * (1 + s.pdf_fwd_w));
                EXPECT_NEAR(e.pdf_rev_w, back.pdf_fwd_w, 1e-5f * (1 + e.pdf_rev_w));
                for (int c = 0; c < 3; ++c) {
                    EXPECT_NEAR(s.weight[c], e.f[c] * s.wi.z / e.pdf_fwd_w,
                                1e-4f * (1 + s.weight[c]));
                    EXPECT_NEAR(e.f[c], adj.f[c], 1e-5f * (1 + e.f[c])) << "adjoint";
                }
                if (std::fabs(e.f.x - back.f.x) > 0.05f * e.f.x) ++asymmetric;
                // radiance: the weight is the fit's albedo at wo, exactly (M keeps z)
                if (mode == Transport::Radiance)
                    EXPECT_NEAR(s.weight.x, sheen_ltc_at(l.ltc, wo.z).r, 1e-4f);
            }
    }
    EXPECT_GT(asymmetric, 0) << "the LTC lobe came out reciprocal: is the mode ignored?";
}

// The lobe's albedo, by quadrature of eval's f cos over the sphere (radiance), is the fit's R at
// mu_o; R <= 1 (white furnace); the sampled weights' mean in importance transport (f of the
// swapped directions) is the other side's integral, which a quadrature gives too.
TEST(BsdfSheen, AlbedoIsTheFitAndAtMostOne) {
    const double z = z_bonferroni(2 * 4 * 4);
    for (float r : kRough)
        for (float theta_o : kTheta) {
            Lobe l(vec3(1.0f), r);
            const Vec3 wo = dir_from_angles(theta_o, 0.2f);
            const float fit = sheen_ltc_at(l.ltc, wo.z).r;
            const double quad = pdf_mass_on_sphere([&](Vec3 wi) {
                return wi.z > 0.0f
                           ? double(sheen_eval(l.p, wo, wi, Transport::Radiance).f.x) * wi.z
                           : 0.0;
            });
            EXPECT_NEAR(quad, fit, 2e-3 * fit + 1e-5) << "r " << r << " theta " << theta_o;
            EXPECT_LE(fit, 1.0f);
            EXPECT_GT(fit, 0.0f);
            // importance: the integral over the camera side of R(mu_i) D_i(wo) / mu_o * mu_i
            const double quad_imp = pdf_mass_on_sphere([&](Vec3 wi) {
                return wi.z > 0.0f
                           ? double(sheen_eval(l.p, wo, wi, Transport::Importance).f.x) * wi.z
                           : 0.0;
            });
            MeanSe m;
            Pcg32 rng = Pcg32::for_path(5, 0, 0);
            for (int i = 0; i < 200000; ++i) {
                BsdfSample s = sheen_sample(l.p, wo, rng.uniform2(), Transport::Importance);
                m.add(s.valid ? double(s.weight.x) : 0.0);
            }
            if (std::getenv("LANTERN_TEST_PRINT"))
                std::printf("sheen r %.1f theta %.2f R %.5f quad %.5f importance %.5f %s\n", r,
                            theta_o, fit, quad, quad_imp, mean_matches(m, quad_imp, z, 2e-3, 0.0)
                                                              .message());
            EXPECT_TRUE(mean_matches(m, quad_imp, z, 2e-3, 0.0))
                << "r " << r << " theta " << theta_o;
        }
}

// The Principled layering (Cycles' closure_layering_weight): the base under the sheen gets
// 1 - weight x max(tint) x R(mu_v); a white sheen over a white Lambert base reflects exactly 1
// at every view in radiance (sampled), and the tinted one max(tint)-weighted less.
TEST(BsdfSheen, PrincipledLayeringFurnace) {
    const double z = z_bonferroni(3 * 3);
    for (float r : {0.1f, 0.5f, 1.0f})
        for (float theta_o : {0.0f, 1.0f, 1.45f}) {
            // Specular IOR Level 0: no specular layer, the Lambert base under the sheen
            Material m = sheened(principled(vec3(1.0f), 0.0f, 0.0f, 0.5f, 1.5f, 0.0f), 1.0f, r);
            const Vec3 wo = dir_from_angles(theta_o, 0.3f);
            MeanSe sum;
            Pcg32 rng = Pcg32::for_path(8, 0, 0);
            for (int i = 0; i < 40000; ++i) {
                BsdfSample s = material_sample(
                    m, true, wo, vec3(rng.uniform(), rng.uniform(), rng.uniform()),
                    Transport::Radiance);
                sum.add(s.valid ? s.weight.x : 0.0);
            }
            EXPECT_TRUE(mean_matches(sum, 1.0, z, 1e-3)) << "r " << r << " theta " << theta_o;
            // the base's share is 1 - R(mu_o)
            const float below = principled_below_sheen(m, wo.z);
            EXPECT_NEAR(below, 1.0f - sheen_ltc_at(m.tables->sheen_ltc, wo.z).r, 1e-6f);
        }
}

TEST(BsdfSheen, HostileInputsStayFinite) {
    Pcg32 rng = Pcg32::for_path(9, 0, 0);
    for (float r : {-1.0f, 0.0f, 1e-4f, 1.0f, 3.0f}) {
        Lobe l(vec3(1.0f), r);
        for (Vec3 wo : {vec3(0, 0, 1), vec3(1, 0, 0), normalize(vec3(1, 0, 1e-7f)),
                        normalize(vec3(1, 0, -0.2f))})
            for (int i = 0; i < 50; ++i)
                for (Transport mode : {Transport::Radiance, Transport::Importance}) {
                    Vec3 wi = normalize(vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f,
                                             rng.uniform() * (i % 2 ? 1e-7f : 1.0f)));
                    BsdfEval e = sheen_eval(l.p, wo, wi, mode);
                    EXPECT_TRUE(finite_eval(e.f, e.pdf_fwd_w, e.pdf_rev_w));
                    BsdfSample s = sheen_sample(l.p, wo, rng.uniform2(), mode);
                    EXPECT_TRUE(is_finite(s.weight) && is_finite(s.wi));
                    e = sheen_eval(l.p, wo, wo, mode);
                    EXPECT_TRUE(finite_eval(e.f, e.pdf_fwd_w, e.pdf_rev_w));
                }
    }
}
