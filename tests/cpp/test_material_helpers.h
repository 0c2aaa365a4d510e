// Checks of whole materials (bsdf/material.h) shared by test_bsdf_principled.cpp and
// test_bsdf_mix.cpp.
#pragma once

#include <gtest/gtest.h>

#include <deque>

#include "bsdf/material.h"
#include "test_bsdf_helpers.h"

namespace lantern::test {

// A whole material at three view angles: its non-delta samples against eval's forward pdf by
// chi-square, and that pdf integrating to the fraction of samples that are not delta
// (expect_pdf_mass).
inline void expect_material_samples_its_pdf(const Material& m, const char* what,
                                            Vec3 coat_n = vec3(0.0f, 0.0f, 1.0f)) {
    for (float theta_o : {0.4f, 1.0f, 1.3f}) {
        Vec3 wo = dir_from_angles(theta_o, 0.7f);
        Chi2Result r = chi2_sphere(
            [&](Vec2 u, float uc, Vec3* wi) {
                BsdfSample s =
                    material_sample(m, true, wo, vec3(u.x, u.y, uc), Transport::Radiance, coat_n);
                *wi = s.wi;
                return s.valid && !s.delta;
            },
            [&](Vec3 wi) {
                return double(
                    material_eval(m, true, wo, wi, Transport::Radiance, coat_n).pdf_fwd_w);
            },
            200000, 1, 32, 32, 12);
        EXPECT_GT(r.p_value, 1e-4) << what << " theta " << theta_o << " chi2 " << r.chi2
                                   << " dof " << r.dof;
        expect_pdf_mass(r, std::string(what) + " theta " + std::to_string(theta_o));
    }
}

// Tables of m of its own (a copy of those it had, if any), which m points at: the scene keeps
// them in SceneView::material_tables; a test's live here, for the test program's lifetime,
// so that a material returned or copied by value keeps them and a changed copy gets new ones.
inline MaterialTables& own_tables(Material& m) {
    static std::deque<MaterialTables> pool;  // push_back keeps the earlier ones in place
    pool.push_back(m.tables ? *m.tables : MaterialTables{});
    m.tables = &pool.back();
    return pool.back();
}

// Principled materials for the tests (tables filled as the scene build does).
inline Material principled(Vec3 base, float metallic, float transmission, float roughness,
                    float ior = 1.5f, float level = 0.5f) {
    Material m{};
    m.type = kMaterialPrincipled;
    m.base_color = base;
    m.metallic = metallic;
    m.transmission = transmission;
    m.roughness = roughness;
    m.ior = ior;
    m.specular_tint = vec3(1.0f);
    float f0 = sqr((ior - 1.0f) / (ior + 1.0f)) * 2.0f * level;
    float r = std::sqrt(std::min(f0, 0.99f));
    m.spec_eta = (1.0f + r) / (1.0f - r);
    principled_albedo_table(m, own_tables(m));
    return m;
}

// The same with Blender's default Multiscatter GGX: the compensation's tables and Fresnels as
// the scene build makes them (scene.cpp fill_lobe_tables), then the layer's albedo with it.
inline Material principled_ms(Vec3 base, float metallic, float transmission, float roughness,
                              float ior = 1.5f, float level = 0.5f) {
    Material m = principled(base, metallic, transmission, roughness, ior, level);
    m.multiscatter = 1;
    MaterialTables& t = own_tables(m);
    const float e_avg = ms_fill_table(m, t);
    m.fms_metal = ms_fresnel([&](float mu) { return conductor_fresnel(principled_metal(m), mu); },
                             e_avg);
    m.fms_spec = ms_fresnel([&](float mu) { return principled_spec_fresnel(m, mu); }, e_avg);
    principled_albedo_table(m, t);
    return m;
}

inline Material coated(Material m, float weight, float roughness, float ior = 1.5f) {
    m.coat_weight = weight;
    m.coat_roughness = roughness;
    m.coat_ior = ior;
    m.coat_tint = vec3(1.0f);
    principled_coat_table(m, own_tables(m));
    return m;
}

inline Material sheened(Material m, float weight, float roughness) {
    m.sheen_weight = weight;
    m.sheen_roughness = roughness;
    m.sheen_tint = vec3(1.0f);
    principled_sheen_table(m, own_tables(m));
    return m;
}

inline Material anisotropic(Material m, float a) {
    m.anisotropy = a;
    return m;
}

inline Material rough_base(Material m, float r) {
    m.diffuse_roughness = r;
    return m;
}


}  // namespace lantern::test
