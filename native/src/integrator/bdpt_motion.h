// Motion blur in the bidirectional stages (bdpt, lvc, cis; docs/motion_blur.md): the time of a
// path pair, and the camera and surfaces at that time. A stage recomputes the time from the
// path index it already has: nothing is stored per slot, and scenes without motion never call
// anything here (their bits stay).
#pragma once

#include "integrator/bdpt_common.h"
#include "integrator/motion_stage.h"

namespace lantern {

// The time of camera path `path` and of the light path it connects to. bdpt: the camera
// path's own (pt's: Rng::for_camera's stream, so its camera sample and time are pt's); its
// paired light path j = path takes the same. lvc, cis: the pass's, shared by all its light and
// camera paths (the cache is shared by every camera path of the pass).
LANTERN_HD inline float bdpt_time(const BdptSettings& st, int64_t path) {
    return st.mode == kBdptOwnPath
               ? motion_time(Rng::for_camera(st.seed, st.iteration, st.spp_per_iteration, path))
               : motion_pass_time(st.seed, st.iteration);
}

// The time at which path `path` meets a moving emitter (its next event's light sample, an
// emission hit's densities: scene/lights.h): bdpt_time where meshes move, else 0 (unread:
// lights do not move, and still scenes skip the time's hashing).
LANTERN_HD inline float bdpt_emitter_time(const SceneView& s, const BdptSettings& st,
                                          int64_t path) {
    return s.motion.num_objects > 0 ? bdpt_time(st, path) : 0.0f;
}

// A triangle's hit for path `path`: moved to its time where meshes move.
LANTERN_HD inline SurfaceHit bdpt_surface(const SceneView& s, const BdptSettings& st,
                                          int64_t path, int tri, Vec2 uv, Vec3 d) {
    if (s.motion.num_objects > 0) return surface_moved_at(s, tri, uv, d, bdpt_time(st, path));
    return pt_surface(s, tri, uv, d);
}

// The camera at path `path`'s time (a moving camera).
LANTERN_HD inline CameraView bdpt_camera_moved(const SceneView& s, const BdptSettings& st,
                                               int64_t path) {
    return camera_moved_at(s, bdpt_time(st, path));
}

}  // namespace lantern
