// Object ray visibility in pt (Cycles' Object > Visibility > Ray Visibility: Diffuse, Glossy,
// Transmission, Volume Scatter; Camera and Shadow are the ray queries' own, accel/bvh.h). A
// bounce ray passes through the surfaces hidden from the kind of scattering that made it, and
// next-event estimation skips their emission for that kind, so both MIS strategies see the
// same scene. Only read where SceneView::tri_rays is set (some object hides from some kind).
#pragma once

#include "bsdf/material.h"
#include "core/offset.h"
#include "integrator/path_state.h"
#include "scene/scene_view.h"

namespace lantern {

// The kind of a scattering towards wi off material m (ng: the geometric normal facing the
// arriving ray), as Cycles' object ray visibility reads it (path_state_ray_visibility): through
// the surface a transmission (its diffuse or glossy label dropped); a reflection off the diffuse
// materials diffuse, off conductors and glass glossy (a sharp mirror too: Cycles labels singular
// rays glossy); off Principled and mixes, which Lantern samples as one mixture, both (an object
// is hidden from such a reflection only when it is hidden from both kinds:
// addon/export/visibility.py warns).
LANTERN_HD inline uint8_t pt_scatter_kind(const Material& m, Vec3 wi, Vec3 ng) {
    if (dot(wi, ng) < 0.0f) return kRayTransmission;
    switch (m.type) {
    case kMaterialConductor:
    case kMaterialHair:  // Cycles labels hair reflection glossy
    case kMaterialDielectric: return kRayGlossy;
    case kMaterialPrincipled:
    case kMaterialMix: return kRayDiffuse | kRayGlossy;
    default: return kRayDiffuse;
    }
}

// The kind of that scattering as a path's flags carry it (Cycles' PathRayVisibility, set by
// path_state_next from the closure's label), which a lamp's exclusion reads: a Translucent
// scattering through the surface is labelled diffuse and transmit, so it is diffuse and
// transmission (a lamp hidden from Diffuse rays lights no Translucent surface: D57); a glossy
// or singular one stays transmission (Cycles' glossy exclusion needs PATH_RAY_REFLECT). Objects
// read it through pt_object_kind, which drops the diffuse again. What PathState::ray_kind holds.
LANTERN_HD inline uint8_t pt_path_kind(const Material& m, Vec3 wi, Vec3 ng) {
    const uint8_t k = pt_scatter_kind(m, wi, ng);
    return k == kRayTransmission && m.type == kMaterialTranslucent
               ? uint8_t(kRayDiffuse | kRayTransmission)
               : k;
}

// A path kind as object visibility reads it: a transmission's diffuse or glossy dropped.
LANTERN_HD inline uint8_t pt_object_kind(uint8_t kind) {
    return (kind & kRayTransmission) ? uint8_t(kind & ~(kRayDiffuse | kRayGlossy)) : kind;
}

// A scattering in a medium: of its own kind only. Cycles' volume-scatter rays once also counted
// as diffuse for object visibility (a "todo" in path_state_ray_visibility); Blender 4.4 dropped
// that (Cycles d1f1923, Fix #135145), so an object with only Volume Scatter off is passed by
// them and its emission skipped by a medium vertex's next-event estimation (D54).
constexpr uint8_t kRayKindVolume = kRayVolumeScatter;
// A subsurface walk's exit: a diffuse reflection (its cosine lobe).
constexpr uint8_t kRayKindSubsurface = kRayDiffuse;

// The kinds a lamp's exclusion reads (Cycles' path flags): a volume scattering is of its own
// kind only (as kRayKindVolume now is for objects too: kept for bdpt's kinds).
LANTERN_HD inline uint8_t pt_lamp_kind(uint8_t kind) {
    return (kind & kRayVolumeScatter) ? uint8_t(kRayVolumeScatter) : kind;
}

// Whether light li is hidden from scatterings of path kind `kind` (next-event estimation then
// finds nothing there): an emissive triangle by its object's flags (tri_rays: seen by any kind
// of pt_object_kind's), a lamp by its own (light_rays: Blender's ray visibility on a light
// object; as Cycles excludes a light's shader, hidden when any kind of the scattering's is off).
LANTERN_HD inline bool pt_light_hidden(const SceneView& s, int li, uint8_t kind) {
    if ((!s.tri_rays && !s.light_rays) || li < 0) return false;
    const Light& l = s.lights[li];
    if (l.type == kLightTriangle) return s.tri_rays && !(s.tri_rays[l.triangle] & pt_object_kind(kind));
    const uint8_t k = pt_lamp_kind(kind);
    return s.light_rays && (s.light_rays[li] & k) != k;
}

// The material whose kind a sampled direction takes (Cycles' path_state_next reads the sampled
// closure's label): a Mix's picked leaf (BsdfSample::lobe, mix_sample), else m itself. Only
// its type is read (a leaf's type is never resolved: scene.h), so the unresolved leaf serves.
// (Principled's own lobes stay one kind, pt_scatter_kind: their labels are not reported.)
LANTERN_HD inline const Material& pt_sampled_leaf(const Material& m, uint8_t lobe) {
    return m.type == kMaterialMix && lobe > 0 && lobe <= m.mix_count ? *m.mix_leaf[lobe - 1]
                                                                      : m;
}

// The path kind of a sampled direction wi (pt_path_kind of the leaf that drew it)
LANTERN_HD inline uint8_t pt_sampled_kind(const Material& m, uint8_t lobe, Vec3 wi, Vec3 ng) {
    return pt_path_kind(pt_sampled_leaf(m, lobe), wi, ng);
}

// Whether next-event estimation of light li lights leaf material m towards wi: Cycles' rule by
// closure class (surface_shader.h _surface_shader_exclude, reading the light's SHADER_EXCLUDE_*
// flags: a lamp's, or an emissive triangle's object's, light.h light_sample ls->shader |=
// visibility_flag), not by path kind: a Translucent closure is of the diffuse class (a light
// hidden from Transmission alone still lights it, one hidden from Diffuse not), a diffuse /
// glossy reflection by its own class. Principled (several closures, one eval here), hair and
// glass keep pt_light_hidden's path kind (Cycles leaves a Glass closure out only where the
// light is hidden from both Glossy and Transmission: not done, lt's rule would differ).
LANTERN_HD inline bool pt_leaf_lit(const SceneView& s, int li, const Material& m, Vec3 wi,
                                   Vec3 ng) {
    if (li < 0) return true;
    const Light& l = s.lights[li];
    const uint8_t* rays = l.type == kLightTriangle ? s.tri_rays : s.light_rays;
    if (!rays) return true;  // (no such light hidden from any kind)
    const uint8_t seen = rays[l.type == kLightTriangle ? l.triangle : li];
    switch (m.type) {
    case kMaterialDiffuse:
    case kMaterialTranslucent: return (seen & kRayDiffuse) != 0;
    case kMaterialConductor: return (seen & kRayGlossy) != 0;
    default: return !pt_light_hidden(s, li, pt_path_kind(m, wi, ng));
    }
}

// The leaves next-event estimation of light li lights on m towards wi (pt_leaf_lit): a Mix's
// as bits (leaf i: bit i), any other material 1 or 0; kNeeAllLit where all are. A Mix lit on
// some leaves only takes those leaves' value (mix_eval's lit) and the whole mixture's pdf in
// its MIS weight, as Cycles' surface_shader_bsdf_eval does.
constexpr uint32_t kNeeAllLit = ~0u;
LANTERN_HD inline uint32_t pt_nee_leaves(const SceneView& s, int li, const Material& m, Vec3 wi,
                                         Vec3 ng) {
    if (m.type != kMaterialMix) return pt_leaf_lit(s, li, m, wi, ng) ? kNeeAllLit : 0u;
    uint32_t lit = 0u, all = 0u;
    for (int k = 0; k < m.mix_count; ++k) {
        if (!(m.mix_weight[k] > 0.0f)) continue;
        all |= 1u << k;
        if (pt_leaf_lit(s, li, *m.mix_leaf[k], wi, ng)) lit |= 1u << k;
    }
    return lit == all ? kNeeAllLit : lit;
}

// A Mix lit on some leaves only (pt_nee_leaves): their value alone (radiance), out of line
#ifdef __CUDA_ARCH__
__noinline__
#else
__attribute__((noinline))
#endif
LANTERN_HD inline Vec3 pt_eval_lit(const Material& m, bool front, Vec3 wo, Vec3 wi, Vec3 coat_n,
                                   uint32_t lit) {
    return mix_eval(m, front, wo, wi, Transport::Radiance, coat_n, lit).f;
}

// Whether lamp li casts no shadow (Blender's Cast Shadow off on a light: kLampNoShadow). As
// Cycles does (shadow_ray_setup: a light without SHADER_CAST_SHADOW gets a zero-length shadow
// ray), next-event estimation adds its contribution unoccluded and unattenuated by media, with
// the usual MIS weight, while a bounce ray still finds the lamp only where nothing blocks it:
// the two strategies no longer estimate one integral, and their weighted sum is Cycles'
// (non-physical) image, a blocker's shadow lit by the weight next-event estimation has there.
// bdpt, lvc and cis reproduce it with pt's weights for the paths next-event estimation makes
// off a non-delta lobe (docs/lvc_notes.md "Linking"), lt by its first segment's walk.
LANTERN_HD inline bool pt_lamp_unshadowed(const SceneView& s, int li) {
    return s.light_rays && li >= 0 && (s.light_rays[li] & kLampNoShadow) != 0;
}

// Records the (path) kind of the scattering that made slot i's next ray.
LANTERN_HD inline void pt_set_ray_kind(const SceneView& s, const PathState& ps, int i,
                                       uint8_t kind) {
    if ((s.tri_rays || s.light_rays) && ps.ray_kind) ps.ray_kind[i] = kind;
}

// Whether lamp li, which slot i's bounce ray found, is hidden from the ray's kind: its emission
// does not count (next-event estimation skips it for that kind too: pt_light_hidden, so the
// two strategies estimate the same integral and their MIS weights still sum to one). Camera
// rays: the lamp's visible_camera. (The kinds alone: bdpt's camera pass keeps a restricted bit
// beside them, bidir_ray_visibility.h kRayRestricted; pt never sets it.)
LANTERN_HD inline bool pt_lamp_unseen(const SceneView& s, const PathState& ps, int i, int li) {
    if (!s.light_rays || !ps.ray_kind || ps.depth[i] <= 1) return false;
    const uint8_t k = pt_lamp_kind(uint8_t(ps.ray_kind[i] & kRayKindsAll));
    return (s.light_rays[li] & k) != k;
}

// True when slot i's bounce ray hit a triangle hidden from its (object) kind: the ray goes on
// from the hit point, the same segment (depth, throughput and the MIS state of the last real vertex
// stay), as if the triangle were not in the ray query. Camera rays: the query's own flags.
LANTERN_HD inline bool pt_hidden_from_ray(const SceneView& s, const PathState& ps, int i, int tri) {
    return s.tri_rays && ps.ray_kind && ps.depth[i] > 1 &&
           !(s.tri_rays[tri] & pt_object_kind(ps.ray_kind[i]));
}

// A strand passed (its object hidden from the ray's kind): on from the same origin past its
// entry, as lt_walk_step (re-offset from a grazing entry into an end sphere, a ray finds the
// strand again and again); its exit, hit next, is passed the same way.
LANTERN_HD inline void pt_pass_hidden_strand(const SceneView& s, const PathState& ps, int i) {
    const float t = ps.hit_t[i];
    ps.ray_tmin[i] = t + 1e-5f * fmaxf(t, s.offset_scale);
    ps.alive[i] = 1;
}

LANTERN_HD inline void pt_pass_hidden(const SceneView& s, const PathState& ps, int i, Vec3 p,
                                      Vec3 ng) {
    const Vec3 d = ps.ray_d[i];
    ps.ray_o[i] = offset_ray_origin(p, ng, d, s.offset_scale);
    ps.ray_tmin[i] = 0.0f;
    const float tmax = ps.ray_tmax[i];
    ps.ray_tmax[i] = tmax < kInf ? fmaxf(tmax - ps.hit_t[i], 0.0f) : kInf;
    ps.alive[i] = 1;
}

}  // namespace lantern
