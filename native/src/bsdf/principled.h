// Blender's Principled BSDF as layers (the order of Cycles' Principled v2): a metal lobe of
// weight `metallic`, a glass lobe of weight (1 - metallic) transmission, and on the rest a
// dielectric specular layer over a Lambertian base. Composition is deterministic: the base is
// weighted by (1 - E_s(mu_v)), E_s the directional albedo of the specular layer (a table of
// kPrincipledAlbedoN cosines made when the scene is built, principled_albedo_table) and mu_v
// the cosine of the direction towards the camera side (wo for radiance, wi for importance), so
// that camera and light sub-paths evaluate the same function and every direction reflects at
// most 1 (energy conserving; reciprocal only where E_s is constant, as in Cycles).
// Sampling picks a lobe with probabilities from the albedos at the sampling direction, then the
// lobe's direction; pdfs are the full mixture (forward and reverse), so MIS sees one BSDF.
// Local frame: +Z the shading normal on the side of wo; `front` as in material.h.
// Coat Normal (kCoatNormal): the coat lobe lives in the frame of its own normal nc (local, in the
// base's frame); its value is f_c |w_l.nc| / |w_l.z| with w_l the light-side direction (wi for
// radiance, wo for importance), so that the integrators' single cosine |w_l.z| and their adjoint
// shading-normal factor [Veach thesis (5.19)] come out per lobe: f_c |w_l.nc| (docs/materials.md).
#pragma once

#include "bsdf/conductor.h"
#include "bsdf/dielectric.h"
#include "bsdf/lambert.h"
#include "bsdf/oren_nayar.h"
#include "bsdf/multiscatter.h"
#include "bsdf/principled_coat.h"
#include "bsdf/sheen.h"
#include "bsdf/thin_film.h"
#include "scene/scene_view.h"

namespace lantern {

// The diffuse base: Lambert, or the energy-preserving Oren-Nayar of Blender's Diffuse Roughness.
LANTERN_HD inline BsdfEval diffuse_base_eval(const Material& m, Vec3 wo, Vec3 wi) {
    return m.diffuse_roughness > 0.0f
               ? oren_nayar_eval(OrenNayarParams{m.base_color, m.diffuse_roughness}, wo, wi)
               : lambert_eval(m.base_color, wo, wi);
}
LANTERN_HD inline BsdfSample diffuse_base_sample(const Material& m, Vec3 wo, Vec2 u) {
    return m.diffuse_roughness > 0.0f
               ? oren_nayar_sample(OrenNayarParams{m.base_color, m.diffuse_roughness}, wo, u)
               : lambert_sample(m.base_color, wo, u);
}

// ---- The specular layer: GGX reflection with Cycles' generalized-Schlick Fresnel ----

// Fresnel of the specular layer at cos(wo, m): the real dielectric curve of eta, rescaled to
// start at F0 * tint (F0 of eta) and end at 1 (tint 1: the plain dielectric Fresnel). With a
// thin film: the film's interference reflectance over the IOR (bsdf/thin_film.h), scaled per
// channel by F0 * tint / F0(IOR) where it is near F0(IOR), by 1 where it reaches 1 (Specular IOR
// Level and Tint keep their meaning; 1 with the defaults).
LANTERN_HD inline Vec3 principled_spec_fresnel(const Material& m, float cos_h) {
    const float eta = m.spec_eta;
    const float f0 = sqr((eta - 1.0f) / (eta + 1.0f));
    if (m.film_thickness > 0.0f) {
        Vec3 f = thin_film_reflectance(cos_h, m.film_ior, m.ior, m.film_thickness);
        const float f0_ior = sqr((m.ior - 1.0f) / (m.ior + 1.0f));
        if (f0_ior > 1e-5f && f0_ior < 1.0f) {
            auto scale = [&](float fc, float tint) {
                const float s = clampf((1.0f - fc) / (1.0f - f0_ior), 0.0f, 1.0f);
                return fc * (1.0f + (fminf(f0 * tint, 1.0f) / f0_ior - 1.0f) * s);
            };
            f = Vec3{scale(f.x, m.specular_tint.x), scale(f.y, m.specular_tint.y),
                     scale(f.z, m.specular_tint.z)};
        }
        return f;
    }
    const float f = fresnel_dielectric(fabsf(cos_h), eta);
    const float s = f0 < 1.0f ? clampf((f - f0) / (1.0f - f0), 0.0f, 1.0f) : 1.0f;
    Vec3 f0c = vec3(fminf(f0 * m.specular_tint.x, 1.0f), fminf(f0 * m.specular_tint.y, 1.0f),
                    fminf(f0 * m.specular_tint.z, 1.0f));
    return f0c + (vec3(1.0f) - f0c) * s;
}

LANTERN_HD inline Ggx principled_ggx(const Material& m) {
    return ggx_from_roughness(m.roughness, m.anisotropy);
}

LANTERN_HD inline bool principled_spec_is_delta(const Material& m) {
    return principled_ggx(m).effectively_smooth();
}

// Value and pdfs of the rough specular lobe (zero for the smooth one: a delta).
LANTERN_HD inline BsdfEval principled_spec_eval(const Material& m, Vec3 wo, Vec3 wi) {
    BsdfEval e{vec3(0.0f), 0.0f, 0.0f};
    Ggx g = principled_ggx(m);
    if (g.effectively_smooth() || wo.z <= 0.0f || wi.z <= 0.0f) return e;
    Vec3 h = wo + wi;
    if (length_sq(h) <= 0.0f) return e;
    h = normalize(h);
    const float d = g.d(h);
    e.f = principled_spec_fresnel(m, dot(wo, h)) * (d * g.g2(wo, wi) / (4.0f * wo.z * wi.z));
    e.pdf_fwd_w = g.g1(wo) * d / (4.0f * wo.z);
    e.pdf_rev_w = g.g1(wi) * d / (4.0f * wi.z);
    if (!is_finite(e.f) || !is_finite(e.pdf_fwd_w) || !is_finite(e.pdf_rev_w))
        return BsdfEval{vec3(0.0f), 0.0f, 0.0f};
    return e;
}

// Directional albedo of the specular layer seen at cosine mu (max over the channels), by
// stratified visible-normal sampling (smooth: the Fresnel itself). Used to fill the table.
inline float principled_spec_albedo_exact(const Material& m, float mu, int n = 64) {
    Ggx g = principled_ggx(m);
    // an anisotropic layer's albedo depends on the view's azimuth, which a table in mu alone
    // cannot hold: Cycles layers the base under the isotropic lobe of alpha sqrt(ax ay); the
    // table read the lobe along its tangent (its widest alpha), so the base showed 13 % too
    // bright under Anisotropic 0.8 (difftest D10)
    if (m.anisotropy > 0.0f) g = Ggx::isotropic(sqrtf(g.ax * g.ay));
    if (g.effectively_smooth()) return max_component(principled_spec_fresnel(m, clampf(mu, 1e-3f, 1.0f)));
    Vec3 e = ggx_reflection_albedo(
        g, mu, [&m](float c) { return principled_spec_fresnel(m, c); }, n);
    if (m.multiscatter) {
        // with the multiple-scattering energy the lobe gets (bsdf/multiscatter.h)
        e = e * ms_scale(m, m.fms_spec, clampf(mu, 1e-3f, 1.0f));
    } else {
        // plain GGX: Cycles layers the base under the albedo of the energy-preserving lobe
        // all the same (its estimate F0 + (1 - F0) s, s from a table of the Fresnel-weighted
        // albedo over the white one: closure/bsdf_microfacet.h), not the lobe's own, which
        // lacks the energy of the missing bounces: E_F / E_white (difftest D6)
        const float white =
            ggx_reflection_albedo(g, mu, [](float) { return vec3(1.0f); }, n).x;
        if (white > 1e-4f) e = e / white;
    }
    return clampf(max_component(e), 0.0f, 1.0f);
}

// Fills t.spec_albedo (host, at scene build; m.tables is t: the exact albedo reads t.ms_e). With a thin film the layer's weight is its Fresnel
// at the view cosine (max channel), the smooth-surface estimate Cycles layers iridescence with.
inline void principled_albedo_table(const Material& m, MaterialTables& t) {
    for (int k = 0; k < kPrincipledAlbedoN; ++k) {
        const float mu = sqr(float(k) / (kPrincipledAlbedoN - 1));
        t.spec_albedo[k] = m.film_thickness > 0.0f
                               ? clampf(max_component(principled_spec_fresnel(m, fmaxf(mu, 1e-3f))),
                                        0.0f, 1.0f)
                               : principled_spec_albedo_exact(m, mu);
    }
}

// The specular layer's albedo split by its Fresnel (host, the roughness rows): with F = F0 +
// (1 - F0) s(cos) (principled_spec_fresnel without a film), E_F = F0 E + (1 - F0) S, E the white
// lobe's albedo and S that of s, both from one quadrature of principled_spec_albedo_exact's
// (64 x 64). S depends on the specular IOR alone, so a scene's materials share the rows of an
// IOR (scene.cpp caches them): a material's rows then cost no quadrature of their own.
struct SpecBasis {
    float e[kPrincipledAlbedoN], s[kPrincipledAlbedoN];
};
inline void principled_spec_basis(float roughness, float eta, SpecBasis& out, int n = 64) {
    const Ggx g = ggx_from_roughness(roughness, 0.0f);
    const float f0 = sqr((eta - 1.0f) / (eta + 1.0f));
    auto rise = [eta, f0](float c) {
        const float f = fresnel_dielectric(fabsf(c), eta);
        return f0 < 1.0f ? clampf((f - f0) / (1.0f - f0), 0.0f, 1.0f) : 1.0f;
    };
    for (int k = 0; k < kPrincipledAlbedoN; ++k) {
        const float mu = sqr(float(k) / (kPrincipledAlbedoN - 1));
        if (g.effectively_smooth()) {
            out.e[k] = 1.0f;
            out.s[k] = rise(clampf(mu, 1e-3f, 1.0f));
            continue;
        }
        const Vec3 v = ggx_reflection_albedo(
            g, mu, [&rise](float c) { return vec3(1.0f, rise(c), 0.0f); }, n);
        out.e[k] = v.x;
        out.s[k] = v.y;
    }
}

// Fills t.spec_albedo of m (no film, isotropic; m.tables = &t with t.ms_e filled) from the
// basis b of its roughness: what principled_albedo_table computes, without a quadrature.
inline void principled_albedo_from_basis(const Material& m, const SpecBasis& b,
                                         MaterialTables& t) {
    const float f0 = sqr((m.spec_eta - 1.0f) / (m.spec_eta + 1.0f));
    const Vec3 f0c = vec3(fminf(f0 * m.specular_tint.x, 1.0f), fminf(f0 * m.specular_tint.y, 1.0f),
                          fminf(f0 * m.specular_tint.z, 1.0f));
    for (int k = 0; k < kPrincipledAlbedoN; ++k) {
        const float mu = sqr(float(k) / (kPrincipledAlbedoN - 1));
        Vec3 e = f0c * b.e[k] + (vec3(1.0f) - f0c) * b.s[k];
        if (m.multiscatter)
            e = e * ms_scale(m, m.fms_spec, clampf(mu, 1e-3f, 1.0f));
        else if (b.e[k] > 1e-4f)
            e = e / b.e[k];
        t.spec_albedo[k] = clampf(max_component(e), 0.0f, 1.0f);
    }
}

LANTERN_HD inline float principled_spec_albedo(const Material& m, float mu) {
    if (!m.tables->rough_rows) return ms_table(m.tables->spec_albedo, mu);
    return clampf(ms_rough(m, m.roughness,
                           [mu](const MaterialTables& t) { return ms_table(t.spec_albedo, mu); }),
                  0.0f, 1.0f);
}

// The metal lobe: F82-tint GGX of the base colour, with the thin film over it.
LANTERN_HD inline ConductorParams principled_metal(const Material& m) {
    ConductorParams c = conductor_f82(m.roughness, m.base_color, m.specular_tint, m.anisotropy);
    c.film_thickness = m.film_thickness;
    c.film_ior = m.film_ior;
    return c;
}

// ---- The sheen: the top layer ----

LANTERN_HD inline SheenParams principled_sheen(const Material& m) {
    return {m.sheen_tint * m.sheen_weight, m.tables->sheen_ltc};
}

// The sheen's fit at the material's roughness (host, at scene build).
inline void principled_sheen_table(const Material& m, MaterialTables& t) {
    sheen_ltc_rows(m.sheen_roughness, t.sheen_ltc);
}

// What the sheen lets through to the coat and below, at camera-side cosine mu: 1 - its albedo
// (the fit's R, exact for the LTC lobe) times the weight's largest channel, as Cycles layers it.
LANTERN_HD inline float principled_below_sheen(const Material& m, float mu) {
    if (!(m.sheen_weight > 0.0f)) return 1.0f;
    float e = sheen_ltc_at(m.tables->sheen_ltc, fabsf(mu)).r * m.sheen_weight *
              max_component(m.sheen_tint);
    return clampf(1.0f - e, 0.0f, 1.0f);
}

// ---- The coat (bsdf/principled_coat.h): what it lets through ----

// What reaches the layers under the coat, seen at camera-side cosines mu (base normal: the
// sheen) and mu_c (coat normal): the coat's transmitted share and its tint along the refracted
// path (Beer, tint per unit thickness at normal incidence, as Cycles). Out of line on the device
// (LANTERN_DEVICE_NOINLINE: its three powf were copied at every eval site of a shade kernel).
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline Vec3 principled_below_coat(const Material& m, float mu, float mu_c) {
    const float cw = m.coat_weight;
    const float sheen_pass = principled_below_sheen(m, mu);
    if (!(cw > 0.0f)) return vec3(sheen_pass);
    const float e = principled_coat_albedo(m, mu_c);
    Vec3 t = vec3(1.0f);
    if (!(m.coat_tint.x == 1.0f && m.coat_tint.y == 1.0f && m.coat_tint.z == 1.0f)) {
        const float mu = clampf(mu_c, 0.0f, 1.0f);
        float sin2 = (1.0f - mu * mu) / (m.coat_ior * m.coat_ior);
        float cos_t = safe_sqrt(1.0f - sin2);
        float depth = 1.0f / fmaxf(cos_t, 1e-3f);
        Vec3 tt = vec3(powf(m.coat_tint.x, depth), powf(m.coat_tint.y, depth),
                       powf(m.coat_tint.z, depth));
        t = vec3(1.0f) * (1.0f - cw) + tt * cw;
    }
    return t * ((1.0f - cw * e) * sheen_pass);
}

// What of a Principled surface's Emission the camera sees at cosine mu with its normal: Cycles
// puts the emission under the sheen and the coat (svm/closure.h: the emission's weight is the
// one the layers above leave), so the coat's reflectance at mu, its tint along the refracted
// path and the sheen's albedo dim it (difftest D12). Only where the full shader runs, though:
// evaluated as a light (next-event estimation, PATH_RAY_EMISSION) it allocates no closures, so
// no layer dims it, and Cycles' lighting by such an emitter is a blend of both by its MIS
// weights. Lantern dims the camera's direct view (camera rays and light tracing's splat of
// the emitter, the two techniques that render it) and leaves the light it casts undimmed, the
// same in every integrator (docs/materials.md). 1 for every other material; a mix's emission
// is its leaves' sum and stays undimmed.
LANTERN_HD inline Vec3 principled_emission_through(const Material& m, float mu) {
    if (m.type != kMaterialPrincipled || !(m.coat_weight > 0.0f || m.sheen_weight > 0.0f))
        return vec3(1.0f);
    const float c = clampf(fabsf(mu), 0.0f, 1.0f);
    return principled_below_coat(m, c, c);
}

// ---- The layers together ----

struct PrincipledWeights {
    float metal, glass, spec;  // lobe weights; the base is spec * (1 - E_s(mu_v))
};

LANTERN_HD inline PrincipledWeights principled_weights(const Material& m) {
    float metal = clampf(m.metallic, 0.0f, 1.0f);
    float glass = (1.0f - metal) * clampf(m.transmission, 0.0f, 1.0f);
    return {metal, glass, 1.0f - metal - glass};
}

// Lobe selection at direction w (cosine mu): probabilities of metal, glass, specular, base.
struct PrincipledPick {
    float metal, glass, spec, base, coat, sheen;
};

LANTERN_HD inline PrincipledPick principled_pick(const Material& m, float mu, float mu_c) {
    PrincipledWeights w = principled_weights(m);
    float es = principled_spec_albedo(m, mu);
    const float sheen_pass = principled_below_sheen(m, mu);
    const float esh = 1.0f - sheen_pass;
    float ec = m.coat_weight > 0.0f
                   ? sheen_pass * m.coat_weight * principled_coat_albedo(m, mu_c)
                   : 0.0f;
    float below = sheen_pass - ec;
    PrincipledPick p{below * w.metal * (0.5f + 0.5f * luminance(m.base_color)),
                     below * w.glass, below * w.spec * es,
                     below * w.spec * (1.0f - es) * (1.0f - m.subsurface) * luminance(m.base_color),
                     ec, esh};  // the base less what scatters under the surface (pt_sss.h)
    float sum = p.metal + p.glass + p.spec + p.base + p.coat + p.sheen;
    if (!(sum > 0.0f)) return {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
    return {p.metal / sum, p.glass / sum, p.spec / sum, p.base / sum, p.coat / sum,
            p.sheen / sum};
}

LANTERN_HD inline Vec3 principled_transmission_tint(const Material& m) {
    return vec3(sqrtf(m.base_color.x), sqrtf(m.base_color.y), sqrtf(m.base_color.z));
}

// nc: the coat's normal in this frame (read only with kCoatNormal).
LANTERN_HD inline BsdfEval principled_eval(const Material& m, bool front, Vec3 wo, Vec3 wi,
                                           Transport mode, Vec3 nc) {
    BsdfEval e{vec3(0.0f), 0.0f, 0.0f};
    if (wo.z <= 0.0f || wi.z == 0.0f) return e;
    const PrincipledWeights w = principled_weights(m);
    const float co = coat_cos(m, nc, wo), ci = coat_cos(m, nc, wi);
    const PrincipledPick pf = principled_pick(m, wo.z, co), pr = principled_pick(m, wi.z, ci);
    const bool reflect = wi.z > 0.0f;
    const bool radiance = mode == Transport::Radiance;
    const float mu_v = radiance ? wo.z : wi.z;  // the camera side
    const float mu_vc = radiance ? co : ci;      // ... and its cosine with the coat normal
    if (m.sheen_weight > 0.0f && reflect) {
        BsdfEval l = sheen_eval(principled_sheen(m), wo, wi, mode);
        e.f += l.f;
        e.pdf_fwd_w += pf.sheen * l.pdf_fwd_w;
        e.pdf_rev_w += pr.sheen * l.pdf_rev_w;
    }
    if (m.coat_weight > 0.0f && reflect) {
        BsdfEval l = principled_coat_eval_tilted(m, nc, wo, wi, mode);
        e.f += l.f * (m.coat_weight * principled_below_sheen(m, mu_v));
        e.pdf_fwd_w += pf.coat * l.pdf_fwd_w;
        e.pdf_rev_w += pr.coat * l.pdf_rev_w;
    }
    const Vec3 below = principled_below_coat(m, mu_v, mu_vc);
    Vec3 f_lower = vec3(0.0f);
    if (w.metal > 0.0f && reflect) {
        BsdfEval l = conductor_eval(principled_metal(m),
                                    wo, wi);
        f_lower += l.f * ms_scale(m, m.fms_metal, mu_v) * w.metal;
        e.pdf_fwd_w += pf.metal * l.pdf_fwd_w;
        e.pdf_rev_w += pr.metal * l.pdf_rev_w;
    }
    if (w.glass > 0.0f) {
        DielectricParams d = dielectric(m.roughness, front ? m.ior : 1.0f / m.ior, mode,
                                        m.anisotropy);
        BsdfEval l = dielectric_eval(d, wo, wi);
        if (!reflect) l.f = l.f * principled_transmission_tint(m);
        f_lower += l.f * w.glass;
        e.pdf_fwd_w += pf.glass * l.pdf_fwd_w;
        e.pdf_rev_w += pr.glass * l.pdf_rev_w;
    }
    if (w.spec > 0.0f && reflect) {
        BsdfEval l = principled_spec_eval(m, wo, wi);
        f_lower += l.f * ms_scale(m, m.fms_spec, mu_v) * w.spec;
        e.pdf_fwd_w += pf.spec * l.pdf_fwd_w;
        e.pdf_rev_w += pr.spec * l.pdf_rev_w;
        // the base under the specular layer, attenuated on the camera side
        const float base_w =  // less what scatters under the surface (integrator/pt_sss.h)
            w.spec * (1.0f - principled_spec_albedo(m, mu_v)) * (1.0f - m.subsurface);
        BsdfEval b = diffuse_base_eval(m, wo, wi);
        f_lower += b.f * base_w;
        e.pdf_fwd_w += pf.base * b.pdf_fwd_w;
        e.pdf_rev_w += pr.base * b.pdf_rev_w;
    }
    e.f += f_lower * below;
    if (!is_finite(e.f) || !is_finite(e.pdf_fwd_w) || !is_finite(e.pdf_rev_w))
        return BsdfEval{vec3(0.0f), 0.0f, 0.0f};
    return e;
}

// u.x, u.y: the lobe's direction; u.z: the lobe (and, for glass, reflection or transmission).
LANTERN_HD inline BsdfSample principled_sample(const Material& m, bool front, Vec3 wo, Vec3 u,
                                               Transport mode, Vec3 nc) {
    BsdfSample s{vec3(0.0f), vec3(0.0f), 0.0f, false};
    if (wo.z <= 0.0f) return s;
    const PrincipledWeights w = principled_weights(m);
    const bool radiance = mode == Transport::Radiance;
    const PrincipledPick p = principled_pick(m, wo.z, coat_cos(m, nc, wo));
    float uc = u.z;
    const Vec2 ud{u.x, u.y};
    // choose the lobe; uc is rescaled into [0, 1) for the lobe's own use
    int lobe;
    float p_lobe;
    if (uc >= 1.0f - p.sheen) {
        lobe = 5;
        p_lobe = p.sheen;
    } else if (uc >= 1.0f - p.sheen - p.coat) {
        lobe = 4;
        p_lobe = p.coat;
    } else if (uc < p.metal) {
        lobe = 0;
        p_lobe = p.metal;
        uc = uc / p.metal;
    } else if (uc < p.metal + p.glass) {
        lobe = 1;
        p_lobe = p.glass;
        uc = (uc - p.metal) / p.glass;
    } else if (uc < p.metal + p.glass + p.spec) {
        lobe = 2;
        p_lobe = p.spec;
        uc = (uc - p.metal - p.glass) / p.spec;
    } else {
        lobe = 3;
        p_lobe = p.base;
    }
    if (!(p_lobe > 0.0f)) return s;
    uc = fminf(uc, 0.99999994f);
    BsdfSample l{vec3(0.0f), vec3(0.0f), 0.0f, false};
    Vec3 delta_f = vec3(0.0f);  // lobe weight x the lobe's own sample weight, for a delta pick
    if (lobe == 0) {
        ConductorParams c = principled_metal(m);
        l = conductor_sample(c, wo, ud);
        delta_f = l.weight * w.metal;
    } else if (lobe == 1) {
        DielectricParams d = dielectric(m.roughness, front ? m.ior : 1.0f / m.ior, mode,
                                        m.anisotropy);
        l = dielectric_sample(d, wo, ud, uc);
        delta_f = l.weight * w.glass;
        if (l.valid && l.wi.z < 0.0f) delta_f = delta_f * principled_transmission_tint(m);
    } else if (lobe == 2) {
        Ggx g = principled_ggx(m);
        if (g.effectively_smooth()) {
            l.wi = vec3(-wo.x, -wo.y, wo.z);
            l.pdf_fwd_w = l.pdf_rev_w = 1.0f;
            l.delta = true;
            l.valid = true;
            delta_f = principled_spec_fresnel(m, wo.z) * w.spec;
        } else {
            Vec3 h = g.sample_visible(wo, ud);
            l.wi = reflect(wo, h);
            l.valid = l.wi.z > 0.0f;
        }
    } else if (lobe == 4) {  // in the coat's frame (its own normal, or the base's)
        const bool tilted = (m.tex_flags & kCoatNormal) != 0;
        const Frame cf = Frame::from_normal(tilted ? nc : vec3(0.0f, 0.0f, 1.0f));
        const Vec3 wo_c = tilted ? cf.to_local(wo) : wo;
        if (!(wo_c.z > 0.0f)) return s;
        Ggx g = principled_coat_ggx(m);
        Vec3 wi_c;
        if (g.effectively_smooth()) {
            wi_c = vec3(-wo_c.x, -wo_c.y, wo_c.z);
            l.wi = tilted ? cf.to_world(wi_c) : wi_c;
            l.pdf_fwd_w = l.pdf_rev_w = 1.0f;
            l.delta = true;
            l.valid = l.wi.z > 0.0f;
            // f_c |w_l.nc| / pdf, seen with the integrators' cosine |wi.z| (header); for the
            // mirror |wo.nc| = |wi.nc|, so importance transport gains |wi.z| / |wo.z|
            const float adj = tilted && !radiance ? fabsf(l.wi.z) / wo.z : 1.0f;
            delta_f = vec3(fresnel_dielectric(wo_c.z, m.coat_ior) * m.coat_weight *
                           principled_below_sheen(m, radiance ? wo.z : fabsf(l.wi.z)) * adj);
        } else {
            Vec3 h = g.sample_visible(wo_c, ud);
            wi_c = reflect(wo_c, h);
            l.wi = tilted ? cf.to_world(wi_c) : wi_c;
            l.valid = wi_c.z > 0.0f && l.wi.z > 0.0f;
        }
    } else if (lobe == 5) {
        Vec3 wi;
        l.valid = sheen_sample_dir(principled_sheen(m), wo, ud, &wi);
        l.wi = wi;
    } else {
        l = diffuse_base_sample(m, wo, ud);
    }
    if (!l.valid) return s;
    // a delta pick from a layer under the coat is seen through it
    if (l.delta && lobe != 4) {
        const Vec3 wv = radiance ? wo : l.wi;  // the camera side
        delta_f = delta_f * principled_below_coat(m, fabsf(wv.z), coat_cos(m, nc, wv));
    }
    if (l.delta) {
        // a delta lobe: its discrete probability times the pick probability
        s.wi = l.wi;
        s.delta = true;
        // (reverse: the same lobe picked from wi's side; BDPT uses the ratio of the two)
        const PrincipledPick pr = principled_pick(m, fabsf(l.wi.z), coat_cos(m, nc, l.wi));
        const float p_rev = lobe == 0   ? pr.metal
                            : lobe == 1 ? pr.glass
                            : lobe == 4 ? pr.coat
                                        : pr.spec;
        s.pdf_fwd_w = l.pdf_fwd_w * p_lobe;
        s.pdf_rev_w = l.pdf_rev_w * p_rev;
        s.weight = delta_f / p_lobe;
        s.valid = is_finite(s.weight);
        return s;
    }
    // a direction from a non-delta lobe: the whole mixture's value and pdfs
    return mixture_sample(l.wi, principled_eval(m, front, wo, l.wi, mode, nc));
}

}  // namespace lantern
