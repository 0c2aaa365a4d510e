// Tables at a per-hit roughness (MaterialTables::rough_rows, bsdf/multiscatter.h ms_rough): a
// material whose Roughness a texture gives reads the multiple-scattering compensation and the
// Principled layer's albedo at the hit's roughness, never at the socket's hidden value. Checked
// through HostScene (scene.cpp fill_lobe_tables) against a constant material of the same
// roughness: equal on a row's roughness, within the rows' interpolation between rows.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "bsdf/material.h"
#include "scene/scene.h"
#include "test_material_helpers.h"

using namespace lantern;

namespace {

// Material 0: roughness from a 1x1 float texture of value r, its own (hidden) value `hidden`;
// material 1: the constant r. Both principled of metallic `metallic`, or conductors.
SceneInput rows_scene(const std::string& type, float r, float hidden, float metallic,
                      bool multiscatter = true) {
    SceneInput in;
    in.width = in.height = 4;
    TextureInput t;
    t.name = "rough";
    t.width = t.height = 1;
    t.format = "float";
    t.output = "red";
    t.floats = {r, r, r, 1.0f};
    in.textures.push_back(t);
    MaterialInput a;
    a.name = "graph";
    a.type = type;
    a.base_color = vec3(0.9f, 0.6f, 0.3f);
    a.metallic = metallic;
    a.roughness = hidden;
    a.multiscatter = multiscatter;
    a.tex_roughness = 0;
    MaterialInput b = a;
    b.name = "constant";
    b.roughness = r;
    b.tex_roughness = -1;
    in.materials = {a, b};
    return in;
}

struct Read {
    float e[kPrincipledAlbedoN], spec[kPrincipledAlbedoN];
    Vec3 fms_metal, fms_spec;
};

// What the lobes read of material id at a hit (its tables at the hit's roughness).
Read read(const HostScene& scene, uint32_t id) {
    MaterialScratch scratch;
    const Material& m = material_at(scene.view(), id, Vec2{0.5f, 0.5f}, scratch);
    Read out;
    for (int k = 0; k < kPrincipledAlbedoN; ++k) {
        const float mu = 0.02f + 0.98f * float(k) / (kPrincipledAlbedoN - 1);
        out.e[k] = ms_white_albedo(m, mu);
        out.spec[k] = m.type == kMaterialPrincipled ? principled_spec_albedo(m, mu) : 0.0f;
    }
    out.fms_metal = m.fms_metal;
    out.fms_spec = m.fms_spec;
    return out;
}

void expect_near(const Read& a, const Read& b, float tol, const std::string& what,
                 bool ms = true) {
    for (int k = 0; k < kPrincipledAlbedoN; ++k) {
        EXPECT_NEAR(a.e[k], b.e[k], tol * b.e[k]) << what << " E at " << k;
        EXPECT_NEAR(a.spec[k], b.spec[k], tol * ::fmaxf(b.spec[k], 0.05f)) << what << " E_s at " << k;
    }
    if (!ms) return;  // the Fresnels of the compensation are read only with it
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(a.fms_metal[c], b.fms_metal[c], tol * b.fms_metal[c]) << what << " fms_metal";
        EXPECT_NEAR(a.fms_spec[c], b.fms_spec[c], tol * ::fmaxf(b.fms_spec[c], 0.05f))
            << what << " fms_spec";
    }
}

}  // namespace

// On a row's roughness (j / 32) the rows are the constant material's own tables: equal up to
// float rounding, the hidden value aside; between rows within the rows' cubic interpolation
// (2e-3 relative: the quadrature's own variation from roughness to roughness, about what
// Cycles' 32 x 32 tables carry). The control: the hidden value read as the roughness (what
// Lantern did, issue 28) is far outside either.
TEST(BsdfRoughRows, TexturedRoughnessReadsTheTablesOfTheHit) {
    for (const char* type : {"principled", "conductor"}) {
        for (float metallic : {0.0f, 1.0f}) {
            for (bool ms : {true, false}) {
                if (!ms && std::strcmp(type, "conductor") == 0) continue;  // reads no table
                const std::string what = std::string(type) + " metallic " +
                                         std::to_string(metallic) + (ms ? " ms" : " plain");
                for (float hidden : {0.0f, 0.9f}) {
                    HostScene on_row(rows_scene(type, 0.5f, hidden, metallic, ms));
                    expect_near(read(on_row, 0), read(on_row, 1), 2e-5f,
                                what + " on a row, hidden " + std::to_string(hidden), ms);
                    HostScene between(rows_scene(type, 0.3f, hidden, metallic, ms));
                    expect_near(read(between, 0), read(between, 1), 2e-3f,
                                what + " between rows, hidden " + std::to_string(hidden), ms);
                }
                // the control: a constant material of the hidden value reads other tables
                HostScene hidden_as_constant(rows_scene(type, 0.9f, 0.9f, metallic, ms));
                HostScene real(rows_scene(type, 0.3f, 0.0f, metallic, ms));
                const Read h = read(hidden_as_constant, 1), r = read(real, 1);
                float worst = 0.0f;
                for (int k = 0; k < kPrincipledAlbedoN; ++k)
                    worst = ::fmaxf(worst, fabsf(h.e[k] - r.e[k]) / r.e[k]);
                EXPECT_GT(worst, 0.02f) << what;
            }
        }
    }
}

// A material without a roughness texture or graph carries no rows (what it pays: nothing).
TEST(BsdfRoughRows, ConstantRoughnessHasNoRows) {
    SceneInput in = rows_scene("principled", 0.3f, 0.3f, 0.0f);
    in.materials[0].tex_roughness = -1;
    HostScene scene(in);
    EXPECT_EQ(scene.view().materials[0].tables->rough_rows, 0);
    EXPECT_EQ(scene.view().materials[1].tables->rough_rows, 0);
    HostScene textured(rows_scene("principled", 0.3f, 0.3f, 0.0f));
    EXPECT_GT(textured.view().materials[0].tables->rough_rows, 0);
}

// The shared basis gives the layer's albedo the quadrature gives (principled_albedo_table),
// with and without the compensation, for other IORs and a tint.
TEST(BsdfRoughRows, SpecBasisIsTheLayerAlbedo) {
    for (float rough : {0.0f, 0.25f, 0.5f, 1.0f}) {
        for (float ior : {1.33f, 1.5f, 2.4f}) {
            for (bool ms : {true, false}) {
                Material m = lantern::test::principled(vec3(0.5f), 0.0f, 0.0f, rough, ior);
                m.specular_tint = vec3(1.0f, 0.6f, 0.2f);
                m.multiscatter = ms ? 1u : 0u;
                MaterialTables& t = lantern::test::own_tables(m);
                const float e_avg = ms_fill_table(m, t);
                m.fms_spec = ms_fresnel([&](float mu) { return principled_spec_fresnel(m, mu); },
                                        e_avg);
                principled_albedo_table(m, t);
                MaterialTables b = t;
                SpecBasis basis;
                principled_spec_basis(rough, m.spec_eta, basis);
                principled_albedo_from_basis(m, basis, b);
                for (int k = 0; k < kPrincipledAlbedoN; ++k)
                    EXPECT_NEAR(b.spec_albedo[k], t.spec_albedo[k], 2e-6f)
                        << "rough " << rough << " ior " << ior << " ms " << ms << " k " << k;
            }
        }
    }
}
