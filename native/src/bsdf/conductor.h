// Rough conductor: GGX with height-correlated Smith G2 and visible-normal sampling; Fresnel is
// either the exact complex-IOR one (eta, k per channel) or Blender's F82-tint. Reflection only,
// local frame with +Z the shading normal on the side of wo; a delta mirror when ax ay <= 2e-10.
#pragma once

#include "bsdf/fresnel.h"
#include "bsdf/lambert.h"
#include "bsdf/microfacet.h"
#include "bsdf/thin_film.h"

namespace lantern {

enum class ConductorFresnel : uint8_t { Complex, F82Tint };

struct ConductorParams {
    Ggx ggx;
    ConductorFresnel fresnel;
    Vec3 eta_or_f0;  // Complex: eta; F82Tint: base colour F0
    Vec3 k_or_tint;  // Complex: k;   F82Tint: the F82 tint
    bool beckmann = false;  // Beckmann D and G of ggx.ax; ggx's visible normals still sample
    float film_thickness = 0.0f;  // Principled Thin Film over the metal (nm; 0: none)
    float film_ior = 1.33f;
};

// D * G2 of the lobe's distribution at half vector m.
LANTERN_HD inline float conductor_dg(const ConductorParams& p, Vec3 m, Vec3 wo, Vec3 wi) {
    return p.beckmann ? beckmann_d(p.ggx.ax, m) * beckmann_g2(p.ggx.ax, wo, wi)
                      : p.ggx.d(m) * p.ggx.g2(wo, wi);
}

LANTERN_HD inline ConductorParams conductor_complex(float roughness, Vec3 eta, Vec3 k,
                                                    float anisotropy = 0.0f) {
    return {ggx_from_roughness(roughness, anisotropy), ConductorFresnel::Complex, eta, k};
}
LANTERN_HD inline ConductorParams conductor_f82(float roughness, Vec3 f0, Vec3 tint,
                                                float anisotropy = 0.0f) {
    return {ggx_from_roughness(roughness, anisotropy), ConductorFresnel::F82Tint, f0, tint};
}

LANTERN_HD inline bool conductor_is_delta(const ConductorParams& p) {
    return p.ggx.effectively_smooth();
}

// With a thin film: the film's interference over the metal's complex index (F82 metals: the
// index estimated from F0 and F82, bsdf/thin_film.h).
LANTERN_HD inline Vec3 conductor_film_fresnel(const ConductorParams& p, float cos_i) {
    Vec3 n = p.eta_or_f0, k = p.k_or_tint;
    if (p.fresnel == ConductorFresnel::F82Tint) f82_to_complex_ior(p.eta_or_f0, p.k_or_tint, &n, &k);
    return thin_film_reflectance_conductor(cos_i, p.film_ior, n, k, p.film_thickness);
}

LANTERN_HD inline Vec3 conductor_fresnel(const ConductorParams& p, float cos_i) {
    if (p.film_thickness > 0.0f) return conductor_film_fresnel(p, cos_i);
    return p.fresnel == ConductorFresnel::Complex
               ? fresnel_conductor(cos_i, p.eta_or_f0, p.k_or_tint)
               : fresnel_f82_tint(cos_i, p.eta_or_f0, p.k_or_tint);
}

// Zero for a delta lobe (its value is a distribution, reached only through sample()).
LANTERN_HD inline BsdfEval conductor_eval(const ConductorParams& p, Vec3 wo, Vec3 wi) {
    BsdfEval e{vec3(0.0f), 0.0f, 0.0f};
    if (conductor_is_delta(p) || wo.z <= 0.0f || wi.z <= 0.0f) return e;
    Vec3 m = wo + wi;
    if (length_sq(m) <= 0.0f) return e;
    m = normalize(m);
    float d = p.ggx.d(m);
    float wo_m = fmaxf(dot(wo, m), 0.0f);
    e.f = conductor_fresnel(p, wo_m) * (conductor_dg(p, m, wo, wi) / (4.0f * wo.z * wi.z));
    // pdf_w(wi) = D_wo(m) / (4 wo.m) = G1(wo) D(m) / (4 wo.z)   [Heitz 2018 (17)]
    e.pdf_fwd_w = p.ggx.g1(wo) * d / (4.0f * wo.z);
    e.pdf_rev_w = p.ggx.g1(wi) * d / (4.0f * wi.z);
    if (!is_finite(e.f) || !is_finite(e.pdf_fwd_w) || !is_finite(e.pdf_rev_w))
        return BsdfEval{vec3(0.0f), 0.0f, 0.0f};
    return e;
}

// For a delta lobe pdf_fwd_w is 1 (the discrete probability of the one direction).
LANTERN_HD inline BsdfSample conductor_sample(const ConductorParams& p, Vec3 wo, Vec2 u) {
    BsdfSample s{vec3(0.0f), vec3(0.0f), 0.0f, false};
    if (wo.z <= 0.0f) return s;
    if (conductor_is_delta(p)) {
        s.wi = vec3(-wo.x, -wo.y, wo.z);
        s.weight = conductor_fresnel(p, wo.z);
        s.pdf_fwd_w = 1.0f;
        s.pdf_rev_w = 1.0f;
        s.delta = true;
        s.valid = true;
        return s;
    }
    Vec3 m = p.ggx.sample_visible(wo, u);
    s.wi = reflect(wo, m);
    if (s.wi.z <= 0.0f) return s;
    float wo_m = fmaxf(dot(wo, m), 0.0f);
    s.pdf_fwd_w = p.ggx.g1(wo) * p.ggx.d(m) / (4.0f * wo.z);
    if (!(s.pdf_fwd_w > 0.0f) || !is_finite(s.pdf_fwd_w)) return s;
    // f cos / pdf = F G2 / G1(wo) (Beckmann: F D_b G2_b / (G1 D) of the GGX proposal)
    s.weight = conductor_fresnel(p, wo_m) *
               (p.beckmann ? conductor_dg(p, m, wo, s.wi) / (p.ggx.g1(wo) * p.ggx.d(m))
                           : p.ggx.g2(wo, s.wi) / p.ggx.g1(wo));
    s.pdf_rev_w = p.ggx.g1(s.wi) * p.ggx.d(m) / (4.0f * s.wi.z);
    s.valid = is_finite(s.weight) && is_finite(s.pdf_rev_w);
    return s;
}

}  // namespace lantern
