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
// triangles whose shadow set (SceneView::tri_shadow_set) is in SceneView::light_blockers[l].
// A bounce ray cannot see such a light through a surface that casts it no shadow, so for a
// shadow-linked light next-event estimation is the only strategy (MIS weight 1; emission a
// bounce ray finds after a non-delta vertex weighs 0): still unbiased where next-event
// estimation can sample the light; after a delta vertex the bounce ray's hit counts, seen past
// no surface (Cycles traces a dedicated ray there). ----
namespace lantern {

LANTERN_HD inline bool pt_shadow_linked(const SceneView& s, int li) {
    return s.light_blockers && li >= 0 && s.light_blockers[li] != kAllReceivers;
}

// Slot i's next-event shadow ray towards light li: whether anything that casts li's shadow
// blocks segment r (Rays: the executor's ray query, kind its shadow rays' RayKind; any surface
// without linking).
template <class Rays, class Kind>
LANTERN_HD inline bool pt_occluded_linked(const SceneView& s, const Rays& rays, Kind kind,
                                          const PathState& ps, int i, Ray r) {
    if (!s.light_blockers || !ps.shadow_light) return rays.occluded(r, kind);  // the usual
    const int li = ps.shadow_light[i];
    if (!pt_shadow_linked(s, li)) return rays.occluded(r, kind);
    const uint64_t mask = s.light_blockers[li];
    for (int k = 0; k < 256; ++k) {  // surfaces passed (a bound: never an endless loop)
        const auto h = rays.closest(r, kind);
        if (h.prim < 0 || !(h.t < r.tmax)) return false;
        const int set = s.tri_shadow_set ? int(s.tri_shadow_set[h.prim]) : 0;
        if ((mask >> set) & 1u) return true;
        Vec3 ng = r.d;  // a strand (pt_curve.h): passed along the ray
        if (h.prim < s.num_triangles) {
            const Vec3 a = triangle_vertex(s, h.prim, 0), b = triangle_vertex(s, h.prim, 1),
                       c = triangle_vertex(s, h.prim, 2);
            ng = normalize(cross(b - a, c - a));
        }
        const Vec3 next = offset_ray_origin(r.o + r.d * h.t, ng, r.d, s.offset_scale);
        if (r.tmax < kInf) r.tmax = fmaxf(r.tmax - dot(next - r.o, r.d), 0.0f);
        r.o = next;
        r.tmin = 0.0f;
    }
    return true;
}

}  // namespace lantern
