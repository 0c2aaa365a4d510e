// Light linking in pt (Cycles' Object > Shading > Light Linking > Receiver collection): light l
// lights a surface of receiver set r only where bit r of SceneView::light_receivers[l] is set.
// Next-event estimation picks lights as before (the tree knows no sets) and finds nothing from
// an unlinked one; emission a bounce ray finds counts only where the light lights the set of the
// vertex the ray left (PathState::recv_set). Both strategies then estimate the same integral,
// and their MIS weights, over the same picks, still sum to one. Camera rays see every emitter.
#pragma once

#include "core/offset.h"
#include "integrator/path_state.h"
#include "scene/lights.h"
#include "scene/scene_view.h"

namespace lantern {

LANTERN_HD inline int pt_receiver_set(const SceneView& s, int tri) {
    return s.tri_light_set && tri >= 0 ? int(s.tri_light_set[tri]) : 0;
}

// Whether light li lights receiver set r.
LANTERN_HD inline bool pt_light_links(const SceneView& s, int li, int r) {
    return !s.light_receivers || li < 0 || ((s.light_receivers[li] >> r) & 1u) != 0;
}

// Whether emission of light li that slot i's ray found counts (the camera's rays: always).
LANTERN_HD inline bool pt_emission_linked(const SceneView& s, const PathState& ps, int i, int li) {
    return !s.light_receivers || ps.depth[i] <= 1 || !ps.recv_set ||
           pt_light_links(s, li, ps.recv_set[i]);
}

// Records the receiver set of the vertex slot i's next ray leaves.
LANTERN_HD inline void pt_set_receiver(const SceneView& s, const PathState& ps, int i, int tri) {
    if (s.light_receivers && ps.recv_set) ps.recv_set[i] = uint8_t(pt_receiver_set(s, tri));
}

// The receiver set of slot i's medium point (Cycles: the volume's object; a world volume's
// OBJECT_NONE reads set 0, an object without linking): 0 in the world's medium; inside a mesh's
// medium the set of the surface the path last left (not the volume object's own: an
// approximation where that differs).
LANTERN_HD inline int pt_medium_receiver(const SceneView& s, const PathState& ps, int i) {
    return ps.medium[i] == s.world_medium ? 0 : int(ps.recv_set[i]);
}

}  // namespace lantern

// ---- Shadow linking (Cycles' Blocker collection): light l's shadows are cast only by
// triangles and strands whose shadow set (SceneView::tri_shadow_set) is in
// SceneView::light_blockers[l]. A bounce ray cannot see such a light through a surface that
// casts it no shadow, so the two strategies split each direction wi from a vertex x by what the
// segment x -> light meets (bench/results/2026-12-06-nee10022/README.md, "MIS"):
// - no surface: next-event estimation and the bounce ray that finds the light take the usual
//   power-heuristic weights (pt_linked_mis);
// - only surfaces outside the blockers: next-event estimation weight 1 (the bounce ray stops at
//   the first of them);
// - a blocker: neither.
// The next event's weight is decided after its shadow ray (PathState::shadow_mis,
// pt_shadow_result_linked). Where a bounce ray may pass a surface the shadow ray does not see
// alike (ray visibility, the catcher pass, volume boundaries: pt_linked_mis false) the old
// rule: next-event estimation alone (weight 1; a bounce ray's hit after a non-delta vertex
// weighs 0). After a delta vertex the bounce ray's hit counts, seen past no surface (Cycles
// traces a dedicated ray there). Both rules are unbiased; the split only lowers the variance
// (next-event estimation alone is heavy-tailed on a sharp glossy lobe). ----
namespace lantern {

LANTERN_HD inline bool pt_shadow_linked(const SceneView& s, int li) {
    return s.light_blockers && li >= 0 && s.light_blockers[li] != kAllReceivers;
}

// Whether a shadow-linked light keeps MIS in this scene: a shadow ray meets every surface a
// bounce ray would, so that a segment free of surfaces for one is free for the other: no ray
// visibility (a bounce ray would pass surfaces hidden from its kind), no object without Cast
// Shadow (a shadow ray would pass it), no media (volume boundaries), not the catcher pass (its
// rays pass every surface but catchers). Camera visibility reads camera rays alone.
LANTERN_HD inline bool pt_linked_mis(const SceneView& s) {
    return s.num_media == 0 && !s.tri_rays && s.no_shadow_objects == 0 &&
           s.catcher_mode != kCatcherPass;
}

// The same in a scene whose only medium is the world's (no mesh volume, so a volume boundary
// changes no medium for either ray): a segment free of surfaces is then one stretch of the
// world's medium for the shadow ray and the bounce ray alike, and both estimate the light times
// its transmittance. pt alone (pt_shade_surface, the walk's exit): its medium vertices keep
// next-event estimation alone (PathState::shadow_mis -1 marks their bounce rays, which weigh 0
// for such a light: pt_linked_bounce), and its shadow ray through the fog reports whether it
// passed a surface (pt_shadow_loop). The bidirectional integrators keep pt_linked_mis.
LANTERN_HD inline bool pt_linked_mis_fog(const SceneView& s) {
    return s.num_media == 1 && s.world_medium == 0 && !s.tri_rays && s.no_shadow_objects == 0 &&
           s.catcher_mode != kCatcherPass;
}

// Whether pt's surface next event of a shadow-linked light keeps its MIS weight for the shadow
// ray's answer.
LANTERN_HD inline bool pt_linked_mis_pt(const SceneView& s) {
    return pt_linked_mis(s) || pt_linked_mis_fog(s);
}

// Whether emission of a shadow-linked light that slot i's bounce ray found (after a non-delta
// vertex) takes the MIS weight (else 0: the next event's alone): where pt_linked_mis holds, and
// in the world's fog after a surface vertex (shadow_mis not -1: pt_linked_mis_fog).
LANTERN_HD inline bool pt_linked_bounce(const SceneView& s, const PathState& ps, int i) {
    return pt_linked_mis(s) || (pt_linked_mis_fog(s) && ps.shadow_mis && ps.shadow_mis[i] >= 0.0f);
}

// Whether surface prim (a triangle or strand segment) casts a shadow for a light whose blocker
// sets are `blockers` (kAllReceivers: every surface; a prim without a shadow set is in set 0):
// pt_shadow_linked_query's and pt_shadow_loop's test.
LANTERN_HD inline bool pt_casts_shadow(const SceneView& s, uint64_t blockers, int prim) {
    const int set = s.tri_shadow_set ? int(s.tri_shadow_set[prim]) : 0;
    return ((blockers >> set) & 1u) != 0;
}

// pt_shadow_linked_query's answers.
constexpr int kLinkedFree = 0;     // the segment meets no surface
constexpr int kLinkedPassed = 1;   // only surfaces that cast the light no shadow
constexpr int kLinkedBlocked = 2;  // a surface that casts its shadow

// Slot i's next-event shadow ray towards light ps.shadow_light[i]: what segment r meets (Rays:
// the executor's ray query, kind its shadow rays' RayKind; any surface blocks a light without
// linking). A passed triangle is left from its offset hit point; a passed strand from the same
// origin with tmin just past its entry (re-offsetting from a grazing entry into a round strand
// found its surface again and again until the loop's bound reported the ray blocked).
template <class Rays, class Kind>
LANTERN_HD inline int pt_shadow_linked_query(const SceneView& s, const Rays& rays, Kind kind,
                                             const PathState& ps, int i, Ray r) {
    const int li = s.light_blockers && ps.shadow_light ? ps.shadow_light[i] : -1;
    if (!pt_shadow_linked(s, li))  // the usual
        return rays.occluded(r, kind) ? kLinkedBlocked : kLinkedFree;
    const uint64_t mask = s.light_blockers[li];
    for (int k = 0; k < 256; ++k) {  // surfaces passed (a bound: never an endless loop)
        const auto h = rays.closest(r, kind);
        if (h.prim < 0 || !(h.t < r.tmax)) return k == 0 ? kLinkedFree : kLinkedPassed;
        if (pt_casts_shadow(s, mask, h.prim)) return kLinkedBlocked;
        if (h.prim >= s.num_triangles) {  // a strand (pt_curve.h): on past its entry
            r.tmin = h.t + 1e-5f * fmaxf(h.t, s.offset_scale);
            continue;
        }
        const Vec3 ng = triangle_geometric_normal(s, h.prim);
        const Vec3 next = offset_ray_origin(r.o + r.d * h.t, ng, r.d, s.offset_scale);
        if (r.tmax < kInf) r.tmax = fmaxf(r.tmax - dot(next - r.o, r.d), 0.0f);
        r.o = next;
        r.tmin = 0.0f;
    }
    return kLinkedBlocked;
}

// Whether anything that casts light ps.shadow_light[i]'s shadow blocks segment r (the
// bidirectional camera pass's next events: bidir_linking.h).
template <class Rays, class Kind>
LANTERN_HD inline bool pt_occluded_linked(const SceneView& s, const Rays& rays, Kind kind,
                                          const PathState& ps, int i, Ray r) {
    return pt_shadow_linked_query(s, rays, kind, ps, i, r) == kLinkedBlocked;
}

// The next event's MIS weight kept across the shadow test: w where the light is shadow-linked
// and keeps MIS (the contribution then carries weight 1), else 1 (w is in it already).
LANTERN_HD inline void pt_keep_shadow_mis(const PathState& ps, int i, float w) {
    if (ps.shadow_mis) ps.shadow_mis[i] = w;
}

// The result of pt_shadow_linked_query for slot i's next event: the contribution at the MIS
// weight kept for it where the segment met no surface, at weight 1 where it passed surfaces.
LANTERN_HD inline void pt_shadow_result_linked(const PathState& ps, int i, int result) {
    if (result == kLinkedBlocked) return;
    const Vec3 c = ps.shadow_contrib[i];
    add_radiance(ps, i, result == kLinkedFree && ps.shadow_mis ? c * ps.shadow_mis[i] : c);
}

}  // namespace lantern
