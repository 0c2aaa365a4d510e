// The bidirectional integrators on the GPU: an iteration (pilot, light pass, cache index,
// camera pass) and the light pass's chunks (bdpt_session.cpp).
#include "backend/cuda/renderer.cuh"

namespace lantern {
namespace cuda_detail {

bool Renderer::run_bdpt_iteration() {
    const int spp_it = set_.spp_per_iteration;
    const int64_t light_paths = int64_t(width_) * height_ * spp_it;
    auto t = Clock::now();
    mis_r_ = mode_ == kBdptOwnPath || !(vertices_per_path_ > 0.0)
                 ? 1.0f
                 : float(set_.connections / vertices_per_path_);
    // the cache starts at the capacity the measured rate predicts (integrator/wavefront_cache.h)
    pass_light_paths_ = light_paths;
    for (auto* a : {&path_key_, &path_key_out_, &path_vertex_, &path_vertex_in_, &path_offset_})
        a->release();  // the last pass's bdpt index
    const size_t want =
        cache_initial_capacity(vertices_per_path_, light_paths, cache_budget_, cache_costs_);
    if (cache_.capacity() < want ||
        cache_.capacity() > cache_max_vertices(cache_budget_, cache_costs_, double(light_paths)))
        cache_.release();  // empty: released before the new one, never both at once
    cache_.grow(want);
    cache_size_ = 0;
    for (int64_t p0 = 0; p0 < light_paths; p0 += chunk_paths_) {
        run_light_chunk(p0, int(std::min<int64_t>(chunk_paths_, light_paths - p0)));
        if (cancel_->load()) return false;
    }
    stats_->cache_vertices = cache_size_;
    vertices_per_path_ = double(cache_size_) / double(light_paths);
    stats_->time_light_pass += seconds_since(t);
    t = Clock::now();
    if (mode_ == kBdptOwnPath) index_cache_by_path(light_paths);
    stats_->time_cache += seconds_since(t);
    t = Clock::now();
    conn_cap_ = mode_ == kBdptOwnPath ? std::max(1, set_.max_depth - 1) : set_.connections;
    const int64_t pixels = int64_t(width_) * height_;
    const int chunk = std::max(spp_it, std::min(chunk_paths_, kGpuShadowBudget / conn_cap_));
    const int64_t chunk_pixels = std::max<int64_t>(1, chunk / spp_it);
    for (int64_t q0 = 0; q0 < pixels; q0 += chunk_pixels) {
        const int64_t np = std::min(chunk_pixels, pixels - q0);
        run_camera_chunk(q0 * spp_it, int(np * spp_it));
        if (cancel_->load()) return false;
    }
    stats_->time_camera_pass += seconds_since(t);
    return true;
}

// bdpt: the vertices of light path j are path_vertex[path_offset[j] .. path_offset[j + 1]), in
// cache order (a stable sort of cache indices by path, then a binary search per path).
void Renderer::index_cache_by_path(int64_t light_paths) {
    const int nv = int(cache_size_);
    const int np = int(light_paths);
    path_offset_.grow(size_t(np) + 1);
    path_key_.grow(std::max(nv, 1));
    path_key_out_.grow(std::max(nv, 1));
    path_vertex_.grow(std::max(nv, 1));
    path_vertex_in_.grow(std::max(nv, 1));
    const LightVertex* cache = cache_.data();
    int32_t* key = path_key_.data();
    int32_t* idx = path_vertex_in_.data();
    each(stream_, nv, [=] __device__(int k) {
        key[k] = cache[k].path;
        idx[k] = k;
    });
    if (nv > 0) {
        const int end_bit = bits_for(uint32_t(np));
        cub_run("DeviceRadixSort", [&](void* t, size_t& bytes) {
            return cub::DeviceRadixSort::SortPairs(t, bytes, key, path_key_out_.data(), idx,
                                                   path_vertex_.data(), nv, 0, end_bit, stream_);
        });
    }
    const int32_t* sorted = path_key_out_.data();
    int32_t* off = path_offset_.data();
    each(stream_, np + 1, [=] __device__(int j) {
        int lo = 0, hi = nv;  // first sorted key >= j
        while (lo < hi) {
            const int mid = (lo + hi) >> 1;
            if (sorted[mid] < j) lo = mid + 1; else hi = mid;
        }
        off[j] = lo;
    });
    check(cudaStreamSynchronize(stream_), "cache index");
}

// The pilot: a small light pass with its own random numbers, stored nowhere (bdpt_session.cpp).
void Renderer::measure_cache_rate() {
    const int64_t light_paths = int64_t(width_) * height_ * set_.spp_per_iteration;
    const int pilot = int(std::min<int64_t>(light_paths, 1 << 14));
    pilot_ = true;
    run_light_chunk(0, pilot);
    pilot_ = false;
    if (!cancel_->load()) vertices_per_path_ = double(pilot_count_) / pilot;
}

void Renderer::run_light_chunk(int64_t first_path, int n) {
    ensure_state(n, 0);  // the light pass queues no connections
    const SceneView s = sv_;
    BdptSettings st = bdpt_settings();
    if (pilot_) {
        st.iteration = ~uint64_t(0);
        pilot_count_ = 0;
    }
    const PathState ps = ps_;
    const BdptState bs = bs_;
    int32_t* q0 = queue_.data();
    timed(stats_->time_generate, [&] {
        each(stream_, n, [=] __device__(int i) {
            bdpt_light_generate(s, ps, bs, st, i, first_path + i);
            q0[i] = i;
        });
    });
    int active = compact(n);
    while (active > 0 && !cancel_->load()) {
        stats_->rays_light += active;
        trace(active, kBvhNeedIndirect);
        sort_queue(active);
        const int32_t* q = queue_.data();
        timed(stats_->time_shade, [&] {
            each(stream_, active, [=] __device__(int k) {
                const int i = q[k];
                bdpt_light_shade(s, ps, bs, st, i, first_path + i);
            });
        });
        // store vertices in queue order: positions by an exclusive scan of the store flags
        auto t = Clock::now();
        int32_t* f = store_flag_.data();  // int: CUB sums in the input's type
        int32_t* pos = scan_.data();
        const uint8_t* store = bs.store;
        each(stream_, active, [=] __device__(int k) { f[k] = store[q[k]]; });
        cub_run("DeviceScan", [&](void* t, size_t& bytes) {
            return cub::DeviceScan::ExclusiveSum(t, bytes, f, pos, active, stream_);
        });
        int* total = small_.data() + 2;
        const int last = active - 1;
        each(stream_, 1, [=] __device__(int) { *total = pos[last] + f[last]; });
        const int add = read_int(total);
        if (pilot_) {
            pilot_count_ += add;
            active = compact(active);
            continue;
        }
        if (size_t(cache_size_ + add) > cache_.capacity()) {  // exact, or CacheOverBudget
            cache_.grow(cache_grow_capacity(size_t(cache_size_ + add), cache_.capacity(),
                                            first_path + n, pass_light_paths_, cache_budget_,
                                            cache_costs_),
                        size_t(cache_size_), stream_);
        }
        LightVertex* dst = cache_.data() + cache_size_;
        const LightVertex* vtx = bs.vertex;
        each(stream_, active, [=] __device__(int k) {
            if (f[k]) dst[pos[k]] = vtx[q[k]];
        });
        cache_size_ += add;
        check(cudaStreamSynchronize(stream_), "cache store");
        stats_->time_cache += seconds_since(t);
        stats_->rays_light_tracing += test_camera_segments(active);
        timed(stats_->time_splat, [&] { splat(active); });
        active = compact(active);
    }
    count_dropped(n);
}

}  // namespace cuda_detail
}  // namespace lantern
