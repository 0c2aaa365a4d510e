// Dielectric interface: rough GGX reflection + transmission (Walter et al. 2007 with visible-normal
// sampling), or smooth specular reflection + transmission as delta lobes when ax ay <= 2e-10 or the
// index is ~1. Local frame: +Z is the normal on the outside; wo and wi may lie on either side.
// eta = n_inside / n_outside. As in Cycles, radiance transport does not scale refraction by
// 1/eta'^2 (radiance is carried as if every medium had index 1, so an emitter inside glass is as
// bright seen through it as in air, less Fresnel); importance transport, its adjoint, divides
// transmission by eta'^2 (eta' of wo's side), so that f_radiance(wo, wi) == f_importance(wi, wo)
// (Veach 1997, sec. 5.2) and light paths carry what camera paths do.
#pragma once

#include "bsdf/fresnel.h"
#include "bsdf/lambert.h"
#include "bsdf/microfacet.h"

namespace lantern {

enum class Transport : uint8_t { Radiance, Importance };

struct DielectricParams {
    Ggx ggx;
    float eta;
    Transport mode;
};

LANTERN_HD inline DielectricParams dielectric(float roughness, float eta, Transport mode,
                                             float anisotropy = 0.0f) {
    // eta <= 0 is nonsense; keep it positive so every ratio below stays finite
    return {ggx_from_roughness(roughness, anisotropy), fmaxf(eta, 1e-3f), mode};
}

LANTERN_HD inline bool dielectric_is_delta(const DielectricParams& p) {
    return p.ggx.effectively_smooth() || fabsf(p.eta - 1.0f) < 1e-3f;
}

// ---- Rough lobe: forward pdf and value ----

// Generalised half vector of (wo, wi), oriented to +Z; false when the pair is impossible.
LANTERN_HD inline bool dielectric_half(const DielectricParams& p, Vec3 wo, Vec3 wi, Vec3* m,
                                       float* etap) {
    if (wo.z == 0.0f || wi.z == 0.0f) return false;
    bool reflect = wo.z * wi.z > 0.0f;
    *etap = reflect ? 1.0f : (wo.z > 0.0f ? p.eta : 1.0f / p.eta);
    Vec3 h = wi * *etap + wo;
    if (length_sq(h) <= 1e-20f) return false;
    h = normalize(h);
    if (h.z < 0.0f) h = -h;
    // microfacets seen from the back of either direction contribute nothing
    if (dot(h, wi) * wi.z <= 0.0f || dot(h, wo) * wo.z <= 0.0f) return false;
    *m = h;
    return true;
}

// pdf_w of sampling wi given wo (reflection and transmission together).
LANTERN_HD inline float dielectric_pdf_rough(const DielectricParams& p, Vec3 wo, Vec3 wi) {
    Vec3 m;
    float etap;
    if (!dielectric_half(p, wo, wi, &m, &etap)) return 0.0f;
    float f = fresnel_dielectric(dot(wo, m), p.eta);
    float pdf_m = p.ggx.pdf_visible(wo, m);
    float pdf;
    if (wo.z * wi.z > 0.0f) {
        pdf = pdf_m / (4.0f * fabsf(dot(wo, m))) * f;  // reflection Jacobian 1 / (4 |wo.m|)
    } else {
        // refraction Jacobian |wi.m| / (wi.m + wo.m / eta')^2   [Walter 2007 (17)]
        float denom = sqr(dot(wi, m) + dot(wo, m) / etap);
        pdf = pdf_m * fabsf(dot(wi, m)) / denom * (1.0f - f);
    }
    return is_finite(pdf) ? pdf : 0.0f;
}

LANTERN_HD inline Vec3 dielectric_f_rough(const DielectricParams& p, Vec3 wo, Vec3 wi) {
    Vec3 m;
    float etap;
    if (!dielectric_half(p, wo, wi, &m, &etap)) return vec3(0.0f);
    float f = fresnel_dielectric(dot(wo, m), p.eta);
    float dg = p.ggx.d(m) * p.ggx.g2(wo, wi);
    float cos_io = fabsf(wo.z * wi.z);
    float v;
    if (wo.z * wi.z > 0.0f) {
        v = dg * f / (4.0f * cos_io);
    } else {
        float denom = sqr(dot(wi, m) + dot(wo, m) / etap);
        v = dg * (1.0f - f) * fabsf(dot(wi, m) * dot(wo, m)) / (cos_io * denom);  // [Walter (21)]
        if (p.mode == Transport::Importance) v /= etap * etap;
    }
    return is_finite(v) ? vec3(v) : vec3(0.0f);
}

// Zero for the delta case (its value is a distribution, reached only through sample()).
LANTERN_HD inline BsdfEval dielectric_eval(const DielectricParams& p, Vec3 wo, Vec3 wi) {
    BsdfEval e{vec3(0.0f), 0.0f, 0.0f};
    if (dielectric_is_delta(p)) return e;
    e.f = dielectric_f_rough(p, wo, wi);
    e.pdf_fwd_w = dielectric_pdf_rough(p, wo, wi);
    e.pdf_rev_w = dielectric_pdf_rough(p, wi, wo);
    return e;
}

// ---- Sampling ----

// u picks the microfacet, uc picks reflection (uc < F) or transmission. For the delta case
// pdf_fwd_w is the discrete probability of the chosen event (F or 1 - F).
LANTERN_HD inline BsdfSample dielectric_sample(const DielectricParams& p, Vec3 wo, Vec2 u,
                                               float uc) {
    BsdfSample s{vec3(0.0f), vec3(0.0f), 0.0f, false};
    if (wo.z == 0.0f || !is_finite(wo)) return s;
    float side = copysignf(1.0f, wo.z);
    if (dielectric_is_delta(p)) {
        float f = fresnel_dielectric(wo.z, p.eta);
        if (uc < f) {
            s.wi = vec3(-wo.x, -wo.y, wo.z);
            s.pdf_fwd_w = f;
            s.weight = vec3(1.0f);  // (F / |cos|) |cos| / F
        } else {
            float etap = wo.z > 0.0f ? p.eta : 1.0f / p.eta;
            if (!refract(wo, vec3(0.0f, 0.0f, side), etap, &s.wi)) return s;
            s.pdf_fwd_w = 1.0f - f;
            s.weight = vec3(p.mode == Transport::Importance ? 1.0f / (etap * etap) : 1.0f);
        }
        // Fresnel is the same seen from either side of a refraction: reverse = forward
        s.pdf_rev_w = s.pdf_fwd_w;
        s.delta = true;
        s.valid = s.pdf_fwd_w > 0.0f;
        return s;
    }
    Vec3 m = p.ggx.sample_visible(wo, u);
    float wo_m = dot(wo, m);
    if (wo_m * side <= 0.0f) return s;
    float f = fresnel_dielectric(wo_m, p.eta);
    if (uc < f) {
        s.wi = reflect(wo, m);
        if (s.wi.z * wo.z <= 0.0f) return s;
    } else {
        float etap = wo_m > 0.0f ? p.eta : 1.0f / p.eta;
        if (!refract(wo, m, etap, &s.wi)) return s;
        if (s.wi.z * wo.z >= 0.0f) return s;
    }
    s.wi = normalize(s.wi);
    // value and pdf from the same expressions eval() uses, so weight == f |cos| / pdf exactly
    s.pdf_fwd_w = dielectric_pdf_rough(p, wo, s.wi);
    if (!(s.pdf_fwd_w > 0.0f)) return s;
    s.weight = dielectric_f_rough(p, wo, s.wi) * (fabsf(s.wi.z) / s.pdf_fwd_w);
    s.pdf_rev_w = dielectric_pdf_rough(p, s.wi, wo);
    s.valid = is_finite(s.weight);
    return s;
}

}  // namespace lantern
