// View-corrected glossy materials (bsdf/shading_normal.h, material.h corrected_eval): the
// corrected normal against its defining property (the view's mirror direction exactly at the
// threshold height, in the plane of n and ng), a view below the shading normal lit (black
// before), one BSDF for both transports (the importance eval is the radiance eval with the
// directions swapped, each pdf its own sampler's), sample() against eval(), and a chi-square
// of the camera sub-path's sampler about the corrected normal.
#include <gtest/gtest.h>

#include <cmath>

#include "test_material_helpers.h"

using namespace lantern;
using namespace lantern::test;

namespace {

// ng tilted by delta from the shading normal (+Z) about the y axis, local to its frame
Vec3 tilted_ng(float delta) { return vec3(std::sin(delta), 0.0f, std::cos(delta)); }

Vec3 mirror(Vec3 v, Vec3 n) { return n * (2.0f * dot(v, n)) - v; }

// a bumped or smooth-shaded surface seen at a grazing angle: ng 0.35 rad off n, the view
// 1.45 rad off ng on the side where n tilts away from it, so below n
struct Grazing {
    Vec3 ng = tilted_ng(0.35f);
    Vec3 v = normalize(vec3(std::sin(0.35f + 1.45f), 0.1f, std::cos(0.35f + 1.45f)));
};

}  // namespace

TEST(ViewCorrectedNormal, ValidMirrorLeavesTheNormal) {
    const Vec3 ng = tilted_ng(0.2f);
    for (float th : {0.1f, 0.5f, 1.0f}) {
        const Vec3 v = dir_from_angles(th, 0.3f);
        ASSERT_GE(dot(mirror(v, vec3(0.0f, 0.0f, 1.0f)), ng), std::fmin(0.9f * dot(v, ng), 0.01f));
        const Vec3 n2 = valid_reflection_normal(ng, v);
        EXPECT_EQ(n2.x, 0.0f);
        EXPECT_EQ(n2.y, 0.0f);
        EXPECT_EQ(n2.z, 1.0f);
    }
}

TEST(ViewCorrectedNormal, MirrorRisesExactlyToTheThreshold) {
    for (float delta : {0.1f, 0.35f, 0.7f}) {
        const Vec3 ng = tilted_ng(delta);
        for (float above : {0.02f, 0.2f, 0.6f}) {  // the view's angle above the surface
            for (float phi : {-0.5f, 0.0f, 0.4f}) {
                // on the side where n turns away from the view
                const float th = delta + float(kPi) / 2.0f - above;
                Vec3 v = normalize(vec3(std::sin(th) * std::cos(phi), std::sin(th) * std::sin(phi),
                                        std::cos(th)));
                if (!(dot(v, ng) > 0.0f)) continue;
                const float t = std::fmin(0.9f * dot(v, ng), 0.01f);
                if (dot(mirror(v, vec3(0.0f, 0.0f, 1.0f)), ng) >= t) continue;
                const Vec3 n2 = valid_reflection_normal(ng, v);
                EXPECT_NEAR(length(n2), 1.0f, 1e-5f);
                EXPECT_NEAR(dot(mirror(v, n2), ng), t, 2e-4f) << delta << " " << above;
                EXPECT_GT(dot(v, n2), 0.0f);  // the view is above the corrected normal
                // in the plane of n and ng, between them
                EXPECT_NEAR(dot(n2, cross(ng, vec3(0.0f, 0.0f, 1.0f))), 0.0f, 1e-5f);
                EXPECT_GE(dot(n2, ng), std::cos(delta) - 1e-5f);
                EXPECT_GT(n2.z, std::cos(delta) - 1e-5f);
            }
        }
    }
}

TEST(ViewCorrected, GrazingViewBelowTheNormalIsLit) {
    const Grazing g;
    ASSERT_LT(g.v.z, 0.0f);
    ASSERT_GT(dot(g.v, g.ng), 0.0f);
    const Material m = principled(vec3(0.8f, 0.5f, 0.3f), 0.0f, 0.0f, 0.4f);
    const Material metal = principled(vec3(0.9f, 0.6f, 0.3f), 1.0f, 0.0f, 0.3f);
    ASSERT_TRUE(material_corrects_view(m));
    const Vec3 l = normalize(vec3(-0.3f, 0.2f, 0.9f));
    for (const Material* x : {&m, &metal}) {
        const BsdfEval e = material_eval(*x, true, g.v, l, Transport::Radiance,
                                         vec3(0.0f, 0.0f, 1.0f), g.ng);
        EXPECT_GT(luminance(e.f), 0.0f);
        EXPECT_GT(e.pdf_fwd_w, 0.0f);
        // without the geometric normal (ng = n) nothing is corrected: black, as before
        const BsdfEval b = material_eval(*x, true, g.v, l, Transport::Radiance);
        EXPECT_TRUE(is_black(b.f));
    }
    // transmission is never corrected (a sharp Principled is: SharpSpecularMirrorsAboutN2)
    EXPECT_FALSE(material_corrects_view(principled(vec3(0.8f), 0.0f, 1.0f, 0.3f)));
    EXPECT_FALSE(material_corrects_view(principled(vec3(0.8f), 0.0f, 1.0f, 0.0f)));
}

// D48 (docs/difftest.md): a Principled of Roughness 0 and a sharp conductor correct their normal
// as Cycles does for every microfacet closure, alpha 0 too: on camera sub-paths the delta pick
// is the mirror about n'(v), above the facet, where the mirror about n falls under it (that
// light was lost); the other picks agree with eval as for a rough one
TEST(ViewCorrected, SharpSpecularMirrorsAboutN2) {
    const Grazing g;
    const Vec3 n2 = valid_reflection_normal(g.ng, g.v);
    ASSERT_LT(n2.z, 1.0f);
    ASSERT_LT(dot(mirror(g.v, vec3(0.0f, 0.0f, 1.0f)), g.ng), 0.0f);  // the uncorrected mirror
    // a sharp Glossy BSDF (a conductor; a Principled of Metallic 1 resolves to one too)
    Material mirror_m = principled(vec3(0.9f, 0.6f, 0.3f), 1.0f, 0.0f, 0.0f);
    mirror_m.type = kMaterialConductor;
    ASSERT_TRUE(conductor_is_delta(material_conductor(mirror_m)));
    for (float metallic : {0.0f, 1.0f, 2.0f}) {  // 2: the conductor
        const Material m = metallic > 1.0f ? mirror_m
                                           : principled(vec3(0.8f, 0.5f, 0.3f), metallic, 0.0f,
                                                        0.0f);
        ASSERT_TRUE(material_corrects_view(m));
        ASSERT_TRUE(m.type == kMaterialConductor || principled_spec_is_delta(m));
        Pcg32 rng = Pcg32::for_path(11, 0, 0);
        int deltas = 0, others = 0;
        for (int i = 0; i < 2000; ++i) {
            const Vec2 u = rng.uniform2();
            const Vec3 uu = vec3(u.x, u.y, rng.uniform());
            const BsdfSample s = material_sample(m, true, g.v, uu, Transport::Radiance,
                                                 vec3(0.0f, 0.0f, 1.0f), g.ng);
            if (!s.valid) continue;
            if (s.delta) {
                ++deltas;
                const Vec3 r = mirror(g.v, n2);
                EXPECT_NEAR(s.wi.x, r.x, 1e-4f);
                EXPECT_NEAR(s.wi.y, r.y, 1e-4f);
                EXPECT_NEAR(s.wi.z, r.z, 1e-4f);
                EXPECT_GT(dot(s.wi, g.ng), 0.0f);
                EXPECT_GT(luminance(s.weight), 0.0f);
                EXPECT_TRUE(is_finite(s.weight));
            } else {
                ++others;
                const BsdfEval e = material_eval(m, true, g.v, s.wi, Transport::Radiance,
                                                 vec3(0.0f, 0.0f, 1.0f), g.ng);
                EXPECT_NEAR(e.pdf_fwd_w, s.pdf_fwd_w, 1e-4f * (1.0f + s.pdf_fwd_w));
            }
            // without the geometric normal (ng = n) the view below n reflects nothing, as before
            EXPECT_FALSE(material_sample(m, true, g.v, uu, Transport::Radiance).valid);
        }
        EXPECT_GT(deltas, 100) << metallic;
        if (metallic == 0.0f) EXPECT_GT(others, 100);
    }
}

// A bumped Principled: coat_n carries the unbent normal (here ng, a flat surface), and its
// base takes the bump shadowing term against it
Material bumped(Material m) {
    m.tex_flags |= kTexBump;
    return m;
}

TEST(ViewCorrected, OneBsdfForBothTransports) {
    const Grazing g;
    const Material mats[] = {principled(vec3(0.8f, 0.5f, 0.3f), 0.0f, 0.0f, 0.4f),
                             principled(vec3(0.9f, 0.6f, 0.3f), 1.0f, 0.0f, 0.3f),
                             bumped(principled(vec3(0.8f, 0.5f, 0.3f), 0.0f, 0.0f, 0.4f))};
    Pcg32 rng = Pcg32::for_path(5, 0, 0);
    int corrected = 0;
    for (const Material& m : mats) {
        const Vec3 z = (m.tex_flags & kTexBump) ? g.ng : vec3(0.0f, 0.0f, 1.0f);
        ASSERT_EQ(corrected_base_shadowed(m, z), (m.tex_flags & kTexBump) != 0);
        for (int i = 0; i < 400; ++i) {
            // views from grazing (below n) to steep, lights over the geometric hemisphere
            const Vec2 a = rng.uniform2(), b = rng.uniform2();
            const Vec3 v = normalize(g.v * a.x + g.ng * (1.0f - a.x) +
                                     vec3(0.0f, 0.4f * (a.y - 0.5f), 0.0f));
            const Vec3 l = Frame::from_normal(g.ng).to_world(
                vec3(std::sqrt(b.x) * std::cos(6.2831853f * b.y),
                     std::sqrt(b.x) * std::sin(6.2831853f * b.y), std::sqrt(1.0f - b.x)));
            if (!(dot(v, g.ng) > 0.0f) || !(dot(l, g.ng) > 0.0f)) continue;
            corrected += valid_reflection_normal(g.ng, v).z < 1.0f;
            const BsdfEval r = material_eval(m, true, v, l, Transport::Radiance, z, g.ng);
            const BsdfEval t = material_eval(m, true, l, v, Transport::Importance, z, g.ng);
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.f[c], t.f[c], 1e-5f * (1.0f + r.f[c]));
            EXPECT_NEAR(r.pdf_fwd_w, t.pdf_rev_w, 1e-5f * (1.0f + r.pdf_fwd_w));
            EXPECT_NEAR(r.pdf_rev_w, t.pdf_fwd_w, 1e-5f * (1.0f + r.pdf_rev_w));
        }
    }
    EXPECT_GT(corrected, 100);  // the correction is exercised
}

TEST(ViewCorrected, SampleAgreesWithEvalInBothTransports) {
    const Grazing g;
    for (bool bump : {false, true}) {
        const Vec3 z = bump ? g.ng : vec3(0.0f, 0.0f, 1.0f);
        const Material m0 = principled(vec3(0.8f, 0.5f, 0.3f), 0.0f, 0.0f, 0.4f);
        const Material m = bump ? bumped(m0) : m0;
        for (bool radiance : {true, false}) {
            // radiance: the grazing view below n; importance: a light above n and ng
            const Vec3 wo = radiance ? g.v : normalize(vec3(-0.2f, 0.1f, 1.0f));
            const Transport mode = radiance ? Transport::Radiance : Transport::Importance;
            Pcg32 rng = Pcg32::for_path(7, 0, 0);
            int kept = 0, turned = 0;
            for (int i = 0; i < 3000; ++i) {
                const Vec2 u = rng.uniform2();
                BsdfSample s = material_sample(m, true, wo, vec3(u.x, u.y, rng.uniform()), mode, z,
                                               g.ng);
                if (!s.valid || !(dot(s.wi, g.ng) > 0.0f)) continue;
                ++kept;
                const Vec3 v = radiance ? wo : s.wi;
                turned += valid_reflection_normal(g.ng, v).z < 1.0f;
                const BsdfEval e = material_eval(m, true, wo, s.wi, mode, z, g.ng);
                EXPECT_NEAR(e.pdf_fwd_w, s.pdf_fwd_w, 1e-4f * (1.0f + s.pdf_fwd_w));
                EXPECT_NEAR(e.pdf_rev_w, s.pdf_rev_w, 1e-4f * (1.0f + s.pdf_rev_w));
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(s.weight[c], e.f[c] * std::fabs(s.wi.z) / e.pdf_fwd_w,
                                1e-4f * (1.0f + s.weight[c]));
            }
            EXPECT_GT(kept, 1000) << radiance;
            EXPECT_GT(turned, radiance ? kept - 1 : 20) << radiance;
        }
        // the camera sub-path's sampler about the corrected normal against eval's pdf
        Chi2Result r = chi2_sphere(
            [&](Vec2 u, float uc, Vec3* wi) {
                BsdfSample s =
                    material_sample(m, true, g.v, vec3(u.x, u.y, uc), Transport::Radiance, z, g.ng);
                *wi = s.wi;
                return s.valid;
            },
            [&](Vec3 wi) {
                const BsdfEval e = material_eval(m, true, g.v, wi, Transport::Radiance, z, g.ng);
                return double(e.pdf_fwd_w);
            },
            200000, 1, 32, 32, 12);
        EXPECT_GT(r.p_value, 1e-4) << "chi2 " << r.chi2 << " dof " << r.dof << " bump " << bump;
    }
}
