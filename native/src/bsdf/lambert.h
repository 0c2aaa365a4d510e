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

}  // namespace lantern
