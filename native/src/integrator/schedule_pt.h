// The path tracer's chunk (integrator "pt"), for every executor: generate camera paths, then per
// bounce trace, shade, test the next-event shadow rays, compact (wavefront.h).
#pragma once

#include "integrator/pt.h"
#include "integrator/wavefront.h"

namespace lantern {
namespace wf {

// A next-event shadow ray at its path's time (motion blur, scene/motion.h; in a scene with
// media pt_shadow_medium's, which takes the path's time itself).
template <class Rays>
LANTERN_HD inline void pt_shadow_at_time(const SceneView& s, const Rays& rays, const PathState& ps,
                                         int i) {
    if (!ps.shadow_valid[i]) return;
    Ray r{ps.shadow_o[i], ps.shadow_d[i], 0.0f, ps.shadow_tmax[i]};
    r.time = motion_time(ps.rng[i]);
    if (s.light_blockers)  // shadow linking: pt_light_linking.h
        pt_shadow_result_linked(ps, i, pt_shadow_linked_query(s, rays, RayKind::kShadow, ps, i, r));
    else
        pt_shadow_result(ps, i, rays.occluded(r, RayKind::kShadow));
}

// The chunk's stages as variant F (pt_features.h): the features the scene may use.
template <uint32_t F, class Exec>
void pt_chunk_variant(Exec& ex, Wavefront<Exec>& w, const SceneView s, WavefrontStep& st,
                      int64_t first_path, int n) {
    w.media = s.num_media > 0;
    w.linked = s.light_blockers != nullptr;  // PathState::shadow_mis
    w.resize(n, 0, Exec::kGpu);
    SessionStats& stats = *st.stats;
    const PathState ps = w.ps;
    const PtSettings pt = st.pt_settings();
    const auto rays = ex.rays();
    int32_t* q0 = w.queue.data();
    const int32_t* list = st.pixel_list;  // adaptive sampling's pixels, or null: all
    const int spp = pt.spp_per_iteration;
    // slots are chunk-local; the path's global index drives its random stream and pixel
    ex.timed(stats.time_generate, [&] {
        ex.each(n, LANTERN_KERNEL(int i) {
            pt_generate<F>(s, ps, pt, i, camera_path(list, spp, first_path + i));
            q0[i] = i;
        });
    });
    int active = n;
    stats.rays_camera += n;
    bool first = true;
    while (active > 0 && !st.cancelled()) {
        const bool motion = (F & kPtMotion) && s.motion.rays_timed();
        trace(ex, w, active, first, stats, motion);
        const int32_t* q = w.queue.data();
        ex.timed(stats.time_shade, [&] {
            ex.each(active, LANTERN_KERNEL(int k) { pt_shade<F>(s, ps, pt, q[k]); });
        });
        // the walks of the paths that went under a surface (pt_sss.h)
        if ((F & kPtSubsurface) && s.has_subsurface)
            ex.timed(stats.time_shade, [&] {
                ex.each(active, LANTERN_KERNEL(int k) { pt_sss_walk(s, rays, RayKind::kIndirect, ps, pt, q[k]); });
            });
        ex.timed(stats.time_shadow, [&] {
            stats.rays_shadow +=
                ex.count(active, LANTERN_KERNEL(int k) { return ps.shadow_valid[q[k]] != 0; });
            if (s.num_media > 0)  // media's equiangular shadow rays (pt_volume.h)
                stats.rays_shadow += ex.count(
                    active, LANTERN_KERNEL(int k) { return ps.vshadow_valid[q[k]] != 0; });
            if (motion) {  // motion blur: each at its path's time
                ex.each(active, LANTERN_KERNEL(int k) {
                    if (s.num_media > 0)
                        pt_shadow_medium(s, rays, RayKind::kShadow, ps, q[k]);
                    else
                        pt_shadow_at_time(s, rays, ps, q[k]);
                });
                return;
            }
            ex.each(active, LANTERN_KERNEL(int k) {
                const int i = q[k];
                if (s.num_media > 0) {  // through media and volume boundaries (pt_volume.h)
                    pt_shadow_medium(s, rays, RayKind::kShadow, ps, i);
                    return;
                }
                if (!ps.shadow_valid[i]) return;
                const Ray r{ps.shadow_o[i], ps.shadow_d[i], 0.0f, ps.shadow_tmax[i]};
                if ((F & kPtLinks) && s.light_blockers)  // shadow linking
                    pt_shadow_result_linked(
                        ps, i, pt_shadow_linked_query(s, rays, RayKind::kShadow, ps, i, r));
                else
                    pt_shadow_result(ps, i, rays.occluded(r, RayKind::kShadow));
            });
        });
        active = compact(ex, w, active);
        if (active) stats.rays_indirect += active;
        first = false;
    }
    if (st.cancelled()) return;
    film(ex, w, st, first_path, n);
}

// A scene without any of the features runs the stages compiled without their tests; the GPU
// builds the general variant only (one set of kernels).
template <class Exec>
void pt_chunk(Exec& ex, Wavefront<Exec>& w, const SceneView s, WavefrontStep& st,
              int64_t first_path, int n) {
    if constexpr (!Exec::kGpu) {
        if (pt_features(s) == 0) return pt_chunk_variant<0>(ex, w, s, st, first_path, n);
    }
    pt_chunk_variant<kPtAll>(ex, w, s, st, first_path, n);
}

}  // namespace wf
}  // namespace lantern
