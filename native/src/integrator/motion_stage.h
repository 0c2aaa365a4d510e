// Motion blur in the light-path stages (lt.h, bdpt_motion.h; docs/motion_blur.md): a triangle's
// hit, the camera and a camera ray at a given shutter time. Out of line on the host and the
// device, so that the stages' still paths stay as they were; scenes without motion never call
// them.
#pragma once

#include "integrator/pt_surface.h"
#include "scene/motion.h"

namespace lantern {

// The triangle hit (tri, uv) of a ray along d at `time` where meshes move (scene/motion.h).
#ifndef __CUDA_ARCH__
__attribute__((noinline))
#endif
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline SurfaceHit surface_moved_at(const SceneView& s, int tri, Vec2 uv, Vec3 d,
                                              float time) {
    return motion_surface<SurfaceHit>(
        s.motion, tri, uv, d, time, [&](Vec3 dx) { return pt_surface(s, tri, uv, dx); },
        [&](Vec3 e[3]) {
            for (int j = 0; j < 3; ++j) e[j] = s.positions[s.indices[3 * tri + j]];
        });
}

// A triangle's hit at `time`: moved there where meshes move, else pt_surface's own (the walk
// under a surface, pt_sss.h: its entry and exit where the mesh is at the path's time).
LANTERN_HD inline SurfaceHit surface_at_time(const SceneView& s, int tri, Vec2 uv, Vec3 d,
                                             float time) {
    if (s.motion.num_objects > 0) return surface_moved_at(s, tri, uv, d, time);
    return pt_surface(s, tri, uv, d);
}

// The camera at `time` (a moving camera's interpolated to_world).
#ifndef __CUDA_ARCH__
__attribute__((noinline))
#endif
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline CameraView camera_moved_at(const SceneView& s, float time) {
    return motion_camera(s.camera, s.motion, time);
}

// A camera ray (o, d) of the still camera carried rigidly to where the camera is at `time` (the
// same draws and clip distances; pt_camera_ray_moved at a given time).
#ifndef __CUDA_ARCH__
__attribute__((noinline))
#endif
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline void camera_ray_moved_at(const SceneView& s, float time, Vec3& o, Vec3& d) {
    Transform still_inv;
    if (!transform_inverse(s.camera.to_world, &still_inv)) return;
    const Transform m = transform_mul(
        motion_at(s.motion.steps, s.motion.camera_first, s.motion.camera_steps, time), still_inv);
    o = m.point(o);
    d = normalize(m.vector(d));
}

}  // namespace lantern
