// Light linking in pt (Cycles' Object > Shading > Light Linking > Receiver collection): light l
// lights a surface of receiver set r only where bit r of SceneView::light_receivers[l] is set.
// Next-event estimation picks lights as before (the tree knows no sets) and finds nothing from
// an unlinked one; emission a bounce ray finds counts only where the light lights the set of the
// vertex the ray left (PathState::recv_set). Both strategies then estimate the same integral,
// and their MIS weights, over the same picks, still sum to one. Camera rays see every emitter.
#pragma once

#include "integrator/path_state.h"
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

}  // namespace lantern
