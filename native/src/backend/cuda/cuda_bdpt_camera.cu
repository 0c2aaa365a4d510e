// The camera pass of the bidirectional integrators on the GPU: shade (emission, next event,
// connections to the light vertex cache), then every shadow ray of the bounce as one batch.
#include "backend/cuda/renderer.cuh"

namespace lantern {
namespace cuda_detail {

void Renderer::run_camera_chunk(int64_t first_path, int n) {
    ensure_state(n, conn_cap_);
    const SceneView s = sv_;
    const BdptSettings st = bdpt_settings();
    const PathState ps = ps_;
    const BdptState bs = bs_;
    const Tracer tr = tracer_;
    const LightCache cache{cache_.data(), int32_t(cache_size_),
                           mode_ == kBdptOwnPath ? path_offset_.data() : nullptr,
                           mode_ == kBdptOwnPath ? path_vertex_.data() : nullptr};
    int32_t* q0 = queue_.data();
    timed(stats_->time_generate, [&] {
        each(stream_, n, [=] __device__(int i) {
            bdpt_camera_generate(s, ps, bs, st, i, first_path + i);
            q0[i] = i;
        });
    });
    int active = n;
    stats_->rays_camera += n;
    bool first = true;
    uint8_t* vis = conn_vis_.data();
    unsigned long long* ctr = counters_.data();
    while (active > 0 && !cancel_->load()) {
        trace(active, first ? kBvhNeedCamera : kBvhNeedIndirect);
        sort_queue(active);
        const int32_t* q = queue_.data();
        timed(stats_->time_shade, [&] {
            each(stream_, active, [=] __device__(int k) {
                const int i = q[k];
                bdpt_camera_shade(s, ps, bs, st, cache, i, first_path + i);
            }, 64);
        });
        // every shadow ray of the bounce, one thread each: [next event, connections...] per slot
        const int per = bs.conn_cap + 1;
        timed(stats_->time_shadow, [&] {
            each(stream_, active * per, [=] __device__(int e) {
                const int k = e / per, j = e - k * per;
                const int i = q[k];
                uint8_t v = 0;
                if (j == 0) {
                    if (ps.shadow_valid[i]) {
                        warp_count(ctr + kCtrShadow);
                        const Ray r{ps.shadow_o[i], ps.shadow_d[i], 0.0f, ps.shadow_tmax[i]};
                        v = tr.blocked(r, kBvhNeedShadow) ? 0 : 1;
                    }
                } else if (j - 1 < bs.conn_n[i]) {
                    warp_count(ctr + kCtrConnection);
                    const size_t c = size_t(i) * bs.conn_cap + (j - 1);
                    const Ray r{bs.conn_o[c], bs.conn_d[c], 0.0f, bs.conn_tmax[c]};
                    v = tr.blocked(r, kBvhNeedShadow) ? 0 : 1;
                }
                vis[e] = v;
            });
            each(stream_, active, [=] __device__(int k) {
                const int i = q[k];
                const uint8_t* v = vis + size_t(k) * per;
                if (v[0]) add_radiance(ps, i, ps.shadow_contrib[i]);
                for (int j = 0; j < bs.conn_n[i]; ++j)
                    if (v[1 + j]) add_radiance(ps, i, bs.conn_c[size_t(i) * bs.conn_cap + j]);
            });
        });
        active = compact(active);
        if (active) stats_->rays_indirect += active;
        first = false;
    }
    if (cancel_->load()) return;
    film(first_path, n);
}

// Out of memory inside a step: the step starts again with half as many paths in flight (the
// wavefront state shrinks with them), down to kGpuMinChunkPaths; only then does the session
// hear of it (and go on on the CPU).
}  // namespace cuda_detail
}  // namespace lantern
