// Lambertian reflection in a local frame with +Z the shading normal on the side of wo.
// Forward and reverse pdfs are in solid angle; both are the cosine pdf of the outgoing side.
#pragma once

#include "bsdf/cosine_lobe.h"

namespace lantern {

LANTERN_HD inline BsdfEval lambert_eval(Vec3 albedo, Vec3 wo, Vec3 wi) {
    return cosine_lobe_eval([albedo](Vec3, Vec3) { return albedo * kInvPi; }, wo, wi);
}

// Sampled exactly like cosine_lobe_sample, with the weight kept exactly the albedo.
LANTERN_HD inline BsdfSample lambert_sample(Vec3 albedo, Vec3 wo, Vec2 u) {
    BsdfSample s{vec3(0.0f), vec3(0.0f), 0.0f, false};
    if (wo.z <= 0.0f) return s;
    s.wi = sample_cosine_hemisphere(u, &s.pdf_fwd_w);
    if (s.pdf_fwd_w <= 0.0f || s.wi.z <= 0.0f) return s;
    s.weight = albedo;  // (albedo/pi) * cos / (cos/pi)
    s.pdf_rev_w = pdf_cosine_hemisphere(wo.z);
    s.valid = true;
    return s;
}

// ---- A bumped Lambert: Cycles' diffuse convention ----
// Cycles' Diffuse BSDF (bsdf_diffuse.h) reads only the light's side of its normal N: a Bump or
// Normal Map that turns N away from the viewer leaves it lit (Lantern's Lambert above is black
// there). Where N differs from the shader's own normal N_s (Cycles' sd->N: the interpolated
// normal, bent by a Displacement bump alone), Cycles 4.5+ multiplies it by its bump shadowing
// term (bsdf.h bump_shadowing_term, Bump Map Correction on): 0 where the light, N and N_s
// disagree on their sides, else the GGX masking G1 of Conty Estevez, Lecocq and Stein ("A
// Microfacet-Based Shadowing Function to Solve the Bump Terminator Problem", Ray Tracing Gems
// 2019, ch. 12) with alpha^2 = min(tan^2(N, N_s) / 8, 1) at the light's angle to N_s. Both read
// the light's direction l only, so the BSDF is f(view, l) = albedo / pi * G(l) [l.z > 0]: in
// radiance transport l is wi, in importance transport (light sub-paths) l is wo, so that every
// integrator sees the same f. n_s: N_s in the local frame (+Z is N); (0, 0, 1) where N is N_s.
LANTERN_HD inline float bump_shadowing(Vec3 n_s, Vec3 l) {
    const float cos_si = dot(n_s, l), cos_sn = n_s.z;
    if (cos_si * cos_sn * l.z < 0.0f) return 0.0f;  // l below N_s while above N (or the reverse)
    const float cos_i = fabsf(cos_si), cos_d = fabsf(cos_sn);
    if (cos_d >= 1.0f || cos_i >= 1.0f) return 1.0f;
    if (cos_i < 1e-6f) return 0.0f;
    const float alpha2 = fminf(0.125f * (1.0f / (cos_d * cos_d) - 1.0f), 1.0f);
    const float tan2_i = 1.0f / (cos_i * cos_i) - 1.0f;
    return 2.0f / (1.0f + sqrtf(1.0f + alpha2 * tan2_i));  // Smith G1 of GGX
}

// The view's side has no cosine and no normal but the geometric one (the caller's side test):
// camera sub-paths (radiance: wi is the light) sample l by the cosine about N, light sub-paths
// (importance: wo is the light) sample the view v by the cosine about ng, the geometric normal
// in this frame (ng_l), which covers every view the lobe lights, N's back included. Each pdf is
// its sampler's: pdf(l) = cos(l, N) / pi, pdf(v) = cos(v, ng) / pi.
LANTERN_HD inline BsdfEval lambert_bumped_eval(Vec3 albedo, Vec3 n_s, Vec3 ng_l, Vec3 wo, Vec3 wi,
                                               bool radiance) {
    BsdfEval e{vec3(0.0f), 0.0f, 0.0f};
    const Vec3 l = radiance ? wi : wo, v = radiance ? wo : wi;
    if (!(l.z > 0.0f)) return e;
    e.f = albedo * (kInvPi * bump_shadowing(n_s, l));
    const float pdf_l = pdf_cosine_hemisphere(l.z), pdf_v = pdf_cosine_hemisphere(dot(v, ng_l));
    e.pdf_fwd_w = radiance ? pdf_l : pdf_v;
    e.pdf_rev_w = radiance ? pdf_v : pdf_l;
    return e;
}

LANTERN_HD inline BsdfSample lambert_bumped_sample(Vec3 albedo, Vec3 n_s, Vec3 ng_l, Vec3 wo,
                                                   Vec2 u, bool radiance) {
    BsdfSample s{vec3(0.0f), vec3(0.0f), 0.0f, false};
    if (radiance) {  // the light's side, about N
        s.wi = sample_cosine_hemisphere(u, &s.pdf_fwd_w);
        if (s.pdf_fwd_w <= 0.0f || s.wi.z <= 0.0f) return s;
        const float g = bump_shadowing(n_s, s.wi);
        if (!(g > 0.0f)) return s;
        s.weight = albedo * g;  // (albedo/pi) g cos / (cos/pi)
        s.pdf_rev_w = pdf_cosine_hemisphere(dot(wo, ng_l));
        s.valid = true;
        return s;
    }
    if (!(wo.z > 0.0f)) return s;  // the light below N
    const float g = bump_shadowing(n_s, wo);
    if (!(g > 0.0f)) return s;
    float pdf_g;
    const Vec3 local = sample_cosine_hemisphere(u, &pdf_g);  // the view's side, about ng
    s.wi = Frame::from_normal(ng_l).to_world(local);
    s.pdf_fwd_w = pdf_cosine_hemisphere(dot(s.wi, ng_l));
    if (!(s.pdf_fwd_w > 0.0f) || s.wi.z == 0.0f) return s;
    s.weight = albedo * (g * fabsf(s.wi.z) * kInvPi / s.pdf_fwd_w);  // f |cos_N| / pdf
    s.pdf_rev_w = pdf_cosine_hemisphere(wo.z);
    s.valid = is_finite(s.weight);
    return s;
}

}  // namespace lantern
