// Mix / Add Shader materials (kMaterialMix, bsdf/material.h) and the Translucent BSDF:
// sampling against the mixture pdf (chi-square), weights and reverse pdfs against eval, energy,
// and delta leaves inside a mix.
#include <gtest/gtest.h>

#include "bsdf/material.h"
#include "test_material_helpers.h"

using namespace lantern;
using namespace lantern::test;

namespace {

Material diffuse(Vec3 c) {
    Material m{};
    m.type = kMaterialDiffuse;
    m.base_color = c;
    return m;
}

Material translucent(Vec3 c) {
    Material m = diffuse(c);
    m.type = kMaterialTranslucent;
    return m;
}

Material glass(float roughness, float ior = 1.5f) {
    Material m{};
    m.type = kMaterialDielectric;
    m.base_color = vec3(1.0f);
    m.roughness = roughness;
    m.ior = ior;
    return m;
}

Material metal(Vec3 f0, float roughness) {
    Material m{};
    m.type = kMaterialConductor;
    m.base_color = f0;
    m.specular_tint = vec3(1.0f);
    m.roughness = roughness;
    m.fresnel = kFresnelF82Tint;
    return m;
}

// A resolved mix (what material_at returns) over leaves that outlive it.
Material mix(std::initializer_list<std::pair<const Material*, float>> leaves) {
    Material m{};
    m.type = kMaterialMix;
    for (auto& [leaf, w] : leaves) {
        m.mix_leaf[m.mix_count] = leaf;
        m.mix_weight[m.mix_count] = w;
        ++m.mix_count;
    }
    return m;
}

}  // namespace

TEST(BsdfMix, SampleMatchesMixturePdfChiSquare) {
    const Material d = diffuse(vec3(0.8f, 0.4f, 0.2f)), t = translucent(vec3(0.5f)),
                   rough_metal = metal(vec3(0.9f, 0.6f, 0.3f), 0.4f),
                   rough_glass = glass(0.5f);
    struct Case {
        Material m;
        const char* what;
    } cases[] = {
        {mix({{&d, 0.3f}, {&rough_metal, 0.7f}}), "diffuse + metal (Mix 0.7)"},
        {mix({{&d, 1.0f}, {&t, 1.0f}}), "diffuse + translucent (Add)"},
        {mix({{&d, 0.2f}, {&rough_metal, 0.3f}, {&rough_glass, 0.5f}}), "three leaves"},
        {translucent(vec3(0.7f)), "translucent alone"},
    };
    for (const Case& c : cases) expect_material_samples_its_pdf(c.m, c.what);
}

TEST(BsdfMix, WeightsAndReversePdfsMatchEval) {
    const Material d = diffuse(vec3(0.6f)), rough_metal = metal(vec3(0.9f), 0.3f),
                   t = translucent(vec3(0.4f, 0.5f, 0.6f));
    const Material m = mix({{&d, 0.5f}, {&rough_metal, 0.25f}, {&t, 0.25f}});
    Pcg32 rng = Pcg32::for_path(3, 0, 0);
    for (Transport mode : {Transport::Radiance, Transport::Importance})
        for (float theta_o : {0.2f, 1.2f}) {
            Vec3 wo = dir_from_angles(theta_o, 2.0f);
            for (int i = 0; i < 3000; ++i) {
                BsdfSample s = material_sample(m, true, wo,
                                               vec3(rng.uniform(), rng.uniform(), rng.uniform()),
                                               mode);
                if (!s.valid) continue;
                ASSERT_FALSE(s.delta);
                BsdfEval e = material_eval(m, true, wo, s.wi, mode);
                ASSERT_GT(e.pdf_fwd_w, 0.0f);
                EXPECT_NEAR(s.pdf_fwd_w, e.pdf_fwd_w, 1e-4f * e.pdf_fwd_w);
                EXPECT_NEAR(s.weight.y, e.f.y * std::fabs(s.wi.z) / e.pdf_fwd_w,
                            1e-4f * (1.0f + s.weight.y));
                // the reverse pdf is eval from wi's side (reflection), and reciprocity holds
                // for these lobes
                if (s.wi.z > 0.0f) {
                    BsdfEval back = material_eval(m, true, s.wi, wo, mode);
                    EXPECT_NEAR(e.pdf_rev_w, back.pdf_fwd_w, 1e-4f * (1.0f + back.pdf_fwd_w));
                    EXPECT_NEAR(e.f.y, back.f.y, 1e-4f * (1.0f + e.f.y));
                }
            }
        }
}

// White diffuse + white translucent, each weight 0.5: every sample carries exactly 1 (the
// mixture is a uniform cosine lobe on the whole sphere); Add Shader of the two: 2.
TEST(BsdfMix, WhiteFurnace) {
    const Material d = diffuse(vec3(1.0f)), t = translucent(vec3(1.0f));
    Pcg32 rng = Pcg32::for_path(5, 0, 0);
    for (float w : {0.5f, 1.0f}) {
        const Material m = mix({{&d, w}, {&t, w}});
        Vec3 wo = dir_from_angles(0.8f, 1.0f);
        double sum = 0.0;
        const int n = 20000;
        for (int i = 0; i < n; ++i) {
            BsdfSample s = material_sample(m, true, wo,
                                           vec3(rng.uniform(), rng.uniform(), rng.uniform()),
                                           Transport::Radiance);
            if (s.valid) sum += s.weight.y;
        }
        EXPECT_NEAR(sum / n, 2.0 * w, 2e-4 * w) << "weight " << w;  // exact: 1e-4 (was 1e-3)
    }
}

// A smooth (delta) glass leaf and a diffuse leaf: delta picks carry the glass weight over
// its pick probability, pdfs scaled by the pick; the mean sample weight equals the weighted
// sum of the leaves' own mean weights.
TEST(BsdfMix, DeltaLeafEnergyAndPdfs) {
    const Material d = diffuse(vec3(0.5f)), smooth = glass(0.0f);
    const Material m = mix({{&d, 0.6f}, {&smooth, 0.4f}});
    EXPECT_FALSE(material_is_delta(m));
    EXPECT_TRUE(material_transmits(m));
    Pcg32 rng = Pcg32::for_path(7, 0, 0);
    for (float theta_o : {0.3f, 1.2f}) {
        Vec3 wo = dir_from_angles(theta_o, 0.5f);
        const int n = 200000;
        double mix_sum = 0.0, d_sum = 0.0, g_sum = 0.0, mix_sq = 0.0;
        int deltas = 0;
        for (int i = 0; i < n; ++i) {
            Vec3 u = vec3(rng.uniform(), rng.uniform(), rng.uniform());
            BsdfSample s = material_sample(m, true, wo, u, Transport::Radiance);
            if (s.valid) {
                mix_sum += s.weight.y;
                mix_sq += double(s.weight.y) * s.weight.y;
                if (s.delta) {
                    ++deltas;
                    // the glass leaf saw u.z rescaled into its share [0.6, 1)
                    Vec3 ug = vec3(u.x, u.y, (u.z - 0.6f) / 0.4f);
                    BsdfSample g = material_sample(smooth, true, wo, ug, Transport::Radiance);
                    EXPECT_NEAR(s.pdf_fwd_w, 0.4f * g.pdf_fwd_w, 1e-5f);
                }
            }
            Vec3 u2 = vec3(rng.uniform(), rng.uniform(), rng.uniform());
            BsdfSample a = material_sample(d, true, wo, u2, Transport::Radiance);
            if (a.valid) d_sum += a.weight.y;
            BsdfSample b = material_sample(smooth, true, wo, u2, Transport::Radiance);
            if (b.valid) g_sum += b.weight.y;
        }
        const double mean = mix_sum / n, expect = 0.6 * d_sum / n + 0.4 * g_sum / n;
        const double se = std::sqrt((mix_sq / n - mean * mean) / n);
        EXPECT_NEAR(mean, expect, 5.0 * se + 1e-3) << "theta " << theta_o;
        EXPECT_NEAR(double(deltas) / n, 0.4, 0.01);
    }
}

// A mix of nothing, zero weights or NaN weights stays finite and black.
TEST(BsdfMix, HostileWeightsStayFinite) {
    const Material d = diffuse(vec3(0.5f));
    Vec3 wo = dir_from_angles(0.5f, 0.1f), wi = dir_from_angles(0.7f, 2.0f);
    for (float w : {0.0f, -1.0f, std::numeric_limits<float>::quiet_NaN()}) {
        const Material m = mix({{&d, w}});
        BsdfEval e = material_eval(m, true, wo, wi, Transport::Radiance);
        EXPECT_TRUE(is_finite(e.f) && std::isfinite(e.pdf_fwd_w));
        EXPECT_EQ(e.f.y, 0.0f);
        BsdfSample s = material_sample(m, true, wo, vec3(0.3f, 0.6f, 0.5f), Transport::Radiance);
        EXPECT_FALSE(s.valid && !is_finite(s.weight));
    }
}
