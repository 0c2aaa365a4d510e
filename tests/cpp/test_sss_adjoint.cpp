// The adjoint walk's exit lobe (integrator/lt_sss.h) evaluates sss_entry_pdf, the density of the
// direction sss_entry samples (pt_sss.h: a rough refraction into the medium; Skin: half a cosine
// lobe). Chi-square of sss_entry's samples against it and its mass against the fraction of
// valid samples, for Random Walk and Skin; negative control: the refraction's Jacobian left out.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "integrator/pt_sss.h"
#include "test_bsdf_helpers.h"

using namespace lantern;
using namespace lantern::test;

namespace {

Material sss_entry_material(float roughness, float ior, bool skin) {
    Material m{};
    m.type = kMaterialPrincipled;
    m.roughness = roughness;
    m.ss_ior = ior;
    m.ss_skin = skin ? 1u : 0u;
    return m;
}

// the density's integral over the sphere by a fine midpoint rule in (z, phi): the refraction's
// density ends sharply at the critical cone, where pdf_mass_on_sphere's 768 x 768 rule reads up
// to 1e-3 off; 1024 x 512 up to 2.4e-3 (roughness 1 at theta 1.2; over the lower hemisphere at
// 4096 x 16384 every case reads within 1e-4 of 1), so the mass is held to 3e-3 and the
// chi-square carries the test
double sss_entry_mass(const std::function<double(Vec3)>& pdf) {
    const int nz = 1024, np = 512;
    double sum = 0.0;
    for (int i = 0; i < nz; ++i)
        for (int j = 0; j < np; ++j) {
            const double z = -1.0 + 2.0 * (i + 0.5) / nz, phi = 2.0 * kPi * (j + 0.5) / np;
            const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
            sum += pdf(vec3(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)));
        }
    return sum * (2.0 / nz) * (2.0 * kPi / np);
}

// (sub 24: the bins' own quadrature of that edge; at 6 the chi-square read the rule's error)
Chi2Result sss_entry_chi2(const Material& m, Vec3 wo, const std::function<double(Vec3)>& pdf) {
    return chi2_sphere(
        [&](Vec2 u, float, Vec3* wi) { return sss_entry(m, wo, u, wi); }, pdf, 200000, 1, 32,
        32, 24);
}

}  // namespace

TEST(SssAdjoint, EntryPdfMatchesEntrySampling) {
    struct Case {
        float roughness, ior;
        bool skin;
    };
    for (const Case c : {Case{0.5f, 1.4f, false}, Case{1.0f, 1.4f, false},
                         Case{0.7f, 2.0f, false}, Case{0.5f, 1.4f, true}})
        for (float theta_o : {0.3f, 1.2f}) {
            const Material m = sss_entry_material(c.roughness, c.ior, c.skin);
            const Vec3 wo = dir_from_angles(theta_o, 0.4f);
            const Chi2Result r =
                sss_entry_chi2(m, wo, [&](Vec3 wi) { return double(sss_entry_pdf(m, wo, wi)); });
            const std::string what = "roughness " + std::to_string(c.roughness) + " ior " +
                                     std::to_string(c.ior) + (c.skin ? " skin" : "") +
                                     " theta " + std::to_string(theta_o);
            EXPECT_GT(r.p_value, 1e-4) << what << " chi2 " << r.chi2 << " dof " << r.dof;
            const double mass =
                sss_entry_mass([&](Vec3 wi) { return double(sss_entry_pdf(m, wo, wi)); });
            EXPECT_NEAR(mass, r.valid_frac, 3e-3) << what;
        }
}

TEST(SssAdjoint, EntryPdfWithoutJacobianFails) {
    // negative control: the visible normals' density alone (the refraction's Jacobian
    // |wi.h| / (wi.h + wo.h / eta)^2 left out) is not sss_entry's density
    const Material m = sss_entry_material(1.0f, 1.4f, false);
    const Vec3 wo = dir_from_angles(0.3f, 0.4f);
    const Chi2Result r = sss_entry_chi2(m, wo, [&](Vec3 wi) {
        if (!(wi.z < 0.0f)) return 0.0;
        Vec3 h = normalize(wo + wi * m.ss_ior);
        if (h.z < 0.0f) h = -h;
        if (!(dot(wo, h) > 0.0f) || !(dot(wi, h) < 0.0f)) return 0.0;
        return double(Ggx::isotropic(1.0f).pdf_visible(wo, h));
    });
    EXPECT_FALSE(r.p_value > 1e-4 && pdf_mass_agrees(r))
        << "a density without the Jacobian passed: p " << r.p_value << " mass " << r.pdf_mass;
}
