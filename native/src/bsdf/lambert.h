// Lambertian reflection in a local frame with +Z the shading normal on the side of wo.
// Forward and reverse pdfs are in solid angle; both are the cosine pdf of the outgoing side.
#pragma once

#include "core/sampling.h"

namespace lantern {

struct BsdfEval {
    Vec3 f;            // BSDF value (without the cosine)
    float pdf_fwd_w;   // pdf of sampling wi given wo
    float pdf_rev_w;   // pdf of sampling wo given wi
};

struct BsdfSample {
    Vec3 wi;
    Vec3 weight;       // f * |cos| / pdf
    float pdf_fwd_w;
    bool valid;
};

LANTERN_HD inline BsdfEval lambert_eval(Vec3 albedo, Vec3 wo, Vec3 wi) {
    BsdfEval e{vec3(0.0f), 0.0f, 0.0f};
    if (wo.z <= 0.0f || wi.z <= 0.0f) return e;
    e.f = albedo * kInvPi;
    e.pdf_fwd_w = pdf_cosine_hemisphere(wi.z);
    e.pdf_rev_w = pdf_cosine_hemisphere(wo.z);
    return e;
}

LANTERN_HD inline BsdfSample lambert_sample(Vec3 albedo, Vec3 wo, Vec2 u) {
    BsdfSample s{vec3(0.0f), vec3(0.0f), 0.0f, false};
    if (wo.z <= 0.0f) return s;
    s.wi = sample_cosine_hemisphere(u, &s.pdf_fwd_w);
    if (s.pdf_fwd_w <= 0.0f || s.wi.z <= 0.0f) return s;
    s.weight = albedo;  // (albedo/pi) * cos / (cos/pi)
    s.valid = true;
    return s;
}

}  // namespace lantern
