// The path tracer's and the light tracer's chunks on the GPU (session.cpp, lt_session.cpp).
#include "backend/cuda/renderer.cuh"

namespace lantern {
namespace cuda_detail {

void Renderer::run_pt_chunk(int64_t first_path, int n) {
    ensure_state(n, 0);
    const SceneView s = sv_;
    const PathState ps = ps_;
    const PtSettings st = pt_settings();
    const Tracer tr = tracer_;
    unsigned long long* shadow_ctr = counters_.data() + kCtrShadow;
    int32_t* q0 = queue_.data();
    timed(stats_->time_generate, [&] {
        each(stream_, n, [=] __device__(int i) {
            pt_generate(s, ps, st, i, first_path + i);
            q0[i] = i;
        });
    });
    int active = n;
    stats_->rays_camera += n;
    bool first = true;
    while (active > 0 && !cancel_->load()) {
        trace(active, first ? kBvhNeedCamera : kBvhNeedIndirect);
        const int32_t* q = queue_.data();
        timed(stats_->time_shade,
              [&] { each(stream_, active, [=] __device__(int k) { pt_shade(s, ps, st, q[k]); }); });
        timed(stats_->time_shadow, [&] {
            each(stream_, active, [=] __device__(int k) {
                const int i = q[k];
                if (!ps.shadow_valid[i]) return;
                warp_count(shadow_ctr);
                const Ray r{ps.shadow_o[i], ps.shadow_d[i], 0.0f, ps.shadow_tmax[i]};
                pt_shadow_result(ps, i, tr.blocked(r, kBvhNeedShadow));
            });
        });
        active = compact(active);
        if (active) stats_->rays_indirect += active;
        first = false;
    }
    if (cancel_->load()) return;
    film(first_path, n);
}

void Renderer::run_lt_chunk(int64_t first_path, int n) {
    ensure_state(n, 0);
    const SceneView s = sv_;
    const PathState ps = ps_;
    const PtSettings st = pt_settings();
    const LightPathState lp{power_.data(), splat_xy_.data()};
    int32_t* q0 = queue_.data();
    timed(stats_->time_generate, [&] {
        each(stream_, n, [=] __device__(int i) {
            lt_generate(s, ps, lp, st, i, first_path + i);
            q0[i] = i;
        });
    });
    int active = n;
    while (!cancel_->load()) {
        stats_->rays_shadow += test_camera_segments(active);
        timed(stats_->time_film, [&] { splat(active); });
        active = compact(active);
        if (active == 0) break;
        stats_->rays_indirect += active;
        trace(active, kBvhNeedIndirect);
        const int32_t* q = queue_.data();
        timed(stats_->time_shade,
              [&] { each(stream_, active, [=] __device__(int k) { lt_shade(s, ps, lp, st, q[k]); }); });
    }
    count_dropped(n);
}

}  // namespace cuda_detail
}  // namespace lantern
