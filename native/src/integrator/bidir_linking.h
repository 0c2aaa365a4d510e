// Light and shadow linking in the bidirectional integrators (bdpt, lvc, cis; lt: lt_linking.h),
// as pt has them (pt_light_linking.h). x0 is the path's vertex on light l, x1 the vertex
// next to it (the receiver).
//
// Light linking is a property of the path: its measurement is 0 where l does not light x1's
// receiver set (camera rays see every emitter: x1 is the camera). Every technique that makes
// the path applies the same zero and no density changes, so the MIS weights stay a partition of
// unity: s = 0 (the camera path's last surface vertex, PathState::recv_set, as pt), s = 1 (the
// camera vertex), and every technique that uses a light sub-path through x1 = y1 (connections
// s >= 2, light tracing t = 1): the light pass ends a sub-path whose y1 l does not light, so no
// vertex of it is stored or splatted.
//
// Shadow linking (l's shadows cast only by its blocker set) changes the visibility of the
// segment x0 x1 alone. Next-event estimation (s = 1) tests it with the linked query; a ray that
// a BSDF or an emission sample traces from x1 or x0 stops at a surface that casts l no shadow.
// The techniques are therefore split by the scattering at x1:
//   - class A, x1 scatters through a non-delta lobe: s = 1 is the only technique, weight 1; the
//     others weigh 0 (s = 0 after a non-delta bounce, PathState::prev_pdf_w > 0; the light pass
//     neither stores nor splats y1 and continues it only through a delta lobe);
//   - class B, x1 scatters through a delta lobe: s = 1 cannot make the path (its density is 0
//     there, and so is its term in every other weight), the others keep the usual weights, and
//     trace x0 x1 with the ordinary query (pt's "seen past no surface").
// Each class's weights sum to one over the techniques that make it: unbiased where next-event
// estimation samples l.
//
// A lamp's Cast Shadow off (pt_lamp_unshadowed): Cycles' image is next-event estimation,
// unoccluded, plus the emission BSDF sampling finds, occluded, each with pt's two-technique
// power-heuristic weight (two unequal integrals: no MIS over more techniques reproduces it).
// Class A: s = 1 with pt's weight and no shadow ray, s = 0 with pt's weight (the ratio of
// next-event estimation alone, bdpt_emission_weight's nee), every light-path technique 0 (the
// light pass as above); class B (x1 delta) as for shadow linking. pt's light pick normal too.
//
// Subsurface (pt_sss.h's rule): a walk's exit is a surface vertex of the object it leaves, its
// receiver set that surface's, the walk's interior receives nothing. The camera side's exit
// (bdpt_sss.h) is a camera vertex (s = 1 from it, recv_set at its continuation for s = 0); the
// light side's walk enters at y1 = x_o, checked as any y1, and its walk is a non-delta
// scattering there (no walk at y1 of a shadow-linked light or a lamp without shadows).
#pragma once

#include "integrator/bidir_ray_visibility.h"
#include "integrator/pt_light_linking.h"
#include "integrator/pt_ray_visibility.h"

namespace lantern {

// Whether scene s has any of the tables the tests below read (light and shadow linking, a lamp
// without shadows, ray visibility by kind: bidir_ray_visibility.h): where it has none, the stages run compiled without the tests (their
// template flag L false, chosen once per chunk: schedule_bdpt.h; the GPU builds L only), the
// same bits as the tests would give.
LANTERN_HD inline bool bidir_links_on(const SceneView& s) {
    return s.light_receivers || s.light_blockers || s.light_rays || s.tri_rays;
}

// Whether light li lights receiver triangle (or strand) tri: the light pass's y1.
LANTERN_HD inline bool bidir_links(const SceneView& s, int li, int tri) {
    return !s.light_receivers || pt_light_links(s, li, pt_receiver_set(s, tri));
}

// Whether only next-event estimation makes a path whose x1 scatters off-delta on light li.
LANTERN_HD inline bool bidir_nee_only(const SceneView& s, int li) {
    return s.light_blockers && pt_shadow_linked(s, li);
}

// Whether no light path of light li may go on from y1 but through a delta lobe (class A paths
// are next-event estimation's and s = 0's alone): shadow-linked, or a lamp without shadows.
LANTERN_HD inline bool bidir_light_path_delta_only(const SceneView& s, int li) {
    return bidir_nee_only(s, li) || pt_lamp_unshadowed(s, li);
}

// Whether emission of lamp li that slot i's ray found after a non-delta bounce takes pt's
// two-technique weight (Cast Shadow off).
LANTERN_HD inline bool bidir_pt_weight(const SceneView& s, const PathState& ps, int i, int li) {
    return s.light_rays && ps.depth[i] > 1 && ps.prev_pdf_w[i] > 0.0f &&
           pt_lamp_unshadowed(s, li);
}

// The weight factor of emission of light li that slot i's camera ray found (s = 0): 0 where li
// does not light the last vertex's receiver set, or li is shadow-linked and the last bounce was
// not a delta lobe's; 1 otherwise (the usual weight then applies).
LANTERN_HD inline bool bidir_emission_counts(const SceneView& s, const PathState& ps, int i,
                                             int li) {
    if (ps.depth[i] <= 1 || li < 0) return true;  // the camera's rays: every emitter
    if (s.light_receivers && !pt_emission_linked(s, ps, i, li)) return false;
    return !(bidir_nee_only(s, li) && ps.prev_pdf_w[i] > 0.0f);
}

// Next-event estimation (s = 1) of light li at slot i's camera vertex: its shadow ray's light
// (the linked query), and the other techniques' weights: none for a shadow-linked light, BSDF
// sampling's alone (pt's) for a lamp without shadows.
LANTERN_HD inline void bidir_nee_weights(const SceneView& s, const PathState& ps, int i, int li,
                                         bool unshadowed, float& w_light, float& w_camera) {
    if (s.light_blockers) {
        if (ps.shadow_light) ps.shadow_light[i] = li;
        if (bidir_nee_only(s, li)) w_light = w_camera = 0.0f;  // the only technique
    }
    if (unshadowed) w_camera = 0.0f;
}

// Integrator auto's moment channels (bdpt_common.h, bdpt_moment) of next-event estimation of a
// shadow-linked light, class A: cis's weight is 1, but pt's (pt_light_linking.h, since shmis)
// depends on what the segment meets: the power heuristic of its two techniques where it meets
// no surface, next-event estimation alone where it passes only surfaces outside the blockers.
// The channels are pt's second moment, so they follow its rule: the camera stage
// (bdpt_camera_nee) queues those of the passed case, bdpt_pt_factor(1, 0, 1), in the
// contribution and the free case's second-moment channel, bdpt_pt_factor(1, a, 1) with a BSDF
// sampling's squared ratio, in PathState::shadow_mis (negative: none; allocated for the cis
// trials of auto where pt keeps MIS, pt_linked_mis: camera_chunk); the shadow ray's answer picks
// one. Where pt_linked_mis is false (media, ray visibility, objects without shadows) pt's rule
// is next-event estimation alone and shadow_mis is not allocated.
LANTERN_HD inline void bidir_linked_moment(const PathState& ps, int i, int result) {
    if (result == kLinkedFree && ps.shadow_mis && ps.shadow_mis[i] >= 0.0f)
        ps.shadow_contrib[i].y = ps.shadow_mis[i];
}

// A next-event shadow ray of the camera pass (ps.shadow_light: its light where shadow linking
// is on), with the linked query where the light is shadow-linked.
template <class Rays, class Kind>
LANTERN_HD inline bool bidir_nee_occluded(const SceneView& s, const Rays& rays, Kind kind,
                                          const PathState& ps, int i, const Ray& r) {
    if (!s.light_blockers) return rays.occluded(r, kind);
    const int result = pt_shadow_linked_query(s, rays, kind, ps, i, r);
    bidir_linked_moment(ps, i, result);
    return result == kLinkedBlocked;
}

}  // namespace lantern
