// Motion blur in the light-path schedules (schedule_bdpt.h, schedule_lt.h): the closest hits and
// the camera segments of the queued slots, each ray at its path's time, time_of(slot) (a functor
// callable on the device). Scenes without moving meshes keep wavefront.h's own loops.
#pragma once

#include "integrator/bdpt_motion.h"
#include "integrator/wavefront.h"

namespace lantern {
namespace wf {

// The time of a slot of the bidirectional passes: its camera path's (through the adaptive
// list) or, in the light pass, its light path's (bdpt_motion.h).
struct BdptTimeOf {
    BdptSettings st;
    const int32_t* list;
    int spp;
    int64_t first_path;
    bool camera;
    LANTERN_HD float operator()(int i) const {
        return bdpt_time(st, camera ? camera_path(list, spp, first_path + i) : first_path + i);
    }
};

// lt's slot: its light path's own time, motion_time of its stream (trace's `motion` too).
struct LtTimeOf {
    PathState ps;
    LANTERN_HD float operator()(int i) const { return motion_time(ps.rng[i]); }
};

// wavefront.h's trace with each ray at time_of(slot).
template <class Exec, class TimeOf>
void trace_timed(Exec& ex, Wavefront<Exec>& w, int n, bool camera, SessionStats& stats,
                 const TimeOf time_of) {
    const PathState ps = w.ps;
    const int32_t* q = w.queue.data();
    auto hit = LANTERN_KERNEL(int k, float t, int32_t prim, Vec2 uv) {
        const int i = q[k];
        ps.hit_t[i] = t;
        ps.hit_prim[i] = prim;
        ps.hit_uv[i] = uv;
    };
    const RayKind kind = camera ? RayKind::kCamera : RayKind::kIndirect;
    ex.timed(stats.time_trace, [&] {
        ex.closest(
            n, kind,
            LANTERN_KERNEL(int k) {
                const int i = q[k];
                Ray r{ps.ray_o[i], ps.ray_d[i], ps.ray_tmin[i], ps.ray_tmax[i]};
                r.time = time_of(i);
                return r;
            },
            hit);
    });
}

// wavefront.h's camera_segments with each segment at time_of(slot).
template <class Exec, class TimeOf>
int64_t camera_segments_timed(Exec& ex, Wavefront<Exec>& w, int n, SessionStats& stats,
                              const TimeOf time_of) {
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
                Ray r{ps.shadow_o[i], ps.shadow_d[i], 0.0f, ps.shadow_tmax[i]};
                r.time = time_of(i);
                v = rays.occluded(r, RayKind::kCamera) ? 0 : 1;
            }
            vis[i] = v;
        });
    });
    return tested;
}

}  // namespace wf
}  // namespace lantern
