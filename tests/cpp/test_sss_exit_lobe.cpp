// The adjoint walk's continuation at its exit (integrator/lt_sss.h): lt_sss_exit_sample draws
// half a cosine, half the walk's last direction refracted out through a GGX normal visible from
// inside; lt_sss_exit_pdf is the mixture's density, which the continuation's weight divides by.
// Chi-square of the samples against it (and its mass against the valid fraction: total internal
// reflection loses some), Random Walk and Skin, steep and grazing last directions; negative
// control: the refraction's Jacobian left out.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "integrator/lt.h"
#include "test_bsdf_helpers.h"

using namespace lantern;
using namespace lantern::test;

namespace {

Material exit_lobe_material(float roughness, bool skin) {
    Material m{};
    m.type = kMaterialPrincipled;
    m.roughness = roughness;
    m.ss_ior = 1.4f;
    m.ss_skin = skin ? 1u : 0u;
    return m;
}

Chi2Result exit_lobe_chi2(const Material& m, Vec3 d, const std::function<double(Vec3)>& pdf) {
    return chi2_sphere(
        [&](Vec2 u, float u3, Vec3* c) { return lt_sss_exit_sample(m, d, Vec3{u.x, u.y, u3}, c); },
        pdf, 200000, 3, 32, 32, 12);
}

}  // namespace

TEST(SssExitLobe, PdfMatchesSampling) {
    for (const float roughness : {0.2f, 0.5f, 1.0f})
        for (const bool skin : {false, true})
            for (const float theta_d : {0.2f, 0.9f, 1.4f}) {
                if (skin && roughness != 0.5f) continue;
                const Material m = exit_lobe_material(roughness, skin);
                const Vec3 d = dir_from_angles(theta_d, 0.7f);
                const Chi2Result r = exit_lobe_chi2(
                    m, d, [&](Vec3 c) { return double(lt_sss_exit_pdf(m, d, c)); });
                const std::string what = "roughness " + std::to_string(roughness) +
                                         (skin ? " skin" : "") + " theta " +
                                         std::to_string(theta_d);
                EXPECT_GT(r.p_value, 1e-4) << what << " chi2 " << r.chi2 << " dof " << r.dof;
                expect_pdf_mass(r, what);
            }
}

TEST(SssExitLobe, PdfWithoutJacobianFails) {
    const Material m = exit_lobe_material(0.5f, false);
    const Vec3 d = dir_from_angles(0.2f, 0.7f);
    const Chi2Result r = exit_lobe_chi2(m, d, [&](Vec3 c) {
        if (!(c.z > 0.0f)) return 0.0;
        double pdf = 0.5 * c.z * kInvPi;
        Vec3 h = normalize(d * m.ss_ior - c);
        if (h.z < 0.0f) h = -h;
        if (dot(d, h) > 0.0f && dot(c, h) > 0.0f)
            pdf += 0.5 * Ggx::isotropic(lt_sss_exit_alpha(m)).pdf_visible(d, h);
        return pdf;
    });
    EXPECT_FALSE(r.p_value > 1e-4 && pdf_mass_agrees(r))
        << "a density without the Jacobian passed: p " << r.p_value << " mass " << r.pdf_mass;
}
