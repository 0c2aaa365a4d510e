// The light tracer's chunk (integrator "lt"), for every executor: generate light paths, then per
// bounce test the camera segments, splat the visible ones (in slot order on the CPU: the same
// bits for any thread count), compact, trace and shade (wavefront.h).
#pragma once

#include "integrator/lt.h"
#include "integrator/wavefront.h"
#include "integrator/wavefront_motion.h"

namespace lantern {
namespace wf {

// Light tracing's camera segments in a scene with media (lt_medium.h): each carries the
// transmittance of the media it crosses from its vertex's medium (PathState::shadow_medium),
// multiplied into its contribution; blocked by any surface but a volume boundary; at its light
// path's time (motion blur).
template <class Exec>
int64_t camera_segments_medium(Exec& ex, Wavefront<Exec>& w, const SceneView& s, int n,
                               SessionStats& stats) {
    const PathState ps = w.ps;
    const int32_t* q = w.queue.data();
    uint8_t* vis = w.visible.data();
    const auto rays = ex.rays();
    int64_t tested = 0;
    ex.timed(stats.time_shadow, [&] {
        tested = ex.count(n, LANTERN_KERNEL(int k) { return ps.shadow_valid[q[k]] != 0; });
        ex.each(n, LANTERN_KERNEL(int k) {
            const int i = q[k];
            uint8_t v = 0;
            if (ps.shadow_valid[i]) {
                const float time = medium_rays_timed(s)  // (its light path's: LtTimeOf)
                                       ? medium_ray_time(s, motion_time(ps.rng[i]))
                                       : 0.0f;
                const Vec3 tr = pt_shadow_transmittance(s, rays, RayKind::kCamera, ps.shadow_o[i],
                                                        ps.shadow_d[i], ps.shadow_tmax[i],
                                                        ps.shadow_medium[i], &ps.rng[i], 1u,
                                                        time);
                if (!is_black(tr)) {
                    ps.shadow_contrib[i] = ps.shadow_contrib[i] * tr;
                    v = 1;
                }
            }
            vis[i] = v;
        });
    });
    return tested;
}

template <class Exec>
void lt_chunk(Exec& ex, Wavefront<Exec>& w, const SceneView s, WavefrontStep& st,
              int64_t first_path, int n) {
    // (the first segment's walk through media: a shadow-linked light's, lt_medium.h)
    w.lt_walk = s.num_media > 0 && s.light_blockers != nullptr;
    w.resize(n, 0, Exec::kGpu);
    SessionStats& stats = *st.stats;
    const PathState ps = w.ps;
    const PtSettings pt = st.pt_settings();
    w.light_id.grow(size_t(n));  // (LightPathState::light)
    const LightPathState lp{w.power.data(), w.splat_xy.data(), w.light_id.data()};
    int32_t* q0 = w.queue.data();
    ex.timed(stats.time_generate, [&] {
        ex.each(n, LANTERN_KERNEL(int i) {
            lt_generate(s, ps, lp, pt, i, first_path + i);
            q0[i] = i;
        });
    });
    int active = n;
    const bool motion = s.motion.rays_timed();  // each ray at its path's time (motion blur)
    while (!st.cancelled()) {
        const auto segments_and_splat = [&] {
            stats.rays_shadow +=
                s.num_media > 0 ? camera_segments_medium(ex, w, s, active, stats)
                : motion        ? camera_segments_timed(ex, w, active, stats, LtTimeOf{ps})
                                : camera_segments(ex, w, active, stats);
            ex.timed(stats.time_film, [&] { splat(ex, w, s, st, active); });
        };
        segments_and_splat();
        if (s.has_subsurface) {  // the adjoint walks (lt_sss.h; a kernel of its own on a GPU),
                                 // then their exits' splats
            const int32_t* q = w.queue.data();
            const auto rays = ex.rays();
            ex.timed(stats.time_shade, [&] {
                ex.each(active, LANTERN_KERNEL(int k) {
                    lt_sss_walk(s, rays, RayKind::kIndirect, ps, lp, pt, q[k]);
                });
            });
            segments_and_splat();
        }
        active = compact(ex, w, active);
        if (active == 0) break;
        stats.rays_indirect += active;  // light rays
        trace(ex, w, active, false, stats, motion);  // (its time: motion_time of its stream)
        const int32_t* q = w.queue.data();
        ex.timed(stats.time_shade, [&] {
            ex.each(active, LANTERN_KERNEL(int k) { lt_shade(s, ps, lp, pt, q[k]); });
        });
    }
    count_dropped(ex, w, n, stats);
}

}  // namespace wf
}  // namespace lantern
