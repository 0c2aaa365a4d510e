// An object's Cast Shadow off (Blender's Object > Visibility > Ray Visibility > Shadow; the
// triangle flag kCastShadow cleared) in the bidirectional integrators (bdpt, lvc, cis), as pt
// renders it: pt's shadow rays pass through such a surface, its BSDF rays hit it. x0 is the
// path's vertex on the light, x1 the vertex next to it.
//
// In pt only the segment x0 x1 of next-event estimation (s = 1) is a shadow ray; every other
// segment is a BSDF (or camera) ray. With V the ordinary visibility of x0 x1 (every surface
// blocks) and V' the shadow query's (the non-casters do not), pt's image is
//     I = integral of f (V' w_nee + V w_bsdf) = integral of f V + integral of f (V' - V) w_nee,
// w_nee, w_bsdf pt's two power-heuristic weights (V <= V'). The first term is the physical
// image of the scene, which every technique samples: the usual weights. The second, paths
// whose x0 x1 only a non-caster blocks, only next-event estimation makes (a BSDF ray from x1
// and the light path from x0 stop at the non-caster): it keeps pt's weight w_nee, its share
// against s = 0 alone (1 / (1 + w_light) in bdpt_camera.h's terms: the light-path techniques'
// part w_camera dropped). So:
//   - s = 1 traces the shadow query (V'); where that passes, the ordinary query (V) too; V = 0
//     scales the contribution by the ratio of the two weights (BdptState::shadow_wn, the
//     slot's (1 + w_light + w_camera) / (1 + w_light));
//   - the connections (s >= 2: segments between two scatterings, BSDF rays in pt) trace the
//     ordinary query;
//   - s = 0 and the light pass trace as ever (BSDF rays), t = 1 the camera query (camera rays).
// The weights of each term sum to one over the techniques that make its paths: exact where
// next-event estimation samples the light. A lamp's Cast Shadow off adds no shadow ray at all
// (bidir_linking.h); in media the same split (bdpt_shadow_medium: V by bidir_medium_blocked,
// the ratio at the finish, bidir_no_shadow_medium_c); shadow linking beside it: a
// shadow-linked light's s = 1 is the only technique where x1 is no delta (weights 0: ratio 1),
// its shadow ray pt's (pt_occluded_linked with the shadow query), in media too (the ratio is
// 1 there); a non-casting strand as a triangle (the shadow query skips it, the ordinary one
// stops at it); a non-caster that is a volume boundary in media: both queries traced through
// the media, T' V' - T V at pt's weight (bidir_no_shadow_medium.h). lt: lt_linking.h. A subsurface walk's exit
// (bdpt_sss.h) is a camera vertex like any: its s = 1 takes the same ratio (its dVCM, the
// light-held set's, is part of w_camera), beside shadow linking too.
#pragma once

#include "integrator/bdpt_common.h"

namespace lantern {

// The query of a connection (s >= 2): the ordinary one (indirect) where some object casts no
// shadow, else the shadow query (the same surfaces then). Kind: the executor's RayKind.
template <class Kind>
LANTERN_HD inline Kind bidir_conn_kind(const SceneView& s, Kind shadow, Kind indirect) {
    return s.no_shadow_objects ? indirect : shadow;
}

// Records the s = 1 weight's ratio for a path that only a non-caster blocks.
LANTERN_HD inline void bidir_no_shadow_ratio(const SceneView& s, const BdptState& bs, int i,
                                             float w_light, float w_camera) {
    if (s.no_shadow_objects && s.num_media == 0)
        bs.shadow_wn[i] = (w_light + 1.0f + w_camera) / (w_light + 1.0f);
}

// The next event's visibility past the shadow query: 1 where nothing blocks it, 2 where only a
// non-caster does (the contribution then takes bidir_no_shadow_value's ratio).
template <class Rays, class Kind>
LANTERN_HD inline uint8_t bidir_nee_visible(const SceneView& s, const Rays& rays, Kind indirect,
                                            const Ray& r) {
    return s.no_shadow_objects && rays.occluded(r, indirect) ? 2 : 1;
}

LANTERN_HD inline Vec3 bidir_nee_value(const PathState& ps, const BdptState& bs, int i,
                                       uint8_t visible) {
    return visible == 2 ? ps.shadow_contrib[i] * bs.shadow_wn[i] : ps.shadow_contrib[i];
}

// In a scene with media (bdpt_shadow_medium): whether a surface other than a volume boundary
// blocks segment o -> o + d tmax for the ordinary query `indirect` (the next event's V; the
// shadow query's V' and the transmittance come from bdpt_medium_shadow; a strand blocks), where
// no non-caster is a volume boundary (both queries cross the same media; else
// bidir_no_shadow_medium.h).
template <class Rays, class Kind>
LANTERN_HD inline bool bidir_medium_blocked(const SceneView& s, const Rays& rays, Kind indirect,
                                            Vec3 o, Vec3 d, float tmax, float time) {
    for (int k = 0; k < 256; ++k) {  // boundaries crossed (a bound: never an endless loop)
        const auto h = rays.closest(Ray{o, d, 0.0f, tmax, time}, indirect);
        if (h.prim < 0 || !(h.t < tmax)) return false;
        if (!(s.tri_flags[h.prim] & kVolumeBoundary)) return true;
        // (boundaries are triangles; a strand would be passed along the ray)
        const Vec3 ng = h.prim < s.num_triangles ? triangle_geometric_normal(s, h.prim) : d;
        const Vec3 next = offset_ray_origin(o + d * h.t, ng, d, s.offset_scale);
        if (tmax < kInf) tmax = fmaxf(tmax - dot(next - o, d), 0.0f);
        o = next;
    }
    return true;
}

// The next event's contribution c (queued with the weight 1 / (1 + wn + wf), wn = w_camera,
// wf = w_light) through media of transmittance tr where only a non-caster blocks it: pt's
// weight 1 / (1 + w_light) (the light-path techniques' term dropped, as above; pt's weights
// hold no flight factor, pt_volume.h).
LANTERN_HD inline Vec3 bidir_no_shadow_medium_c(Vec3 c, Vec3 tr, float wn, float wf) {
    return c * tr * ((1.0f + wn + wf) / (1.0f + wf));
}

}  // namespace lantern
