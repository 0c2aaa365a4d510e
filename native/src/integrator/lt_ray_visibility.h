// Ray visibility by kind in the light tracer (integrator "lt"), as pt renders it
// (pt_ray_visibility.h): objects and lamps hidden from Diffuse, Glossy or Transmission rays, on
// surfaces, past subsurface walks (lt_rays_sss_weight) and in media (lt_rays_medium_weight);
// strands, and linking or Cast Shadow off beside media, stay pt's: allocation.cpp
// bidir_visibility_reason. A light path y0 (on light l) y1 ... yk is pt's path
// x0 = camera, x1 = yk, ..., x_k = y0 read backward. pt's segment x_i x_{i+1} (i >= 1) is a bounce
// ray leaving x_i with the kind K(x_i) of the scattering there (pt_scatter_kind: x_i's material,
// and whether x_{i-1} and x_{i+1} lie on one side): it passes every surface hidden from K(x_i)
// and ends on x_{i+1} only where x_{i+1} is seen by K(x_i) (a light: pt_light_hidden). In lt
// the segment y_k y_{k+1} is that ray leaving y_{k+1}, whose kind is known only once y_{k+1}
// scatters toward the camera (the splat) or on (the continuation). So lt's segment walks: at a
// hit on a surface hidden from some kind ("R": tri_rays short of Diffuse | Glossy |
// Transmission) it stops (y_{k+1} = the hit) or passes on, probability 1/2 each, weight 2; a
// surface seen by every kind ends the walk. The slot keeps in PathState::ray_kind the kinds
// that see some passed surface (low nibble P) and the kinds that see y_k (high nibble E, k >= 1);
// a scattering of kind K at y_{k+1} counts where P & K = 0 and E & K != 0 (at y1: l not hidden
// from K), else its splat or its continuation is 0. The camera segment is a camera ray (the
// query's own flags, as lt tests it).
//
// The first segment y0 y1 is pt's last, made by two techniques: next-event estimation (its
// shadow ray ignores kinds: stopped by any R surface) and the bounce ray (passes surfaces
// hidden from K(y1)). pt's image there is f (w_nee V_shadow + w_bsdf V_K): at the first hit
// h1 weight 1 (V_shadow = V_K = 1), at a hit past R surfaces all hidden from K only the bounce
// ray's share, w_bsdf = 1 - w_nee for a non-delta lobe (the splat, a non-delta continuation;
// lt_linking.h lt_nee_weight, from x0 = prev_p) and 1 for a delta lobe (pt's bounce ray
// alone). A delta light (a point, spot of radius 0, a sun of angle 0) is found by no bounce
// ray: its first segment does not walk (kLtRaysNoWalk, set at generation).
// Included by lt.h.
#pragma once

#include "integrator/lt_linking.h"
#include "integrator/pt_ray_visibility.h"

namespace lantern {

constexpr uint8_t kLtSurfaceKinds = kRayDiffuse | kRayGlossy | kRayTransmission;
// y0's slot (the high nibble E is read at k >= 1 only): a delta light's first segment makes
// no bounce-ray vertex; the first segment passed some surface; one of them casts l a shadow.
constexpr uint8_t kLtRaysNoWalk = 0x10, kLtRaysPassed = 0x20, kLtRaysBlocked = 0x40;

// Whether lt reads ray visibility by kind (some object or lamp hidden from some kind).
LANTERN_HD inline bool lt_rays_on(const SceneView& s) { return s.rays_hidden != 0; }

// The kinds a surface must be seen by for every segment to end on it: the surface kinds, and in
// a scene with media Volume Scatter too (a medium vertex's phase ray passes a surface hidden
// from it: lt_rays_medium_weight).
LANTERN_HD inline uint8_t lt_rays_all(const SceneView& s) {
    return s.num_media > 0 ? uint8_t(kRayKindsAll) : kLtSurfaceKinds;
}

// y0's state: nothing passed; a delta light's first segment does not walk.
LANTERN_HD inline void lt_rays_start(const PathState& ps, int i, const EmissionSample& es) {
    ps.ray_kind[i] = es.delta_pos || es.delta_dir ? kLtRaysNoWalk : uint8_t(0);
}

// Whether pt's next event of y0's light still sees the first segment's y1 past what it passed:
// some surface passed, each casting the light no shadow (lt_linking.h lt_shadow_passes).
LANTERN_HD inline bool lt_rays_nee(uint8_t st) {
    return (st & kLtRaysPassed) && !(st & kLtRaysBlocked);
}

// One step of slot i's walk at its hit on triangle or strand tri (point p): true where the hit
// is the next vertex (the throughput then carries the choice's weight), false where the slot
// passed on (its ray continues past the hit) or ended (no technique sees past it). `walk`: the
// first segment of light li also walks past surfaces that cast li no shadow (lt_linking.h
// lt_walks): there a hit is passed where pt's bounce ray (an R surface, some kind seeing none
// passed) or pt's next event (every passed surface transparent to li) may see past it.
LANTERN_HD inline bool lt_rays_step(const SceneView& s, const PathState& ps, int i, int li,
                                    int tri, Vec3 p, bool walk) {
    if (!s.tri_rays) return true;
    const bool first = ps.depth[i] == 0, strand = tri >= s.num_triangles;
    const uint8_t all = lt_rays_all(s);
    const uint8_t seen = strand ? all : uint8_t(s.tri_rays[tri] & all);
    uint8_t st = ps.ray_kind[i];
    walk = walk && first;
    const bool nee = walk && !(st & kLtRaysBlocked) && lt_shadow_passes(s, li, tri);
    const bool bsdf = seen != all && !(first && (st & kLtRaysNoWalk));
    if (!nee && !bsdf) return true;  // every technique stops here
    if (walk && ps.walk_passed(i) >= 255) return false;  // (a bound: never an endless walk)
    if (!walk || bidir_links(s, li, tri)) {  // (an unlit hit is passed for sure: lt_walk_step)
        Rng rng = ps.rng[i];
        const bool stop = rng.uniform() < 0.5f;
        ps.rng[i] = rng;
        ps.throughput[i] = ps.throughput[i] * 2.0f;
        if (stop) return true;
    }
    st |= seen;
    if (first) st |= nee ? kLtRaysPassed : uint8_t(kLtRaysPassed | kLtRaysBlocked);
    ps.ray_kind[i] = st;
    if (!nee && (st & all) == all) return false;  // no kind passes
    if (walk) ps.walk_passed(i) += 1;
    if (strand) {  // on from the same origin past its entry, as lt_walk_step
        const float t = ps.hit_t[i];
        ps.ray_tmin[i] = t + 1e-5f * fmaxf(t, s.offset_scale);
        ps.alive[i] = 1;
        return false;
    }
    pt_pass_hidden(s, ps, i, p, triangle_geometric_normal(s, tri));
    return false;
}

// Whether a scattering at slot i's vertex y_{k+1} (depth k + 1, material m, geometric normal
// ng) from the light side w_l toward the camera side w_c (`delta`: off a delta lobe) is of a
// kind pt's bounce ray from y_{k+1} toward y_k has: seen by no passed surface, seeing y_k (at
// y1: light li); at y1 past surfaces all transparent to li, a non-delta lobe of any kind (pt's
// next event's share, lt_rays_weight).
LANTERN_HD inline bool lt_rays_kind_ok(const SceneView& s, const PathState& ps, int i, int li,
                                       const Material& m, Vec3 ng, Vec3 w_l, Vec3 w_c,
                                       bool delta = false) {
    const Vec3 n = dot(w_c, ng) < 0.0f ? -ng : ng;
    const uint8_t k = pt_scatter_kind(m, w_l, n);
    const uint8_t st = ps.ray_kind[i];
    if ((st & k & kLtSurfaceKinds) && !(ps.depth[i] == 1 && !delta && lt_rays_nee(st)))
        return false;
    if (ps.depth[i] == 1) return !pt_light_hidden(s, li, pt_path_kind(m, w_l, n));  // (D57)
    return ((st >> 4) & k) != 0;
}

// The first segment's weight at y1 past what it passed: pt's next event's share w_nee where
// every passed surface casts li no shadow (a non-delta lobe), plus pt's bounce ray's where
// every passed surface is hidden from the scattering's kind (1 - w_nee for a non-delta lobe, 1
// for a delta one; none from a delta light); 1 at the first hit.
LANTERN_HD inline float lt_rays_weight(const SceneView& s, const PathState& ps, int i, int li,
                                       int tri, const Material& m, const SurfaceHit& h, Vec3 w_l,
                                       Vec3 w_c, float pdf_rev, bool delta) {
    const uint8_t st = ps.ray_kind[i];
    if (ps.depth[i] != 1 || !(st & kLtRaysPassed)) return 1.0f;
    const uint8_t k = pt_scatter_kind(m, w_l, dot(w_c, h.ng) < 0.0f ? -h.ng : h.ng);
    const bool bsdf = !(st & kLtRaysNoWalk) && !(st & k & kLtSurfaceKinds);
    const bool nee = !delta && lt_rays_nee(st);
    if (delta || nee == bsdf) return bsdf ? 1.0f : 0.0f;  // (both: w_nee + w_bsdf = 1)
    const float w = lt_nee_weight(s, ps, i, li, tri, m, h, w_l, w_c, pdf_rev);
    return nee ? w : fmaxf(0.0f, 1.0f - w);
}

// A walk under the surface from slot i's vertex x_o (lt_sss.h; triangle tri, h facing the light
// along w_l): pt's exit there (pt_sss.h) is a diffuse scattering, its next event skipping a light
// hidden from diffuse rays and its continuation a diffuse bounce (kRayKindSubsurface). Its
// factor as such a scattering's: lt_rays_kind_ok's test, and at y1 past what the first segment
// passed lt_rays_weight's shares with pt's next-event weight at an exit (lt_sss_nee_weight).
// The walk reads no kinds, nor does its exit (a surface seen by the camera-side ray that reaches
// it: lt_sss_exit starts the next segment's, lt_rays_next).
LANTERN_HD inline float lt_rays_sss_weight(const SceneView& s, const PathState& ps, int i, int li,
                                           int tri, const SurfaceHit& h, Vec3 w_l) {
    const uint8_t k = kRayKindSubsurface, st = ps.ray_kind[i];
    if (ps.depth[i] != 1) return !(st & k) && ((st >> 4) & k) ? 1.0f : 0.0f;
    if (pt_light_hidden(s, li, k)) return 0.0f;
    if (!(st & kLtRaysPassed)) return 1.0f;
    const bool bsdf = !(st & kLtRaysNoWalk) && !(st & k), nee = lt_rays_nee(st);
    if (nee == bsdf) return bsdf ? 1.0f : 0.0f;  // (both: w_nee + w_bsdf = 1)
    const float w = lt_sss_nee_weight(s, ps, i, li, tri, h, w_l);
    return nee ? w : fmaxf(0.0f, 1.0f - w);
}

// After y_{k+1}'s scattering: the next segment starts with nothing passed, E = its kinds.
LANTERN_HD inline void lt_rays_next(const SceneView& s, const PathState& ps, int i, int tri) {
    const uint8_t seen =
        s.tri_rays && tri < s.num_triangles ? s.tri_rays[tri] : uint8_t(kRayKindsAll);
    ps.ray_kind[i] = uint8_t((seen & lt_rays_all(s)) << 4);
}

// A medium vertex of slot i at p, reached along d (the light's travel), going on along w_c (the
// splat's or the phase sample's direction), phase asymmetry g: pt's scattering there is a phase
// sample of kind Volume Scatter alone (pt_volume.h kRayKindVolume), its next event skipping a
// light hidden from it. Its factor as lt_rays_sss_weight's for that kind; at y1 past what the
// first segment passed (surfaces hidden from Volume Scatter) pt's phase ray's share 1 - w_nee,
// w_nee its medium next event's power heuristic (the light's density, picked with n = 0,
// against the phase's; no flight factor); none from a delta light. (Linking and Cast Shadow
// off beside it in media stay pt's: allocation.cpp.)
LANTERN_HD inline float lt_rays_medium_weight(const SceneView& s, const PathState& ps, int i,
                                              int li, Vec3 p, Vec3 d, Vec3 w_c, float g) {
    const uint8_t k = kRayKindVolume, st = ps.ray_kind[i];
    if (ps.depth[i] != 1) return !(st & k) && ((st >> 4) & k) ? 1.0f : 0.0f;
    if (li < 0 || pt_light_hidden(s, li, k)) return 0.0f;
    if (!(st & kLtRaysPassed)) return 1.0f;
    if ((st & kLtRaysNoWalk) || (st & k)) return 0.0f;
    const float pdf_w = lt_light_pdf_w(s, ps, i, li, p, -d);
    const float pick = s.light_tree_on ? light_pick_pmf(s, li, p, vec3(0.0f))
                                       : s.lights[li].nee_pdf;
    const float pdf = pdf_w > 0.0f ? pick * pdf_w : 0.0f;
    if (!(pdf > 0.0f)) return 1.0f;  // (a light next-event estimation never takes)
    return fmaxf(0.0f, 1.0f - power_heuristic(pdf, hg_phase(g, dot(d, w_c))));
}

}  // namespace lantern
