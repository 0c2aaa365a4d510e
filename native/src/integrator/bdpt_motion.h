// Motion blur in the bidirectional stages (bdpt, lvc, cis; docs/motion_blur.md): the time of a
// path pair, and the camera and surfaces at that time. A stage recomputes the time from the
// path index it already has: nothing is stored per slot, and scenes without motion never call
// anything here (their bits stay).
#pragma once

#include "integrator/bdpt_common.h"
#include "integrator/pt_surface.h"
#include "scene/motion.h"

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

// The triangle hit (tri, uv) of a ray along d at `time` where meshes move (scene/motion.h).
#ifndef __CUDA_ARCH__
__attribute__((noinline))
#endif
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline SurfaceHit bdpt_surface_moved(const SceneView& s, int tri, Vec2 uv, Vec3 d,
                                                float time) {
    return motion_surface<SurfaceHit>(
        s.motion, tri, uv, d, time, [&](Vec3 dx) { return pt_surface(s, tri, uv, dx); },
        [&](Vec3 e[3]) {
            for (int j = 0; j < 3; ++j) e[j] = s.positions[s.indices[3 * tri + j]];
        });
}

// A triangle's hit for path `path`: moved to its time where meshes move.
LANTERN_HD inline SurfaceHit bdpt_surface(const SceneView& s, const BdptSettings& st,
                                          int64_t path, int tri, Vec2 uv, Vec3 d) {
    if (s.motion.num_objects > 0) return bdpt_surface_moved(s, tri, uv, d, bdpt_time(st, path));
    return pt_surface(s, tri, uv, d);
}

// The camera at path `path`'s time (a moving camera), else the scene's.
#ifndef __CUDA_ARCH__
__attribute__((noinline))
#endif
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline CameraView bdpt_camera_moved(const SceneView& s, const BdptSettings& st,
                                               int64_t path) {
    return motion_camera(s.camera, s.motion, bdpt_time(st, path));
}

// A camera ray r of the still camera carried rigidly to where the camera is at `time` (the same
// draws and clip distances; pt_camera_ray_moved at a given time).
#ifndef __CUDA_ARCH__
__attribute__((noinline))
#endif
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline void bdpt_camera_ray_moved(const SceneView& s, float time, Vec3& o, Vec3& d) {
    Transform still_inv;
    if (!transform_inverse(s.camera.to_world, &still_inv)) return;
    const Transform m = transform_mul(
        motion_at(s.motion.steps, s.motion.camera_first, s.motion.camera_steps, time), still_inv);
    o = m.point(o);
    d = normalize(m.vector(d));
}

}  // namespace lantern
