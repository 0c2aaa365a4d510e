// The Principled coat (bsdf/principled.h layers it): a dielectric GGX reflection of its own
// roughness and IOR, its directional albedo table, and its own shading normal (Coat Normal):
// with kCoatNormal the lobe is evaluated in the frame of nc and returned as f_c |w_l.nc| /
// |w_l.z| (w_l the light-side direction), so the integrators' single cosine and adjoint factor
// come out per lobe (docs/materials.md, "Coat Normal").
#pragma once

#include "bsdf/fresnel.h"
#include "bsdf/microfacet.h"
#include "bsdf/multiscatter.h"
#include "scene/scene_view.h"

namespace lantern {

LANTERN_HD inline Ggx principled_coat_ggx(const Material& m) {
    return Ggx::isotropic(ggx_alpha_from_roughness(m.coat_roughness));
}

LANTERN_HD inline BsdfEval principled_coat_eval(const Material& m, Vec3 wo, Vec3 wi) {
    BsdfEval e{vec3(0.0f), 0.0f, 0.0f};
    Ggx g = principled_coat_ggx(m);
    if (g.effectively_smooth() || wo.z <= 0.0f || wi.z <= 0.0f) return e;
    Vec3 h = wo + wi;
    if (length_sq(h) <= 0.0f) return e;
    h = normalize(h);
    const float d = g.d(h);
    e.f = vec3(fresnel_dielectric(dot(wo, h), m.coat_ior) * d * g.g2(wo, wi) /
               (4.0f * wo.z * wi.z));
    e.pdf_fwd_w = g.g1(wo) * d / (4.0f * wo.z);
    e.pdf_rev_w = g.g1(wi) * d / (4.0f * wi.z);
    if (!is_finite(e.f) || !is_finite(e.pdf_fwd_w) || !is_finite(e.pdf_rev_w))
        return BsdfEval{vec3(0.0f), 0.0f, 0.0f};
    return e;
}

inline float principled_coat_albedo_exact(const Material& m, float mu, int n = 48) {
    Ggx g = principled_coat_ggx(m);
    if (g.effectively_smooth()) return fresnel_dielectric(clampf(mu, 1e-3f, 1.0f), m.coat_ior);
    Vec3 e = ggx_reflection_albedo(
        g, mu, [&m](float c) { return vec3(fresnel_dielectric(c, m.coat_ior)); }, n);
    return clampf(e.x, 0.0f, 1.0f);
}

inline void principled_coat_table(const Material& m, MaterialTables& t) {
    for (int k = 0; k < kPrincipledAlbedoN; ++k)
        t.coat_albedo[k] = principled_coat_albedo_exact(m, sqr(float(k) / (kPrincipledAlbedoN - 1)));
}

// Cosine of local direction w with the coat's normal nc (the base's +Z without kCoatNormal),
// turned to w's side of the surface (a transmitted direction sees the coat from below).
LANTERN_HD inline float coat_cos(const Material& m, Vec3 nc, Vec3 w) {
    const float c = (m.tex_flags & kCoatNormal) ? dot(nc, w) : w.z;
    return w.z < 0.0f ? -c : c;
}

// The coat's directional albedo at coat cosine mu_c (none from below its surface).
LANTERN_HD inline float principled_coat_albedo(const Material& m, float mu_c) {
    return mu_c > 0.0f ? ms_table(m.tables->coat_albedo, mu_c) : 0.0f;
}

// The coat lobe at (wo, wi) in the base's frame, seen in the frame of its normal nc: f_c
// |w_l.nc| / |w_l.z| (header), pdfs in solid angle (frame-free).
LANTERN_HD inline BsdfEval principled_coat_eval_tilted(const Material& m, Vec3 nc, Vec3 wo,
                                                       Vec3 wi, Transport mode) {
    if (!(m.tex_flags & kCoatNormal)) return principled_coat_eval(m, wo, wi);
    const Frame cf = Frame::from_normal(nc);
    BsdfEval l = principled_coat_eval(m, cf.to_local(wo), cf.to_local(wi));
    const Vec3 wl = mode == Transport::Radiance ? wi : wo;
    l.f = l.f * (fabsf(dot(wl, nc)) / fabsf(wl.z));
    if (!is_finite(l.f)) return BsdfEval{vec3(0.0f), 0.0f, 0.0f};
    return l;
}

}  // namespace lantern
