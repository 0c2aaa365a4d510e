// pt in a heterogeneous medium (scene/medium_hetero.h, docs/volumes.md): per traced segment a
// spectral tracking to the next real scattering event, the medium's emission and the lights the
// segment crosses estimated along it with the tracking's weights, and at the event a medium
// vertex (next-event estimation by the light tree against the phase sample; no equiangular
// sampling: the tracking's free-flight pdf has no closed form). Included by pt_volume.h after
// pt_medium_vertex, which it uses.
#pragma once

#include "scene/medium_hetero.h"

namespace lantern {

// ---- The traced segment in heterogeneous medium med; true when the path scattered inside it
// (this stage then shaded the medium vertex) ----
#ifndef __CUDA_ARCH__
__attribute__((noinline))
#endif
LANTERN_HD inline bool pt_hetero_segment(const SceneView& s, const PathState& ps,
                                         const PtSettings& st, int i, bool catcher_camera) {
    const int32_t med = ps.medium[i];
    const Medium& m = s.media[med];
    const Vec3 o0 = ps.ray_d[i] * ps.ray_tmin[i] + ps.ray_o[i], d = ps.ray_d[i];
    const float tmin = ps.ray_tmin[i];
    const float t_end = ps.hit_prim[i] >= 0 ? ps.hit_t[i] : ps.ray_tmax[i];
    const float len = fmaxf(t_end - tmin, 0.0f);
    const Vec3 beta = ps.throughput[i];
    ps.vshadow_valid[i] = 0;
    Rng rng = ps.rng[i];
    Rng tr = medium_tracking_rng(rng, 0);
    rng.uniform();  // the next segment's tracking starts a block of its own
    const bool emits = m.emits && !catcher_camera;
    const bool camera = ps.depth[i] <= 1;
    const bool lights = !catcher_camera && s.num_hittable_lights > 0;
    Vec3 fo = o0, fd = d;  // where the density is: a moving volume's exported frame (motion.h)
#ifndef __CUDA_ARCH__  // (motion blur renders on the CPU only, session.cpp: the kernel's stack)
    if (s.motion.medium_objects)
        medium_ray_exported(s.motion, med, motion_time(ps.rng[i]), &fo, &fd);
#endif
    const HeteroStep step = medium_track(
        s, m, med, fo, fd, len, beta, tr,
        [&](float t, Vec3 w, float mu) {
            if (emits)
                add_radiance(ps, i, beta * w * medium_emission_at(s, m, med, fo + fd * t) / mu);
        },
        [&](float a, float b, Vec3 w) {
            if (!lights || is_black(w)) return;
            for (int k = 0; k < s.num_hittable_lights; ++k) {
                const Light& l = s.lights[s.hittable_lights[k]];
                if (camera && !l.visible_camera) continue;
                if (pt_lamp_unseen(s, ps, i, s.hittable_lights[k])) continue;
                const LightHit h = intersect_light(l, o0, d, a, b);
                if (!h.hit || is_black(h.le)) continue;
                const float pdf = pt_light_pdf_w(s, ps, i, l, o0, d, h.t, h.n);
                add_radiance(ps, i, beta * w * h.le *
                                        pt_emission_weight(s, ps, i, s.hittable_lights[k], pdf));
            }
        });
    ps.throughput[i] = beta * step.weight;
    if (step.scattered)
        pt_medium_vertex(s, ps, st, i, o0 + d * step.t, d, m, 1.0f, rng);
    ps.rng[i] = rng;
    return step.scattered;
}

}  // namespace lantern
