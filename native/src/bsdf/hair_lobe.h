// The Principled Hair BSDF (bsdf/hair.h) as a material lobe (kMaterialHair) in the shading frame
// a strand hit builds (integrator/pt_curve.h): local X the strand's tangent, Z the
// cross-section normal at the hit, so the offset h where the view ray crossed the fiber follows
// from wo alone (hair_frame's h seen in this frame: -wo.y over wo's length across the fiber).
// Converts hair_eval's integrand f_cos to BsdfEval's f, which the integrators multiply by
// |wi.z|. Material fields (scene/hair_build.cpp): base_color the absorption, roughness,
// coat_roughness the radial roughness, coat_weight the coat, aniso_rotation the offset, ior.
// On a mesh (Cycles shades hair closures on curves only) the frame's X is any tangent.
#pragma once

#include "bsdf/cosine_lobe.h"
#include "bsdf/hair.h"
#include "scene/scene_view.h"

namespace lantern {

LANTERN_HD inline HairParams hair_lobe_params(const Material& m, Vec3 wo) {
    const float across = sqrtf(wo.y * wo.y + wo.z * wo.z);
    const float h = across > 1e-7f ? -wo.y / across : 0.0f;
    return hair_params(m.base_color, m.roughness, m.coat_roughness, m.coat_weight,
                       m.aniso_rotation, m.ior, h);
}

// f = f_cos / |wi.z| (0 where wi lies in the tangent plane: a set of measure zero)
LANTERN_HD inline BsdfEval hair_lobe_eval(const Material& m, Vec3 wo, Vec3 wi) {
    BsdfEval e{vec3(0.0f), 0.0f, 0.0f};
    const float c = fabsf(wi.z);
    if (!(c > 1e-7f)) return e;
    const HairEval h = hair_eval(hair_lobe_params(m, wo), wo, wi);
    e.f = h.f_cos / c;
    e.pdf_fwd_w = h.pdf_fwd_w;
    e.pdf_rev_w = 0.0f;  // pt only (allocation.cpp hands curve scenes to pt)
    return e;
}

LANTERN_HD inline BsdfSample hair_lobe_sample(const Material& m, Vec3 wo, Vec3 u) {
    BsdfSample s{vec3(0.0f), vec3(0.0f), 0.0f, false};
    const HairSample h = hair_sample(hair_lobe_params(m, wo), wo, Vec2{u.x, u.y}, u.z);
    if (!h.valid || !(fabsf(h.wi.z) > 1e-7f)) return s;
    s.wi = h.wi;
    s.weight = h.weight;  // f_cos / pdf = f |wi.z| / pdf
    s.pdf_fwd_w = h.pdf_fwd_w;
    s.valid = true;
    return s;
}

}  // namespace lantern
