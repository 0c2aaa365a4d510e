// Sheen: the "Charlie" microfacet distribution (Estevez & Kulla 2017, "Production friendly
// microfacet sheen BRDF") with Neubelt & Pettineo's visibility 1 / (4 (cos_i + cos_o - cos_i
// cos_o)) (as in glTF's KHR_materials_sheen), cosine-hemisphere sampled, alpha = roughness^2
// clamped to >= 0.07. That pair reflects more than it receives at grazing for alpha < ~0.21, so
// f is divided by the grazing albedo E(0, alpha) there (one constant per alpha: stays reciprocal,
// albedo <= 1 for every wo, tested); smoother sheens are left as they are.
#pragma once

#include "bsdf/lambert.h"

namespace lantern {

struct SheenParams {
    Vec3 color;
    float roughness;  // alpha = max(roughness^2, 0.07)
};

LANTERN_HD inline float sheen_alpha(float roughness) {
    return fmaxf(sqr(clampf(roughness, 0.0f, 1.0f)), 0.07f);
}

// D(m) = (2 + 1/alpha) sin(theta_m)^(1/alpha) / (2 pi)
LANTERN_HD inline float sheen_d(float alpha, float cos_m) {
    float sin2 = fmaxf(0.0f, 1.0f - cos_m * cos_m);
    float inv_a = 1.0f / alpha;
    return (2.0f + inv_a) * powf(sin2, 0.5f * inv_a) * (0.5f * kInvPi);
}

// max(1, E(mu_o = 0, alpha)) by midpoint quadrature (2000^2) at a few alphas, +0.5%; E(0, alpha)
// is convex in alpha, so linear interpolation only overestimates.
LANTERN_HD inline float sheen_energy_norm(float alpha) {
    constexpr int kN = 10;
    constexpr float kAlpha[kN] = {0.07f, 0.08f, 0.09f, 0.10f, 0.12f,
                                  0.14f, 0.16f, 0.18f, 0.20f, 0.22f};
    constexpr float kE0[kN] = {1.5854f, 1.4932f, 1.4173f, 1.3535f, 1.2518f,
                               1.1738f, 1.1118f, 1.0610f, 1.0186f, 0.9826f};
    if (alpha >= kAlpha[kN - 1]) return 1.0f;
    int i = 0;
    while (i < kN - 2 && alpha > kAlpha[i + 1]) ++i;
    float t = clampf((alpha - kAlpha[i]) / (kAlpha[i + 1] - kAlpha[i]), 0.0f, 1.0f);
    return fmaxf(1.0f, 1.005f * (kE0[i] + t * (kE0[i + 1] - kE0[i])));
}

LANTERN_HD inline Vec3 sheen_f(const SheenParams& p, Vec3 wo, Vec3 wi) {
    Vec3 m = wo + wi;
    if (length_sq(m) <= 0.0f) return vec3(0.0f);
    m = normalize(m);
    float alpha = sheen_alpha(p.roughness);
    float v = 1.0f / (4.0f * (wi.z + wo.z - wi.z * wo.z));
    float f = sheen_d(alpha, m.z) * v / sheen_energy_norm(alpha);
    return is_finite(f) ? p.color * f : vec3(0.0f);
}

LANTERN_HD inline BsdfEval sheen_eval(const SheenParams& p, Vec3 wo, Vec3 wi) {
    return cosine_lobe_eval([&p](Vec3 o, Vec3 i) { return sheen_f(p, o, i); }, wo, wi);
}

LANTERN_HD inline BsdfSample sheen_sample(const SheenParams& p, Vec3 wo, Vec2 u) {
    return cosine_lobe_sample([&p](Vec3 o, Vec3 i) { return sheen_f(p, o, i); }, wo, u);
}

}  // namespace lantern
