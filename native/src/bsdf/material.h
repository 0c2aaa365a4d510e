// A material's BSDF as the integrators see it: one eval/sample pair that dispatches on the
// material type to the lobes of this folder. Local frame: +Z is the shading normal turned to the
// side wo arrives from; `front` says whether that side is the surface's front (outside), which
// fixes the relative index of refraction. Reflection lobes are two-sided (as in Cycles).
// Light paths pass Transport::Importance: refraction then divides by eta'^2 (bsdf/dielectric.h).
// coat_n: the coat's own normal in this frame (SurfaceHit::coat_n), read only by principled
// materials with kCoatNormal, and by a bumped Lambert as its unbent normal.
#pragma once

#include "bsdf/hair_lobe.h"
#include "bsdf/material_resolve.h"
#include "bsdf/shading_normal.h"

namespace lantern {

// True when every lobe of m is a delta distribution: a vertex there cannot be connected to.
LANTERN_HD inline bool material_is_delta_leaf(const Material& m) {
    switch (m.type) {
    case kMaterialConductor:
        return conductor_is_delta(material_conductor(m));
    case kMaterialDielectric:
        return dielectric_is_delta(material_dielectric(m, true, Transport::Radiance));
    case kMaterialPrincipled: {  // all delta only without a base and with smooth lobes
        PrincipledWeights w = principled_weights(m);
        return w.spec <= 0.0f && principled_spec_is_delta(m);
    }
    default:
        return false;
    }
}

LANTERN_HD inline bool material_transmits_leaf(const Material& m) {
    return m.type == kMaterialDielectric || m.type == kMaterialTranslucent ||
           m.type == kMaterialHair || (m.type == kMaterialPrincipled && m.transmission > 0.0f);
}

// Translucent BSDF: Lambertian transmission (to the other side), albedo base_color.
// Cycles' Translucent (bsdf_translucent.h) reads the light's side of N alone: its eval takes
// any view, and so does its sampler (which then drops a direction on the view's side of Ng,
// as pt's side test does here). Where a smooth low-poly mesh's normal leans far from the facet
// (the inner walls of a capped cylinder seen from inside, D43) the view can fall below N; a
// view-sided Lambert went black there. Camera sub-paths (radiance: wi is the light) take
// Cycles' convention; light sub-paths keep the symmetric one (no view below N), so bdpt and lt
// read a slightly different BSDF only where the view lies below N.
LANTERN_HD inline BsdfEval translucent_eval(Vec3 color, Vec3 wo, Vec3 wi, bool radiance) {
    if (radiance && wo.z <= 0.0f && wi.z < 0.0f) {
        BsdfEval e{color * kInvPi, pdf_cosine_hemisphere(-wi.z), pdf_cosine_hemisphere(-wo.z)};
        return e;
    }
    return lambert_eval(color, wo, Vec3{wi.x, wi.y, -wi.z});
}

LANTERN_HD inline BsdfSample translucent_sample(Vec3 color, Vec3 wo, Vec2 u, bool radiance) {
    // the view below N (radiance): sampled as from above, the same cosine about -N
    const Vec3 wv = radiance && wo.z <= 0.0f ? Vec3{wo.x, wo.y, fmaxf(-wo.z, 1e-7f)} : wo;
    BsdfSample s = lambert_sample(color, wv, u);
    s.wi.z = -s.wi.z;
    return s;
}

// The leaves' eval and sample are out of line on the device (LANTERN_DEVICE_NOINLINE): each is
// called at up to three sites (corrected_*, mix_*, material_*) and was copied at each.
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline BsdfEval material_eval_leaf(const Material& m, bool front, Vec3 wo, Vec3 wi,
                                              Transport mode, Vec3 coat_n) {
    switch (m.type) {
    case kMaterialConductor: {
        BsdfEval e = conductor_eval(material_conductor(m), wo, wi);
        e.f = e.f * material_conductor_scale(m) *
              ms_scale(m, m.fms_metal, mode == Transport::Radiance ? wo.z : wi.z);
        return e;
    }
    case kMaterialDielectric: {
        // base_color tints transmission; with kTintReflection (Blender's Glass BSDF Color: Cycles'
        // reflection_tint and transmission_tint are both Color) reflection as well
        BsdfEval e = dielectric_eval(material_dielectric(m, front, mode), wo, wi);
        if (wo.z * wi.z < 0.0f || (m.tex_flags & kTintReflection)) e.f = e.f * m.base_color;
        return e;
    }
    case kMaterialPrincipled:
        return principled_eval(m, front, wo, wi, mode, coat_n);
    case kMaterialTranslucent:
        return translucent_eval(m.base_color, wo, wi, mode == Transport::Radiance);
    case kMaterialHair:
        return hair_lobe_eval(m, wo, wi, mode);
    default:
        return diffuse_base_eval(m, wo, wi);
    }
}

// u.x, u.y choose the direction, u.z the lobe event (dielectric reflection or transmission).
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline BsdfSample material_sample_leaf(const Material& m, bool front, Vec3 wo, Vec3 u,
                                                  Transport mode, Vec3 coat_n) {
    switch (m.type) {
    case kMaterialConductor: {
        BsdfSample s = conductor_sample(material_conductor(m), wo, Vec2{u.x, u.y});
        s.weight = s.weight * material_conductor_scale(m);
        if (s.valid && !s.delta)
            s.weight = s.weight * ms_scale(m, m.fms_metal,
                                           mode == Transport::Radiance ? wo.z : s.wi.z);
        return s;
    }
    case kMaterialDielectric: {
        BsdfSample s = dielectric_sample(material_dielectric(m, front, mode), wo, Vec2{u.x, u.y}, u.z);
        if (s.valid && (wo.z * s.wi.z < 0.0f || (m.tex_flags & kTintReflection)))
            s.weight = s.weight * m.base_color;
        return s;
    }
    case kMaterialPrincipled:
        return principled_sample(m, front, wo, u, mode, coat_n);
    case kMaterialTranslucent:
        return translucent_sample(m.base_color, wo, Vec2{u.x, u.y}, mode == Transport::Radiance);
    case kMaterialHair:
        return hair_lobe_sample(m, wo, u, mode);
    default:
        return diffuse_base_sample(m, wo, Vec2{u.x, u.y});
    }
}

// ---- Mix / Add Shader: sum_i w_i f_i, a leaf picked with probability w_i / sum w (fixed, so
// the forward and reverse pdfs are the same mixture: deterministic, as BDPT's MIS needs) ----

LANTERN_HD inline float mix_total(const Material& m) {
    float sum = 0.0f;
    for (int i = 0; i < m.mix_count; ++i) sum += fmaxf(m.mix_weight[i], 0.0f);
    return sum;
}

// tmp: room for a resolved leaf (mix_leaf_at), one at a time. lit: the leaves whose value
// counts (bit i: leaf i; Cycles' next event leaves out the closures whose class cannot see the
// light, integrator/pt_ray_visibility.h pt_nee_leaves), every leaf's pdf counting still
LANTERN_HD inline BsdfEval mix_eval(const Material& m, bool front, Vec3 wo, Vec3 wi,
                                    Transport mode, Vec3 coat_n, Material& tmp,
                                    uint32_t lit = ~0u) {
    BsdfEval e{vec3(0.0f), 0.0f, 0.0f};
    const float total = mix_total(m);
    if (!(total > 0.0f)) return e;
    for (int i = 0; i < m.mix_count; ++i) {
        const float w = fmaxf(m.mix_weight[i], 0.0f);
        if (w <= 0.0f) continue;
        BsdfEval l = material_eval_leaf(mix_leaf_at(m, i, tmp), front, wo, wi, mode, coat_n);
        if ((lit >> i) & 1u) e.f += l.f * w;
        e.pdf_fwd_w += l.pdf_fwd_w * (w / total);
        e.pdf_rev_w += l.pdf_rev_w * (w / total);
    }
    return e;
}

LANTERN_HD inline BsdfEval mix_eval(const Material& m, bool front, Vec3 wo, Vec3 wi,
                                    Transport mode, Vec3 coat_n, uint32_t lit = ~0u) {
    union Leaf {  // uninitialised: assigned whole where a leaf is resolved
        Material m;
        LANTERN_HD Leaf() {}
    } tmp;
    return mix_eval(m, front, wo, wi, mode, coat_n, tmp.m, lit);
}

LANTERN_HD inline BsdfSample mix_sample(const Material& m, bool front, Vec3 wo, Vec3 u,
                                        Transport mode, Vec3 coat_n) {
    BsdfSample s{vec3(0.0f), vec3(0.0f), 0.0f, false};
    const float total = mix_total(m);
    if (!(total > 0.0f)) return s;
    // pick a leaf with u.z, then rescale u.z for the leaf's own choices
    float uc = u.z * total, before = 0.0f;
    int pick = -1;
    for (int i = 0; i < m.mix_count; ++i) {
        const float w = fmaxf(m.mix_weight[i], 0.0f);
        if (w <= 0.0f) continue;
        pick = i;
        if (uc < before + w) break;
        before += w;
    }
    if (pick < 0) return s;
    const float w = fmaxf(m.mix_weight[pick], 0.0f), p = w / total;
    const float u_leaf = fminf(fmaxf((uc - before) / w, 0.0f), 0.99999994f);
    union Leaf {
        Material m;
        LANTERN_HD Leaf() {}
    } tmp;
    BsdfSample l = material_sample_leaf(mix_leaf_at(m, pick, tmp.m), front, wo,
                                        Vec3{u.x, u.y, u_leaf}, mode, coat_n);
    if (!l.valid) return s;
    if (l.delta) {  // a delta lobe of one leaf: its discrete probability times the pick
        l.weight = l.weight * (w / p);
        l.pdf_fwd_w *= p;
        l.pdf_rev_w *= p;
        l.valid = is_finite(l.weight);
        l.lobe = uint8_t(pick + 1);
        return l;
    }
    BsdfSample r = mixture_sample(l.wi, mix_eval(m, front, wo, l.wi, mode, coat_n, tmp.m));
    r.lobe = uint8_t(pick + 1);  // the kind of the ray: the picked leaf's (Cycles' label)
    return r;
}

// ---- What the integrators call, on a material from material_at ----

// Lambert, the diffuse type without roughness: the path a diffuse-only scene takes, checked
// first so that it never reaches the mix, Oren-Nayar or layered code.
LANTERN_HD inline bool material_is_lambert(const Material& m) {
    return m.type == kMaterialDiffuse && !(m.diffuse_roughness > 0.0f);
}

// A Lambert whose normal a Bump, Displacement or Normal Map bends: coat_n then carries the
// unbent normal (SurfaceHit::coat_n) for the bump shadowing term (bsdf/lambert.h).
LANTERN_HD inline bool material_reads_light_side(const Material& m) {
    return material_is_lambert(m) && (m.tex_flags & (kTexBump | kTexNormal)) != 0;
}

// A glossy material whose lobes take the view-corrected normal (bsdf/shading_normal.h, Cycles'
// Bump Map Correction): reflection only. docs/materials.md, "Shading normals". Sharp ones (a
// mirror conductor, a Principled whose specular and metal lobes are a delta) are corrected too,
// as Cycles corrects every microfacet closure's normal, alpha 0 included (D48: otherwise the
// mirror about a smooth normal that leans far from the facet falls under it at a low-poly
// mesh's rims, and that light is lost). A delta pick is a mirror about n'(v) on camera
// sub-paths but about n on light sub-paths (no light sub-path can solve for v), so bdpt and lt
// read a slightly different BSDF there, only where n' turns; a sharp coat is still left out.
LANTERN_HD inline bool material_corrects_view(const Material& m) {
    if (m.type == kMaterialConductor) return true;
    if (m.type != kMaterialPrincipled) return false;
    return !(m.transmission > 0.0f) &&
           !(m.coat_weight > 0.0f && principled_coat_ggx(m).effectively_smooth());
}

// coat_n carries the normal before Bump and Normal Map nodes (Cycles' N) for a diffuse lobe's
// bump shadowing term: a bumped Lambert, a bumped Principled without a coat normal of its own.
LANTERN_HD inline bool material_keeps_unbent_normal(const Material& m) {
    return material_reads_light_side(m) ||
           (m.type == kMaterialPrincipled && (m.tex_flags & (kTexBump | kTexNormal)) != 0 &&
            !(m.tex_flags & kCoatNormal));
}

// A BSDF defined for every view on ng's side, below the shading normal too (a Lambert reads the
// light's side only; a view-corrected glossy material): view_side_agrees, integrator/pt.h.
LANTERN_HD inline bool material_view_geometric(const Material& m) {
    return material_is_lambert(m) || material_corrects_view(m);
}

// Out of line on the device: its room for a resolved leaf (376 B) is then a frame of its own,
// off the shade kernels' deepest call chain, not a part of theirs.
#ifdef __CUDA_ARCH__
__noinline__
#endif
LANTERN_HD inline bool mix_is_delta(const Material& m) {
    Material tmp;
    for (int i = 0; i < m.mix_count; ++i)
        if (m.mix_weight[i] > 0.0f && !material_is_delta_leaf(mix_leaf_at(m, i, tmp)))
            return false;
    return true;
}

LANTERN_HD inline bool material_is_delta(const Material& m) {
    if (m.type == kMaterialDiffuse) return false;
    return m.type == kMaterialMix ? mix_is_delta(m) : material_is_delta_leaf(m);
}

// True when m can send light to the other side of the surface.
LANTERN_HD inline bool material_transmits(const Material& m) {
    if (m.type != kMaterialMix) return material_transmits_leaf(m);
    for (int i = 0; i < m.mix_count; ++i)  // type and transmission are never resolved
        if (material_transmits_leaf(*m.mix_leaf[i])) return true;
    return false;
}

// ---- View-corrected glossy materials (material_corrects_view) ----
// f(v, l): the lobes about n'(v) = valid_reflection_normal(ng, v), v the camera side, times
// |l.n'| / |l.n| (the integrators apply |l.n|), l under n too (light_side_agrees); a Principled
// Lambert base stays on n, light side only, with the bump shadowing term (Cycles' diffuse).
// Camera sub-paths sample l about n'(v), light sub-paths v about n: each pdf its own sampler's,
// one BSDF, exact MIS. Where n'(v) = n and nothing is bumped: the lobes' own eval.
LANTERN_HD inline bool corrected_base_shadowed(const Material& m, Vec3 coat_n) {
    return material_keeps_unbent_normal(m) && m.type == kMaterialPrincipled && coat_n.z < 1.0f;
}

// corrected_eval and corrected_sample: out of line on the device (LANTERN_DEVICE_NOINLINE),
// with valid_reflection_normal's trigonometry inside them once
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline BsdfEval corrected_eval(const Material& m, bool front, Vec3 wo, Vec3 wi,
                                          Transport mode, Vec3 coat_n, Vec3 ng_l) {
    const bool radiance = mode == Transport::Radiance;
    const Vec3 v = radiance ? wo : wi, l = radiance ? wi : wo;
    BsdfEval e{vec3(0.0f), 0.0f, 0.0f};
    if (!(dot(v, ng_l) > 0.0f)) return e;
    const Vec3 n2 = valid_reflection_normal(ng_l, v);
    const bool turned = n2.z < 1.0f, shadowed = corrected_base_shadowed(m, coat_n);
    if (!turned && !shadowed) return material_eval_leaf(m, front, wo, wi, mode, coat_n);
    // l under n: only the lobes about n' (the integrators' cosine is |l.n|)
    if (!(fabsf(l.z) > 1e-6f)) return e;
    const Frame f = turned ? valid_reflection_frame(n2) : Frame{{1.0f, 0.0f, 0.0f},
                                                                {0.0f, 1.0f, 0.0f},
                                                                {0.0f, 0.0f, 1.0f}};
    const Vec3 v2 = f.to_local(v), l2 = f.to_local(l), nc2 = f.to_local(coat_n);
    const BsdfEval er = material_eval_leaf(m, front, v2, l2, Transport::Radiance, nc2);
    // the light sub-path's sampler (about n) for v given l
    const float pdf_v = turned ? material_eval_leaf(m, front, l, v, Transport::Importance, coat_n)
                                     .pdf_fwd_w
                               : er.pdf_rev_w;
    const float keep = fabsf(l2.z) / fabsf(l.z);
    e.f = er.f * keep;
    if (m.type == kMaterialPrincipled && !(m.diffuse_roughness > 0.0f)) {
        // the base: off n' (as principled_eval weighs it at the camera-side cosine), onto n
        const float g = !(l.z > 0.0f) ? 0.0f : shadowed ? bump_shadowing(coat_n, l) : 1.0f;
        const float on_n2 = v2.z > 0.0f && l2.z > 0.0f ? keep : 0.0f;
        const float w_base = principled_weights(m).spec *
                             (1.0f - principled_spec_albedo(m, v2.z));
        const Vec3 below = principled_below_coat(m, v2.z, coat_cos(m, nc2, v2));
        e.f += below * m.base_color * (w_base * kInvPi * (g - on_n2));
        e.f = Vec3{fmaxf(e.f.x, 0.0f), fmaxf(e.f.y, 0.0f), fmaxf(e.f.z, 0.0f)};
    }
    e.pdf_fwd_w = radiance ? er.pdf_fwd_w : pdf_v;
    e.pdf_rev_w = radiance ? pdf_v : er.pdf_fwd_w;
    if (!is_finite(e.f)) return BsdfEval{vec3(0.0f), 0.0f, 0.0f};
    return e;
}

LANTERN_DEVICE_NOINLINE
LANTERN_HD inline BsdfSample corrected_sample(const Material& m, bool front, Vec3 wo, Vec3 u,
                                              Transport mode, Vec3 coat_n, Vec3 ng_l) {
    BsdfSample s{vec3(0.0f), vec3(0.0f), 0.0f, false};
    bool turned;
    if (mode == Transport::Radiance) {  // the view is wo: sample l about n'(wo)
        if (!(dot(wo, ng_l) > 0.0f)) return s;
        const Vec3 n2 = valid_reflection_normal(ng_l, wo);
        turned = n2.z < 1.0f;
        if (!turned) {
            s = material_sample_leaf(m, front, wo, u, mode, coat_n);
        } else {
            const Frame f = valid_reflection_frame(n2);
            s = material_sample_leaf(m, front, f.to_local(wo), u, mode, f.to_local(coat_n));
            s.wi = f.to_world(s.wi);
        }
    } else {  // the light is wo: sample the view about n
        s = material_sample_leaf(m, front, wo, u, mode, coat_n);
        turned = s.valid && valid_reflection_normal(ng_l, s.wi).z < 1.0f;
    }
    // a delta pick (a sharp Principled's specular or metal lobe): about n' on camera
    // sub-paths, about n on light sub-paths (material_corrects_view)
    if (!s.valid || s.delta || !(turned || corrected_base_shadowed(m, coat_n))) return s;
    const Vec3 wi = s.wi;
    return mixture_sample(wi, corrected_eval(m, front, wo, wi, mode, coat_n, ng_l));
}

// ng_l: the geometric normal in this frame: the axis of a Lambert's light sub-path sampler (its
// importance sample and its reverse pdf in radiance) and what a view-corrected glossy material
// corrects towards; +Z (the default: nothing corrected) only where the caller has no such
// normal.
LANTERN_HD inline BsdfEval material_eval(const Material& m, bool front, Vec3 wo, Vec3 wi,
                                         Transport mode, Vec3 coat_n = Vec3{0.0f, 0.0f, 1.0f},
                                         Vec3 ng_l = Vec3{0.0f, 0.0f, 1.0f}) {
    if (material_is_lambert(m))  // Cycles' diffuse: the light's side only, for every view
        return lambert_bumped_eval(m.base_color,
                                   (m.tex_flags & (kTexBump | kTexNormal))
                                       ? coat_n
                                       : Vec3{0.0f, 0.0f, 1.0f},
                                   ng_l, wo, wi, mode == Transport::Radiance);
    if (material_corrects_view(m)) return corrected_eval(m, front, wo, wi, mode, coat_n, ng_l);
    return m.type == kMaterialMix ? mix_eval(m, front, wo, wi, mode, coat_n)
                                  : material_eval_leaf(m, front, wo, wi, mode, coat_n);
}

LANTERN_HD inline BsdfSample material_sample(const Material& m, bool front, Vec3 wo, Vec3 u,
                                             Transport mode,
                                             Vec3 coat_n = Vec3{0.0f, 0.0f, 1.0f},
                                             Vec3 ng_l = Vec3{0.0f, 0.0f, 1.0f}) {
    if (material_is_lambert(m))
        return lambert_bumped_sample(m.base_color,
                                     (m.tex_flags & (kTexBump | kTexNormal))
                                         ? coat_n
                                         : Vec3{0.0f, 0.0f, 1.0f},
                                     ng_l, wo, Vec2{u.x, u.y}, mode == Transport::Radiance);
    if (material_corrects_view(m))
        return corrected_sample(m, front, wo, u, mode, coat_n, ng_l);
    return m.type == kMaterialMix ? mix_sample(m, front, wo, u, mode, coat_n)
                                  : material_sample_leaf(m, front, wo, u, mode, coat_n);
}

}  // namespace lantern
