// Light linking with medium vertices in the bidirectional integrators (bdpt, lvc, cis; lt's
// light pass the same way: lt_linking.h): pt's
// rule (pt_light_linking.h pt_medium_receiver; pt_volume.h pt_medium_nee, pt_emission_weight):
// a vertex in the world's medium receives as set 0 (Cycles' "no object": the world volume's),
// a vertex in another medium (a mesh's volume) as the surface its path last left on the camera
// side (PathState::recv_set; 0 where the camera path met no surface yet, or scattered in the
// world's medium since).
//
// The receiver set of a path x0 (on light l) x1 ... is then found walking from x1 toward the
// camera: x1's own where it is a surface (bidir_linking.h), 0 at the first vertex in the world's
// medium, else the first surface vertex's, or 0 at the camera. Each technique applies the same
// zero, no density changes (the MIS weights stay a partition of unity):
//   - the light pass: while every vertex y1..yk is a medium vertex of a mesh's volume the
//     path's set is not known yet ("pending": PathState::recv_set of the light pass's slot, 1);
//     its first surface vertex or world-medium vertex decides it, and ends the sub-path where l
//     does not light it. A pending medium vertex carries its light in the cache
//     (LightVertex::bary16 = light + 1, 0 otherwise);
//   - a connection z - y (s >= 2, t >= 2) to a pending y: z's set (a surface's own, a medium
//     vertex's pt_medium_receiver, kept in CameraVertex::tri = -2 - set);
//   - light tracing's splat (t = 1) of a pending vertex: set 0 (the camera);
//   - next-event estimation at a camera medium vertex (s = 1) and emission found past one
//     (s = 0): PathState::recv_set, as pt (a camera medium vertex writes its receiver there,
//     as pt's scatter does).
// Shadow linking in media follows bidir_linking.h's classes (a medium vertex scatters off no
// delta lobe): s = 1 alone, its shadow ray through media with the light's blocker sets
// (bdpt_medium_shadow, as pt_shadow_loop); a light sub-path's y1 in a medium ends there
// (bdpt_medium_light.h). A lamp's Cast Shadow off in media the same way, with pt's weights
// (pt_medium_nee): s = 1 at a camera medium vertex without a ray or transmittance
// (bdpt_camera_medium_nee), s = 0 past a medium or surface vertex with pt's solid-angle ratio
// (bidir_pt_weight_medium), its y1 in a medium not the light path's (bdpt_medium_light.h).
#pragma once

#include "integrator/pt_light_linking.h"

namespace lantern {

// The light of a pending medium vertex of the cache (-1: not pending, or a surface).
LANTERN_HD inline int lv_pending_light(uint32_t bary16, int32_t tri) {
    return tri <= -2 && bary16 != 0u ? int(bary16) - 1 : -1;
}

// A camera vertex's receiver set from its CameraVertex::tri (a surface or strand: >= 0; a
// medium vertex: -2 - the camera path's set; -1: set 0).
LANTERN_HD inline int camera_vertex_set(const SceneView& s, int tri) {
    return tri >= 0 ? pt_receiver_set(s, tri) : tri <= -2 ? -2 - tri : 0;
}

// CameraVertex::tri of a camera medium vertex of slot i (-1 without light linking).
// Also records that set as the camera path's (pt_volume.h's scatter does the same).
LANTERN_HD inline int camera_medium_tri(const SceneView& s, const PathState& ps, int i,
                                        int32_t med) {
    if (!s.light_receivers || !ps.recv_set) return -1;
    const int set = med == s.world_medium ? 0 : int(ps.recv_set[i]);
    ps.recv_set[i] = uint8_t(set);
    return -2 - set;
}

// Whether light li lights slot i's camera medium vertex (s = 1): its set, which
// camera_medium_tri recorded when the vertex was made.
LANTERN_HD inline bool camera_medium_links(const SceneView& s, const PathState& ps, int i,
                                           int li) {
    return !s.light_receivers || !ps.recv_set || pt_light_links(s, li, ps.recv_set[i]);
}

}  // namespace lantern
