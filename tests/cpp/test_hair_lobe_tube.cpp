// The hair lobe as a mix's leaf (kHairTube, bsdf/hair_lobe.h; docs/curves.md "Principled Hair
// in a mix"): a tube vertex in the surface measure, each side reading its own offset h(w) at
// the point. Importance transport is then pt's BSDF with the sides swapped: f_imp(wl, wc) =
// f_rad(wc, wl), pdf_fwd and pdf_rev exchanged, the mix with a Diffuse leaf too; Radiance's f
// and forward pdf are pt's bits. Negative controls: the fiber measure's forms (no kHairTube:
// -h on the other side, cos theta in place of |n.w|) and the Jacobian alone dropped break the
// identity on most pairs.
#include <gtest/gtest.h>

#include <cmath>

#include "bsdf/material.h"
#include "core/sampling.h"
#include "integrator/bdpt_curve.h"

using namespace lantern;

namespace {

Material tube_hair(Vec3 sigma, float roughness, float radial, float offset_rad, bool tube) {
    Material m{};
    m.type = kMaterialHair;
    m.base_color = sigma;
    m.roughness = roughness;
    m.coat_roughness = radial;
    m.aniso_rotation = offset_rad;
    m.ior = 1.55f;
    m.tex_flags = kHairReverse | (tube ? kHairTube : 0u);  // (HostScene: set_mix_leaves)
    return m;
}

const Material kTubeHairs[] = {
    tube_hair(vec3(0.0f), 0.3f, 0.3f, 0.0f, true),
    tube_hair(vec3(0.2f, 0.5f, 1.0f), 0.5f, 0.6f, 2.0f * kPi / 180.0f, true),
    tube_hair(vec3(1.5f, 0.8f, 0.3f), 0.8f, 0.2f, 5.0f * kPi / 180.0f, true),
};

// a direction on the point's outer side (z > 0: pt reaches a tube point from outside)
Vec3 tube_outside(Vec2 u) {
    Vec3 w = sample_uniform_sphere(u, nullptr);
    w.z = fabsf(w.z) + 1e-3f;
    return normalize(w);
}

bool tube_close(float a, float b, float rel) { return fabsf(a - b) <= rel * fabsf(b) + 1e-9f; }

// Counts the pairs (wl outside, wc anywhere) where Importance at (wl, wc) is not Radiance at
// (wc, wl) swapped; `eval_imp` gives the Importance eval to check.
template <class F>
int tube_adjoint_misses(const Material& m, int n, uint64_t seed, F&& eval_imp, int* counted) {
    Pcg32 rng = Pcg32::for_path(seed, 0, 0);
    int miss = 0;
    *counted = 0;
    for (int i = 0; i < n; ++i) {
        const Vec3 wl = tube_outside(rng.uniform2());
        const Vec3 wc = tube_outside(rng.uniform2());
        const BsdfEval rad = hair_lobe_eval(m, wc, wl, Transport::Radiance);
        if (!(rad.f.y > 1e-6f) || !(rad.pdf_fwd_w > 1e-6f)) continue;
        ++*counted;
        const BsdfEval imp = eval_imp(wl, wc);
        if (!tube_close(imp.f.y, rad.f.y, 1e-4f) || !tube_close(imp.pdf_fwd_w, rad.pdf_rev_w, 1e-4f) ||
            !tube_close(imp.pdf_rev_w, rad.pdf_fwd_w, 1e-4f))
            ++miss;
    }
    return miss;
}

}  // namespace

TEST(HairLobeTube, ImportanceIsPtsBsdfWithTheSidesSwapped) {
    int k = 0;
    for (const Material& m : kTubeHairs) {
        int n = 0;
        const int miss = tube_adjoint_misses(m, 2000, 21 + k, [&](Vec3 wl, Vec3 wc) {
            return hair_lobe_eval(m, wl, wc, Transport::Importance);
        }, &n);
        EXPECT_GT(n, 500) << "material " << k;
        EXPECT_EQ(miss, 0) << "material " << k << ": " << miss << " of " << n;
        // negative controls: the fiber measure's forms (-h, cos theta), and the tube's with the
        // Jacobian dropped (cos theta(wl) where |wl.z| belongs), miss on most pairs
        Material fiber = m;
        fiber.tex_flags &= ~uint32_t(kHairTube);
        const int miss_fiber = tube_adjoint_misses(m, 2000, 21 + k, [&](Vec3 wl, Vec3 wc) {
            return hair_lobe_eval(fiber, wl, wc, Transport::Importance);
        }, &n);
        EXPECT_GT(miss_fiber, n / 2) << "control (fiber forms) material " << k;
        const int miss_jac = tube_adjoint_misses(m, 2000, 21 + k, [&](Vec3 wl, Vec3 wc) {
            BsdfEval e = hair_lobe_eval(m, wl, wc, Transport::Importance);
            e.f = e.f * (fabsf(wl.z) / hair_cos_theta(wl));
            return e;
        }, &n);
        EXPECT_GT(miss_jac, n / 2) << "control (Jacobian dropped) material " << k;
        ++k;
    }
}

TEST(HairLobeTube, RadianceIsPtsAndSamplesMatchEval) {
    Pcg32 rng = Pcg32::for_path(31, 0, 0);
    for (const Material& m : kTubeHairs) {
        Material pt_m = m;
        pt_m.tex_flags = 0;  // pt: no reverse pdf, no tube flag
        for (int i = 0; i < 500; ++i) {
            const Vec3 wo = tube_outside(rng.uniform2());
            const Vec3 wi = sample_uniform_sphere(rng.uniform2(), nullptr);
            const BsdfEval a = hair_lobe_eval(pt_m, wo, wi), b = hair_lobe_eval(m, wo, wi);
            EXPECT_EQ(a.f.x, b.f.x);
            EXPECT_EQ(a.f.z, b.f.z);
            EXPECT_EQ(a.pdf_fwd_w, b.pdf_fwd_w);
            const Vec3 u = vec3(rng.uniform(), rng.uniform(), rng.uniform());
            for (Transport mode : {Transport::Radiance, Transport::Importance}) {
                const BsdfSample s = hair_lobe_sample(m, wo, u, mode);
                if (!s.valid) continue;
                const BsdfEval e = hair_lobe_eval(m, wo, s.wi, mode);
                EXPECT_TRUE(tube_close(s.pdf_fwd_w, e.pdf_fwd_w, 1e-4f));
                EXPECT_TRUE(tube_close(s.pdf_rev_w, e.pdf_rev_w, 1e-4f));
                // weight pdf = f |wi.z| (the tube's cosine, Z the point's normal)
                EXPECT_TRUE(tube_close(s.weight.y * s.pdf_fwd_w, e.f.y * fabsf(s.wi.z), 2e-4f))
                    << s.weight.y * s.pdf_fwd_w << " vs " << e.f.y * fabsf(s.wi.z);
            }
        }
    }
}

// The mix (hair leaf + Diffuse) keeps the identity: one measure for both leaves.
TEST(HairLobeTube, MixWithDiffuseIsOneMeasure) {
    Material d{};
    d.type = kMaterialDiffuse;
    d.base_color = vec3(0.8f, 0.5f, 0.3f);
    d.diffuse_roughness = 0.0f;
    const Material& h = kTubeHairs[1];
    Material mx{};
    mx.type = kMaterialMix;
    mx.mix_leaf[0] = &h;
    mx.mix_weight[0] = 0.6f;
    mx.mix_leaf[1] = &d;
    mx.mix_weight[1] = 0.4f;
    mx.mix_count = 2;
    Pcg32 rng = Pcg32::for_path(41, 0, 0);
    int n = 0;
    for (int i = 0; i < 1000; ++i) {
        const Vec3 wl = tube_outside(rng.uniform2()), wc = tube_outside(rng.uniform2());
        const BsdfEval rad = material_eval(mx, true, wc, wl, Transport::Radiance);
        const BsdfEval imp = material_eval(mx, true, wl, wc, Transport::Importance);
        if (!(rad.f.y > 1e-6f)) continue;
        ++n;
        EXPECT_TRUE(tube_close(imp.f.y, rad.f.y, 1e-4f));
        EXPECT_TRUE(tube_close(imp.pdf_fwd_w, rad.pdf_rev_w, 1e-4f));
        EXPECT_TRUE(tube_close(imp.pdf_rev_w, rad.pdf_fwd_w, 1e-4f));
    }
    EXPECT_GT(n, 500);
    // the vertex: a tube's for the flagged hair (alone too), the fiber's for hair alone
    EXPECT_FALSE(strand_fiber(h));
    EXPECT_FALSE(strand_fiber(mx));
    Material fiber = h;
    fiber.tex_flags = kHairReverse;
    EXPECT_TRUE(strand_fiber(fiber));
}
