// The material dispatch (bsdf/material.h) for conductors: the complex-IOR mode with base_color 1
// is conductor_complex's lobe, base_color scales it (Mitsuba's specular_reflectance), the F82
// mode is unchanged, single-scatter albedo stays <= 1, and HostScene fills and sanitises the
// new fields.
#include <gtest/gtest.h>

#include <cmath>

#include "bsdf/material.h"
#include "scene/scene.h"
#include "test_bsdf_helpers.h"

using namespace lantern;
using namespace lantern::test;

namespace {

// Mitsuba's eta and k as Bitterli's veach-mis gives them (plates of the MIS scene)
const Vec3 kVeachEta{0.200438f, 0.924033f, 1.10221f}, kVeachK{3.91295f, 2.45285f, 2.14219f};

Material complex_conductor(float roughness, Vec3 eta, Vec3 k, Vec3 base = vec3(1.0f)) {
    Material m{};
    m.type = kMaterialConductor;
    m.base_color = base;
    m.roughness = roughness;
    m.ior = 1.5f;
    m.specular_tint = vec3(1.0f);
    m.eta = eta;
    m.k = k;
    m.fresnel = kFresnelComplex;
    return m;
}

void expect_vec_near(Vec3 a, Vec3 b, float rel, const char* what) {
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(a[c], b[c], rel * (1e-6f + fabsf(b[c]))) << what << " channel " << c;
}

}  // namespace

TEST(BsdfMaterial, ComplexModeIsConductorComplex) {
    Pcg32 rng = Pcg32::for_path(11, 0, 0);
    for (float rough : {0.0f, 0.1f, 0.316f, 0.7f}) {
        Material m = complex_conductor(rough, kVeachEta, kVeachK);
        ConductorParams p = conductor_complex(rough, kVeachEta, kVeachK);
        EXPECT_EQ(material_is_delta(m), conductor_is_delta(p));
        for (int i = 0; i < 200; ++i) {
            Vec3 wo = dir_from_angles(1.5f * rng.uniform(), 6.28f * rng.uniform());
            Vec3 wi = dir_from_angles(1.5f * rng.uniform(), 6.28f * rng.uniform());
            BsdfEval a = material_eval(m, i % 2 == 0, wo, wi, Transport::Radiance);
            BsdfEval b = conductor_eval(p, wo, wi);
            expect_vec_near(a.f, b.f, 1e-6f, "eval f");
            EXPECT_EQ(a.pdf_fwd_w, b.pdf_fwd_w);
            EXPECT_EQ(a.pdf_rev_w, b.pdf_rev_w);
            Vec3 u{rng.uniform(), rng.uniform(), rng.uniform()};
            BsdfSample s = material_sample(m, true, wo, u, Transport::Radiance);
            BsdfSample t = conductor_sample(p, wo, Vec2{u.x, u.y});
            ASSERT_EQ(s.valid, t.valid);
            if (!s.valid) continue;
            expect_vec_near(s.wi, t.wi, 1e-6f, "sample wi");
            expect_vec_near(s.weight, t.weight, 1e-6f, "sample weight");
            EXPECT_EQ(s.delta, t.delta);
        }
    }
}

TEST(BsdfMaterial, BaseColorScalesComplexFresnelAndF82IsUnchanged) {
    const Vec3 tint{0.3f, 0.5f, 0.9f};
    Material white = complex_conductor(0.4f, kVeachEta, kVeachK);
    Material tinted = complex_conductor(0.4f, kVeachEta, kVeachK, tint);
    Material f82 = tinted;
    f82.fresnel = kFresnelF82Tint;
    f82.specular_tint = {0.7f, 0.9f, 1.0f};
    ConductorParams pf = conductor_f82(0.4f, tint, f82.specular_tint);
    Pcg32 rng = Pcg32::for_path(12, 0, 0);
    for (int i = 0; i < 100; ++i) {
        Vec3 wo = dir_from_angles(1.4f * rng.uniform(), 6.28f * rng.uniform());
        Vec3 wi = dir_from_angles(1.4f * rng.uniform(), 6.28f * rng.uniform());
        BsdfEval w = material_eval(white, true, wo, wi, Transport::Radiance);
        BsdfEval t = material_eval(tinted, true, wo, wi, Transport::Radiance);
        expect_vec_near(t.f, w.f * tint, 1e-6f, "tinted eval");
        EXPECT_EQ(t.pdf_fwd_w, w.pdf_fwd_w);
        Vec3 u{rng.uniform(), rng.uniform(), rng.uniform()};
        BsdfSample ws = material_sample(white, true, wo, u, Transport::Radiance);
        BsdfSample ts = material_sample(tinted, true, wo, u, Transport::Radiance);
        if (ws.valid) expect_vec_near(ts.weight, ws.weight * tint, 1e-6f, "tinted sample");
        // F82 mode: base_color is F0, not a scale
        BsdfEval fe = material_eval(f82, true, wo, wi, Transport::Radiance);
        BsdfEval ce = conductor_eval(pf, wo, wi);
        expect_vec_near(fe.f, ce.f, 1e-6f, "f82 eval");
        BsdfSample fs = material_sample(f82, true, wo, u, Transport::Radiance);
        BsdfSample cs = conductor_sample(pf, wo, Vec2{u.x, u.y});
        if (fs.valid) expect_vec_near(fs.weight, cs.weight, 1e-6f, "f82 sample");
    }
}

TEST(BsdfMaterial, ComplexWhiteFurnaceAlbedoAtMostOne) {
    auto albedo = [](const Material& m, Vec3 wo) {
        Pcg32 rng = Pcg32::for_path(13, 0, 0);
        const int n = 100000;
        double sum[3] = {0.0, 0.0, 0.0};  // (a float sum drifts by ~0.1% over n samples)
        for (int i = 0; i < n; ++i) {
            BsdfSample s = material_sample(m, true, wo, {rng.uniform(), rng.uniform(), 0.5f},
                                           Transport::Radiance);
            if (!s.valid) continue;
            for (int c = 0; c < 3; ++c) sum[c] += s.weight[c];
        }
        return vec3(float(sum[0] / n), float(sum[1] / n), float(sum[2] / n));
    };
    for (float rough : {0.0f, 0.1f, 0.5f, 1.0f})
        for (float theta_o : {0.0f, 0.8f, 1.5f}) {
            Vec3 wo = dir_from_angles(theta_o, 0.3f);
            // eta 0, k 1 is a perfect mirror (F = 1): the albedo is E[G2 / G1] <= 1
            Vec3 mirror = albedo(complex_conductor(rough, vec3(0.0f), vec3(1.0f)), wo);
            EXPECT_LE(max_component(mirror), 1.0f + 1e-4f) << rough << " " << theta_o;
            if (rough <= 0.1f && theta_o < 1.0f) EXPECT_GT(mirror.x, 0.97f);
            Vec3 metal = albedo(complex_conductor(rough, kVeachEta, kVeachK), wo);
            EXPECT_LE(max_component(metal), max_component(mirror) + 1e-4f);
            Vec3 scaled = albedo(complex_conductor(rough, kVeachEta, kVeachK, vec3(0.3f)), wo);
            expect_vec_near(scaled, metal * 0.3f, 1e-3f, "specular_reflectance 0.3");
        }
}

TEST(BsdfMaterial, HostSceneReadsAndSanitisesComplexFresnel) {
    SceneInput in;
    MaterialInput a;  // Blender's conductor: F82
    a.type = "conductor";
    MaterialInput b = a;
    b.complex_fresnel = true;
    b.eta = kVeachEta;
    b.k = kVeachK;
    MaterialInput c = b;
    c.eta = {NAN, 1.0f, -2.0f};
    in.materials = {a, b, c};
    MeshInput mesh;
    mesh.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    mesh.indices = {0, 1, 2};
    mesh.material_ids = {0};
    in.meshes.push_back(mesh);
    HostScene scene(in);
    const Material* m = scene.view().materials;
    EXPECT_EQ(m[0].fresnel, uint32_t(kFresnelF82Tint));
    EXPECT_EQ(m[1].fresnel, uint32_t(kFresnelComplex));
    expect_vec_near(m[1].eta, kVeachEta, 0.0f, "eta");
    expect_vec_near(m[1].k, kVeachK, 0.0f, "k");
    // a non-finite channel is a perfect mirror there; negative eta clamps to 0
    EXPECT_EQ(m[2].eta.x, 0.0f);
    EXPECT_EQ(m[2].k.x, 1.0f);
    EXPECT_EQ(m[2].eta.y, 1.0f);
    EXPECT_EQ(m[2].eta.z, 0.0f);
}
