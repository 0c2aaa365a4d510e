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
#include "bsdf/dielectric.h"  // Transport
#include "bsdf/hair.h"
#include "scene/scene_view.h"

namespace lantern {

LANTERN_HD inline HairParams hair_lobe_params(const Material& m, Vec3 wo) {
    const float across = sqrtf(wo.y * wo.y + wo.z * wo.z);
    const float h = across > 1e-7f ? -wo.y / across : 0.0f;
    return hair_params(m.base_color, m.roughness, m.coat_roughness, m.coat_weight,
                       m.aniso_rotation, m.ior, h);
}

// cos theta of w, the cosine to the fiber's normal plane (X is the tangent): a strand vertex's
// geometric cosine in the bidirectional integrators' fiber measure (integrator/bdpt_curve.h).
LANTERN_HD inline float hair_cos_theta(Vec3 w) { return sqrtf(fmaxf(w.y * w.y + w.z * w.z, 0.0f)); }

// The same material at the offset -h: what the reverse of a path through the fiber sees (a ray
// entering at offset h leaves, seen along its way out, at -h: Chiang's azimuthal shifts are odd
// in h, so the reversed path's lobes lie where the forward one's do).
LANTERN_HD inline HairParams hair_reversed(HairParams p) {
    p.h = -p.h;
    return p;
}

// The other sub-path's parameters at a vertex whose wo gave P: in the fiber measure the same
// fiber at -h (hair_reversed); at a tube vertex (kHairTube: the lobe as a mix's leaf, on pt's
// point on the tube, integrator/bdpt_curve.h) the offset at which w itself meets that point.
LANTERN_HD inline HairParams hair_other_side(const Material& m, const HairParams& p, Vec3 w) {
    return (m.tex_flags & kHairTube) ? hair_lobe_params(m, w) : hair_reversed(p);
}

// The geometric cosine that the Importance form divides by: cos theta (the fiber measure) or
// |w.z| (the tube's surface measure: Z is the point's outward normal).
LANTERN_HD inline float hair_vertex_cos(const Material& m, Vec3 w) {
    return (m.tex_flags & kHairTube) ? fabsf(w.z) : hair_cos_theta(w);
}

// (pdf_rev_w in Radiance only with kHairReverse: pt, which never reads it, does not pay for it.)
// h is read from wo, the direction that found the vertex (the camera's side in Radiance, the
// light's in Importance), and the other sub-path reads the vertex at -h (hair_reversed). With
// P = the parameters at h: pdf_fwd_w is hair_sample(P, wo)'s density of wi and pdf_rev_w the
// same routine's density of wo from wi with the directions swapped, at -h: a light sub-path
// samples from its own wo at its own offset, which is -h of the camera's and the reverse.
// Radiance (wo camera side): f = f_cos_h(wo, wi) / |wi.z|, the integrators multiply by |wi.z|.
// Importance (wo light side, wi camera side): f = f_cos_{-h}(wi, wo) / cos_theta(wo), the fiber
// measure's BSDF (docs/curves.md "Bidirectional"): the integrators multiply by cos_theta(wi) at
// a strand vertex. 0 where wi lies in the tangent plane (a set of measure zero).
// kHairTube (a mix's leaf; docs/curves.md "Principled Hair in a mix"): the vertex is a point on
// the tube with normal Z, and the offset is a function of the point and the direction that meets
// it, h(w) = -w.y / |w_yz|: Radiance as above (pt's f), pdf_rev_w the density of wo from wi at
// h(wi); Importance f = f_cos_{h(wi)}(wi, wo) / |wo.z| (pt's f with the sides swapped), pdf_fwd_w
// the density of wi from wo at h(wo), pdf_rev_w that of wo from wi at h(wi).
LANTERN_HD inline BsdfEval hair_lobe_eval(const Material& m, Vec3 wo, Vec3 wi,
                                          Transport mode = Transport::Radiance) {
    BsdfEval e{vec3(0.0f), 0.0f, 0.0f};
    const float c = fabsf(wi.z);
    if (!(c > 1e-7f)) return e;
    const HairParams p = hair_lobe_params(m, wo);
    if (mode == Transport::Radiance) {
        const HairEval fwd = hair_eval(p, wo, wi);
        e.f = fwd.f_cos / c;
        e.pdf_fwd_w = fwd.pdf_fwd_w;
        // (pt reads no reverse pdf: only where a light-path integrator may render, kHairReverse)
        if (m.tex_flags & kHairReverse)
            e.pdf_rev_w = hair_eval(hair_other_side(m, p, wi), wi, wo).pdf_fwd_w;
    } else {
        const HairEval rev = hair_eval(hair_other_side(m, p, wi), wi, wo);
        e.pdf_fwd_w = hair_eval(p, wo, wi).pdf_fwd_w;
        e.pdf_rev_w = rev.pdf_fwd_w;
        const float co = hair_vertex_cos(m, wo);
        e.f = co > 1e-7f ? rev.f_cos / co : vec3(0.0f);
    }
    return e;
}

// weight: f_cos / pdf (Radiance); f_cos_{-h}(wi, wo) cos_theta(wi) / (cos_theta(wo) pdf)
// (Importance, the fiber measure's adjoint throughput: integrator/bdpt_curve.h); kHairTube:
// f_cos_{h(wi)}(wi, wo) |wi.z| / (|wo.z| pdf).
LANTERN_HD inline BsdfSample hair_lobe_sample(const Material& m, Vec3 wo, Vec3 u,
                                              Transport mode = Transport::Radiance) {
    BsdfSample s{vec3(0.0f), vec3(0.0f), 0.0f, false};
    const HairParams p = hair_lobe_params(m, wo);
    const HairSample h = hair_sample(p, wo, Vec2{u.x, u.y}, u.z);
    if (!h.valid || !(fabsf(h.wi.z) > 1e-7f)) return s;
    s.wi = h.wi;
    s.weight = h.weight;  // f_cos / pdf = f |wi.z| / pdf
    s.pdf_fwd_w = h.pdf_fwd_w;
    if (mode == Transport::Radiance && !(m.tex_flags & kHairReverse)) {  // pt: no reverse pdf
        s.valid = is_finite(s.weight);
        return s;
    }
    const HairEval rev = hair_eval(hair_other_side(m, p, h.wi), h.wi, wo);
    s.pdf_rev_w = rev.pdf_fwd_w;
    if (mode == Transport::Importance) {
        const float co = hair_vertex_cos(m, wo);
        s.weight = co > 1e-7f ? rev.f_cos * (hair_vertex_cos(m, h.wi) / (co * h.pdf_fwd_w))
                              : vec3(0.0f);
    }
    s.valid = is_finite(s.weight);
    return s;
}

}  // namespace lantern
