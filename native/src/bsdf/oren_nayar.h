// Rough diffuse reflection as Blender (>= 4.3) and Cycles define it: the energy-preserving
// Oren-Nayar "EON" (Portsmouth, Kutz & Hill 2024): Fujii's qualitative Oren-Nayar plus a
// multiple-scattering term, parametrised by roughness r in [0, 1] (r = 0 is Lambert). Reflection
// only, local frame with +Z the normal on the side of wo; cosine-hemisphere sampled.
#pragma once

#include "bsdf/lambert.h"

namespace lantern {

constexpr float kFonC1 = 0.5f - 2.0f / (3.0f * kPi);           // [EON (6)]
constexpr float kFonC2 = 2.0f / 3.0f - 28.0f / (15.0f * kPi);  // [EON (12)]

struct OrenNayarParams {
    Vec3 albedo;
    float roughness;
};

// Directional albedo of the single-scattering (Fujii) term, the paper's polynomial fit [EON (13)].
LANTERN_HD inline float oren_nayar_e_fon(float mu, float r) {
    float mc = 1.0f - clampf(mu, 0.0f, 1.0f);
    float g_over_pi =
        mc * (0.0571085289f + mc * (0.491881867f + mc * (-0.332181442f + mc * 0.0714429953f)));
    return (1.0f + r * g_over_pi) / (1.0f + kFonC1 * r);
}

LANTERN_HD inline Vec3 oren_nayar_f(const OrenNayarParams& p, Vec3 wo, Vec3 wi) {
    float r = clampf(p.roughness, 0.0f, 1.0f);
    Vec3 rho = vec3(clampf(p.albedo.x, 0.0f, 1.0f), clampf(p.albedo.y, 0.0f, 1.0f),
                    clampf(p.albedo.z, 0.0f, 1.0f));
    float mu_i = wi.z, mu_o = wo.z;
    float s = dot(wi, wo) - mu_i * mu_o;
    float s_over_t = s > 0.0f ? s / fmaxf(mu_i, mu_o) : s;  // [EON (4)]
    float a_f = 1.0f / (1.0f + kFonC1 * r);
    Vec3 f_ss = rho * (kInvPi * a_f * (1.0f + r * s_over_t));
    // multiple scattering: rho_ms (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - E_avg))  [EON (11)]
    const float eps = 1e-7f;
    float e_avg = a_f * (1.0f + kFonC2 * r);
    float e_o = oren_nayar_e_fon(mu_o, r), e_i = oren_nayar_e_fon(mu_i, r);
    float ms = kInvPi * fmaxf(eps, 1.0f - e_o) * fmaxf(eps, 1.0f - e_i) / fmaxf(eps, 1.0f - e_avg);
    // Cycles (closure/bsdf_oren_nayar.h) weights the whole closure by the colour and puts the
    // paper's rho_ms inside it too: its multiple scattering is rho x rho_ms, which Blender renders
    // and so Lantern follows (1-3 % darker than EON's rho_ms at rho 0.8: difftest D3)
    Vec3 rho_ms;
    for (int c = 0; c < 3; ++c) {
        float rc = rho[c];
        float v = rc * rc * rc * e_avg / (1.0f - rc * (1.0f - e_avg));
        (c == 0 ? rho_ms.x : c == 1 ? rho_ms.y : rho_ms.z) = v;
    }
    if (r == 0.0f) return f_ss;  // exactly Lambert
    return f_ss + rho_ms * ms;
}

LANTERN_HD inline BsdfEval oren_nayar_eval(const OrenNayarParams& p, Vec3 wo, Vec3 wi) {
    return cosine_lobe_eval([&p](Vec3 o, Vec3 i) { return oren_nayar_f(p, o, i); }, wo, wi);
}

LANTERN_HD inline BsdfSample oren_nayar_sample(const OrenNayarParams& p, Vec3 wo, Vec2 u) {
    return cosine_lobe_sample([&p](Vec3 o, Vec3 i) { return oren_nayar_f(p, o, i); }, wo, u);
}

}  // namespace lantern
