// Light linking with medium vertices in the bidirectional integrators (bdpt, lvc, cis): pt's
// rule (pt_volume.h pt_medium_nee, pt_emission_weight) is that a medium vertex receives as the
// surface its path last left on the camera side (PathState::recv_set), the camera's own set 0
// where the camera path met no surface yet (pt_generate; Cycles' receiver "no object").
//
// The receiver set of a path x0 (on light l) x1 ... is then that of the first surface vertex
// after x0 (x1 itself where it is a surface, bidir_linking.h), or 0 where every vertex between
// x0 and the camera is a medium vertex. Each technique applies the same zero, no density
// changes (the MIS weights stay a partition of unity):
//   - the light pass: while every vertex y1..yk is a medium vertex the path's set is not known
//     yet ("pending": PathState::recv_set of the light pass's slot, 1); its first surface
//     vertex decides it, and ends the sub-path where l does not light it. A pending medium
//     vertex carries its light in the cache (LightVertex::bary16 = light + 1, 0 otherwise);
//   - a connection z - y (s >= 2, t >= 2) to a pending y: z's set (a surface's own, a medium
//     vertex's the camera path's PathState::recv_set, kept in CameraVertex::tri = -2 - set);
//   - light tracing's splat (t = 1) of a pending vertex: set 0 (the camera);
//   - next-event estimation at a camera medium vertex (s = 1) and emission found past one
//     (s = 0): the camera path's PathState::recv_set, as pt.
// Shadow linking and a lamp's Cast Shadow off in media stay with pt (allocation.cpp): pt's
// shadow rays through media ignore blocker sets (pt_shadow_medium), which no technique here
// reproduces without its weights.
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
LANTERN_HD inline int camera_medium_tri(const SceneView& s, const PathState& ps, int i) {
    return s.light_receivers && ps.recv_set ? -2 - int(ps.recv_set[i]) : -1;
}

// Whether light li lights slot i's camera medium vertex (s = 1): the set its path last left.
LANTERN_HD inline bool camera_medium_links(const SceneView& s, const PathState& ps, int i,
                                           int li) {
    return !s.light_receivers || !ps.recv_set || pt_light_links(s, li, ps.recv_set[i]);
}

}  // namespace lantern
