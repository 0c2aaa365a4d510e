// Motion blur on the medium rays of lt, bdpt, lvc and cis (docs/motion_blur.md "Volumes"): a
// volume boundary crossed where its mesh is at the path's time, and that time for the light
// and camera sub-paths' crossings and for the connecting segments through media (bdpt_medium.h's
// bdpt_medium_shadow, lt's camera segments). One time per path, the surfaces' (bdpt_motion.h's
// bdpt_time, used by bdpt_medium.h's bdpt_cross_boundary; lt: motion_time of its stream). Still scenes never call the moved branches.
#pragma once

#include "integrator/pt_volume.h"

namespace lantern {

// A medium ray's time: the path's, or 0 under the test hook (MotionView::media_untimed).
LANTERN_HD inline float medium_ray_time(const SceneView& s, float time) {
    return s.motion.media_untimed ? 0.0f : time;
}

// Whether a path's medium rays need its time: meshes or strands move. Never on the device:
// a scene with motion renders on the CPU (session.cpp), and the device build leaves these
// branches out so that its kernels' stacks stay as they were (docs/cuda_backend.md).
LANTERN_HD inline bool medium_rays_timed(const SceneView& s) {
#ifdef __CUDA_ARCH__
    (void)s;
    return false;
#else
    return s.motion.rays_timed();
#endif
}

// A ray (o, d) through medium med at `time`, as its density sees it: a moving heterogeneous
// volume's brought to its mesh's exported frame (scene/motion.h), any other unchanged.
LANTERN_HD inline void medium_frame_ray(const SceneView& s, int32_t med, float time, Vec3* o,
                                        Vec3* d) {
#ifndef __CUDA_ARCH__  // (medium_rays_timed)
    if (s.motion.medium_objects) medium_ray_exported(s.motion, med, time, o, d);
#endif
}

// The side a ray along d meets volume boundary tri from (front: against its winding's normal)
// and that normal (unit), with the mesh where it is at `time` (hit at uv).
struct BoundarySide {
    Vec3 ng;
    bool front;
};
LANTERN_HD inline BoundarySide boundary_side_at(const SceneView& s, int tri, Vec2 uv, Vec3 d,
                                                float time) {
#ifndef __CUDA_ARCH__  // (medium_rays_timed)
    if (s.motion.num_objects > 0 && object_motion_of(s.motion, tri)) {
        const SurfaceHit h = surface_moved_at(s, tri, uv, d, time);
        return BoundarySide{h.ng, h.front};
    }
#endif
    const Vec3 n = triangle_cross(s, tri);
    return BoundarySide{normalize(n), dot(n, d) <= 0.0f};
}

// pt_cross_boundary at a given time (the slot's traced ray reached volume boundary tri): a
// moving volume's boundary where it is then, else pt's own.
LANTERN_HD inline void cross_boundary_at(const SceneView& s, const PathState& ps, int i, int tri,
                                         float time) {
#ifdef __CUDA_ARCH__  // (medium_rays_timed)
    const bool moves = false;
#else
    const bool moves = s.motion.num_objects > 0 && object_motion_of(s.motion, tri);
#endif
    if (!moves) {
        pt_cross_boundary(s, ps, i, tri);
        return;
    }
    const Vec3 d = ps.ray_d[i];
    const SurfaceHit h = surface_moved_at(s, tri, ps.hit_uv[i], d, time);
    ps.medium[i] = medium_across(s, tri, h.front, ps.medium[i]);
    ps.ray_o[i] = offset_ray_origin(h.p, h.ng, d, s.offset_scale);
    ps.ray_tmin[i] = 0.0f;
    const float tmax = ps.ray_tmax[i];
    ps.ray_tmax[i] = tmax < kInf ? fmaxf(tmax - ps.hit_t[i], 0.0f) : kInf;
    ps.alive[i] = 1;
}

}  // namespace lantern
