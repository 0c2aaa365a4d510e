// The Translucent BSDF where a smooth mesh's shading normal N leans from its facet (D43): on
// camera sub-paths it reads the light's side of N alone (Cycles' bsdf_translucent_eval and
// _sample take any view), so a view below N transmits (black before); light sub-paths keep the
// symmetric BSDF.
#include <gtest/gtest.h>

#include <cmath>

#include "bsdf/material.h"

using namespace lantern;

namespace {

Material translucent_material(float albedo) {
    Material m{};
    m.type = kMaterialTranslucent;
    m.base_color = vec3(albedo);
    return m;
}

}  // namespace

TEST(TranslucentViewBelowN, CameraPathTransmitsForAViewBelowN) {
    const Material m = translucent_material(0.8f);
    const Vec3 wo = normalize(vec3(0.9f, 0.1f, -0.25f));  // below N, above a leaning facet
    const Vec3 wi = normalize(vec3(-0.3f, 0.2f, -0.8f));  // N's far side
    const BsdfEval e = material_eval(m, true, wo, wi, Transport::Radiance);
    EXPECT_NEAR(e.f.x, 0.8f / 3.14159265f, 1e-6f);
    EXPECT_NEAR(e.pdf_fwd_w, -wi.z / 3.14159265f, 1e-6f);
    EXPECT_NEAR(e.pdf_rev_w, -wo.z / 3.14159265f, 1e-6f);
    // N's near side stays black, as in Cycles
    EXPECT_EQ(material_eval(m, true, wo, vec3(0.0f, 0.6f, 0.8f), Transport::Radiance).f.x, 0.0f);
    // light sub-paths: unchanged (no view below N)
    EXPECT_EQ(material_eval(m, true, wo, wi, Transport::Importance).f.x, 0.0f);
    // a view above N: the Lambert through the surface, as before
    const Vec3 up = normalize(vec3(0.2f, 0.1f, 0.9f));
    EXPECT_NEAR(material_eval(m, true, up, wi, Transport::Radiance).f.x, 0.8f / 3.14159265f, 1e-6f);
}

TEST(TranslucentViewBelowN, CameraPathSamplesForAViewBelowN) {
    const Material m = translucent_material(0.5f);
    const Vec3 wo = normalize(vec3(0.9f, -0.2f, -0.3f));
    int valid = 0;
    for (int k = 0; k < 64; ++k) {
        const Vec3 u{(k % 8 + 0.5f) / 8.0f, (k / 8 + 0.5f) / 8.0f, 0.5f};
        const BsdfSample s = material_sample(m, true, wo, u, Transport::Radiance);
        if (!s.valid) continue;
        ++valid;
        ASSERT_LT(s.wi.z, 0.0f);
        EXPECT_NEAR(s.weight.x, 0.5f, 1e-6f);
        const BsdfEval e = material_eval(m, true, wo, s.wi, Transport::Radiance);
        EXPECT_NEAR(s.pdf_fwd_w, e.pdf_fwd_w, 1e-5f * ::fmaxf(1.0f, e.pdf_fwd_w));
    }
    EXPECT_EQ(valid, 64);
    EXPECT_FALSE(material_sample(m, true, wo, Vec3{0.3f, 0.6f, 0.5f}, Transport::Importance).valid);
}
