// The lobe tables a scene's conductors and principled materials carry (multiple-scattering
// compensation, the layers' albedos, the roughness rows; scene_materials.cpp fill_lobe_tables,
// the coat in scene.cpp) are kept per process and handed to the next scene with the same
// material. Checked: a material's tables are what the bsdf/ quadratures give for it whatever
// came before in the process (an independent computation, bit for bit), a material that
// differs in one input gets its own, and a scene built again reads what it read the first time.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "bsdf/material.h"
#include "scene/scene.h"

using namespace lantern;

namespace {

MaterialInput principled(const std::string& name, float roughness, float coat_ior) {
    MaterialInput m;
    m.name = name;
    m.type = "principled";
    m.base_color = vec3(0.8f, 0.5f, 0.3f);
    m.roughness = roughness;
    m.metallic = 0.3f;
    m.multiscatter = true;
    m.coat_weight = 0.5f;
    m.coat_roughness = 0.2f;
    m.coat_ior = coat_ior;
    m.sheen_weight = 0.4f;
    m.sheen_roughness = 0.3f;
    return m;
}

MaterialInput conductor(const std::string& name, float roughness) {
    MaterialInput m;
    m.name = name;
    m.type = "conductor";
    m.base_color = vec3(0.9f, 0.7f, 0.4f);
    m.roughness = roughness;
    m.multiscatter = true;
    return m;
}

SceneInput scene_of(std::vector<MaterialInput> materials) {
    SceneInput in;
    in.width = in.height = 4;
    in.materials = std::move(materials);
    return in;
}

// The tables of material `id` of `scene` computed again from its fields with the bsdf/
// functions alone (what fill_lobe_tables did before it kept them), compared byte for byte.
void expect_fresh(const HostScene& scene, int id, const std::string& what) {
    const SceneView& v = scene.view();
    Material m = v.materials[id];
    const MaterialTables& got = *m.tables;
    MaterialTables t{};
    std::memcpy(t.sheen_ltc, got.sheen_ltc, sizeof(t.sheen_ltc));  // set at conversion
    if (m.type == kMaterialPrincipled && m.coat_weight > 0.0f) principled_coat_table(m, t);
    m.tables = &t;
    const float e_avg = ms_fill_table(m, t);
    EXPECT_EQ(e_avg, got.e_avg) << what;
    EXPECT_EQ(0, std::memcmp(t.ms_e, got.ms_e, sizeof(t.ms_e))) << what << ": ms_e";
    EXPECT_EQ(0, std::memcmp(t.coat_albedo, got.coat_albedo, sizeof(t.coat_albedo)))
        << what << ": coat";
    if (m.type == kMaterialPrincipled) {
        m.fms_spec = ms_fresnel_from_average(
            ms_average_fresnel([&](float mu) { return principled_spec_fresnel(m, mu); }), e_avg);
        EXPECT_EQ(m.fms_spec.x, v.materials[id].fms_spec.x) << what;
        EXPECT_EQ(m.fms_spec.z, v.materials[id].fms_spec.z) << what;
        principled_albedo_table(m, t);
        EXPECT_EQ(0, std::memcmp(t.spec_albedo, got.spec_albedo, sizeof(t.spec_albedo)))
            << what << ": spec_albedo";
    }
}

}  // namespace

TEST(LobeTablesMemo, TablesAreTheQuadraturesWhateverCameBefore) {
    // the first scene fills the memo; the second reuses one material, changes the others by
    // one input each (roughness, coat IOR), in another order
    HostScene first(scene_of({principled("a", 0.30f, 1.5f), conductor("c", 0.4f)}));
    HostScene second(scene_of({principled("b", 0.31f, 1.5f), principled("a2", 0.30f, 1.6f),
                               conductor("c2", 0.45f), principled("a3", 0.30f, 1.5f)}));
    for (int id : {0, 1}) expect_fresh(first, id, "first scene, material " + std::to_string(id));
    for (int id : {0, 1, 2, 3})
        expect_fresh(second, id, "second scene, material " + std::to_string(id));
    // the control: materials one input apart have other tables (a memo keyed too coarsely
    // would hand them the first scene's)
    const SceneView& v = second.view();
    EXPECT_NE(0, std::memcmp(v.materials[0].tables->spec_albedo, v.materials[3].tables->spec_albedo,
                             sizeof(MaterialTables::spec_albedo)));
    EXPECT_NE(0, std::memcmp(v.materials[1].tables->coat_albedo, v.materials[3].tables->coat_albedo,
                             sizeof(MaterialTables::coat_albedo)));
    EXPECT_NE(v.materials[2].tables->e_avg, first.view().materials[1].tables->e_avg);
}

TEST(LobeTablesMemo, ASceneBuiltAgainReadsTheSameTables) {
    const SceneInput in = scene_of({principled("a", 0.55f, 1.45f), conductor("c", 0.25f),
                                    principled("d", 0.05f, 1.7f)});
    HostScene once(in), again(in);
    ASSERT_EQ(once.view().num_materials, again.view().num_materials);
    for (int k = 0; k < once.view().num_materials; ++k) {
        const Material& a = once.view().materials[k];
        const Material& b = again.view().materials[k];
        EXPECT_EQ(0, std::memcmp(a.tables, b.tables, sizeof(MaterialTables))) << k;
        EXPECT_EQ(a.fms_metal.y, b.fms_metal.y) << k;
        EXPECT_EQ(a.metal_favg1.x, b.metal_favg1.x) << k;
        EXPECT_EQ(a.e_avg, b.e_avg) << k;
    }
}
