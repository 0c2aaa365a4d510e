// What every lobe returns (BsdfEval, BsdfSample), and the eval/sample pair shared by reflection
// lobes that are sampled by the cosine hemisphere (Lambert, Oren-Nayar): local frame,
// +Z the shading normal on the side of wo; both pdfs in solid angle.
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
    float pdf_fwd_w;   // pdf of wi given wo; for a delta lobe the discrete event probability
    bool valid;
    float pdf_rev_w = 0.0f;  // pdf of sampling wo given wi (same conventions)
    bool delta = false;      // wi came from a delta lobe: eval() cannot reproduce it
    // which lobe drew wi, for the integrators' ray kinds (Cycles' closure label): a Mix's leaf
    // as 1 + its index (mix_sample), 0 where the material's one kind holds. Read only where a
    // scene has ray visibility by kind; in the padding after `delta` (the size stays 40 B)
    uint8_t lobe = 0;
};
static_assert(sizeof(BsdfSample) == 40, "BsdfSample: the kernels' frames hold it");

// A direction wi drawn from one lobe of a mixture, carrying the whole mixture's value and pdfs
// e (eval at wi): what every mixture (principled layers, Mix Shader) returns for a non-delta
// pick, so that sample() and eval() agree exactly.
LANTERN_HD inline BsdfSample mixture_sample(Vec3 wi, const BsdfEval& e) {
    BsdfSample s{vec3(0.0f), vec3(0.0f), 0.0f, false};
    if (!(e.pdf_fwd_w > 0.0f)) return s;
    s.wi = wi;
    s.pdf_fwd_w = e.pdf_fwd_w;
    s.pdf_rev_w = e.pdf_rev_w;
    s.weight = e.f * (fabsf(wi.z) / e.pdf_fwd_w);
    s.valid = is_finite(s.weight);
    return s;
}

// f(wo, wi) -> Vec3 is the lobe's value for two directions in the upper hemisphere.
template <typename F>
LANTERN_HD inline BsdfEval cosine_lobe_eval(F f, Vec3 wo, Vec3 wi) {
    BsdfEval e{vec3(0.0f), 0.0f, 0.0f};
    if (wo.z <= 0.0f || wi.z <= 0.0f) return e;
    e.f = f(wo, wi);
    e.pdf_fwd_w = pdf_cosine_hemisphere(wi.z);
    e.pdf_rev_w = pdf_cosine_hemisphere(wo.z);
    return e;
}

template <typename F>
LANTERN_HD inline BsdfSample cosine_lobe_sample(F f, Vec3 wo, Vec2 u) {
    BsdfSample s{vec3(0.0f), vec3(0.0f), 0.0f, false};
    if (wo.z <= 0.0f) return s;
    s.wi = sample_cosine_hemisphere(u, &s.pdf_fwd_w);
    if (s.pdf_fwd_w <= 0.0f || s.wi.z <= 0.0f) return s;
    s.weight = f(wo, s.wi) * kPi;  // f cos / (cos / pi)
    s.pdf_rev_w = pdf_cosine_hemisphere(wo.z);
    s.valid = true;
    return s;
}

}  // namespace lantern
