// The CUDA backend: the wavefront of session.cpp / bdpt_session.cpp / lt_session.cpp on the GPU.
// The stages are the host+device functions the CPU runs (integrator/pt.h, lt.h, bdpt.h), each
// launched as a kernel over a device queue of path slots; the BVH is accel/bvh.h, built on the
// host and copied as it is. What differs from the CPU schedule, and why:
//  - queues are compacted with CUB's stable DeviceSelect and sorted with a stable radix sort of
//    the paper's material key (type above id) on only the bits in use; the CPU sorts by type
//    alone and runs smaller chunks, so the cache's order, and with it which vertex a random
//    lvc/cis pick selects, differs from the CPU's: the same estimator, not the same samples
//  - the light vertex cache grows by an exclusive scan of the store flags (queue order, as on
//    the CPU) and, for bdpt, is indexed by light path with a radix sort instead of counting
//  - shadow rays of a camera bounce (next event + connections) are one batch of independent
//    rays, one thread each; a second kernel adds the unoccluded ones per slot in a fixed order
//  - light-tracing splats add into the iteration with double atomics: the image is the same
//    estimate, but its last bits depend on scheduling (the CPU's do not)
//  - the finished sum goes to pinned host memory on a copy stream; the next iteration's
//    kernels run while it drains, only the final add into the sum waits for it
// Every stage is timed with a stream synchronisation so that SessionStats' per-stage times are
// real; the synchronisation costs a few microseconds per stage and bounce.
#include "backend/cuda/renderer.cuh"

namespace lantern {
namespace cuda_detail {

__global__ void probe_kernel() {}

Renderer::Renderer(const HostScene& scene, const SessionSettings& settings,
                   std::vector<std::string>& warnings)
    : set_(settings) {
    try {
        use_device();
        cudaDeviceProp prop{};
        check(cudaGetDeviceProperties(&prop, device_), "cudaGetDeviceProperties");
        name_ = prop.name;
        size_t free_b = 0, total_b = 0;
        check(cudaMemGetInfo(&free_b, &total_b), "cudaMemGetInfo");
        free_at_start_ = int64_t(free_b);
        // the driver reserves each kernel's stack frame for every thread the card can hold, at
        // the kernel's first launch: set that much aside before the cache budget is taken
        stack_reserve_ = kShadeStackEstimate * int64_t(prop.maxThreadsPerMultiProcessor) *
                         int64_t(prop.multiProcessorCount);
        check(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking), "cudaStreamCreate");
        check(cudaStreamCreateWithFlags(&copy_stream_, cudaStreamNonBlocking), "cudaStreamCreate");
        check(cudaEventCreateWithFlags(&sum_ready_, cudaEventDisableTiming), "cudaEventCreate");
        check(cudaEventCreateWithFlags(&copy_done_, cudaEventDisableTiming), "cudaEventCreate");
        check(cudaEventRecord(copy_done_, copy_stream_), "cudaEventRecord");
        for (auto* a : {&ray_o_, &ray_d_, &throughput_, &radiance_, &shadow_o_, &shadow_d_,
                        &shadow_c_, &power_, &conn_o_, &conn_d_, &conn_c_})
            a->bind(&mem_);
        for (auto* a : {&ray_tmin_, &ray_tmax_, &prev_pdf_, &hit_t_, &shadow_tmax_, &dvcm_, &dvc_,
                        &conn_tmax_})
            a->bind(&mem_);
        for (auto* a : {&depth_, &hit_prim_, &queue_, &next_queue_, &scan_, &store_flag_, &light_id_, &conn_n_,
                        &path_key_, &path_key_out_, &path_vertex_, &path_vertex_in_, &path_offset_})
            a->bind(&mem_);
        for (auto* a : {&alive_, &dropped_, &shadow_valid_, &occluded_, &flags_, &store_,
                        &conn_vis_, &temp_})
            a->bind(&mem_);
        for (auto* a : {&hit_uv_, &splat_xy_}) a->bind(&mem_);
        for (auto* a : {&keys_, &keys_out_}) a->bind(&mem_);
        for (auto* a : {&vertex_, &cache_}) a->bind(&mem_);
        for (auto* a : {&iter_, &sum_}) a->bind(&mem_);
        rng_.bind(&mem_);
        small_.bind(&mem_);
        counters_.bind(&mem_);

        // the scene, array by array, then the BVH (built on the host, copied as it is)
        auto upload = [&](const void* host, size_t bytes) -> void* {
            if (!host || bytes == 0) return nullptr;
            void* d = nullptr;
            check(cudaMalloc(&d, bytes), "cudaMalloc (scene)");
            scene_mem_.push_back(d);
            mem_.add(int64_t(bytes));
            check(cudaMemcpy(d, host, bytes, cudaMemcpyHostToDevice), "cudaMemcpy (scene)");
            return d;
        };
        sv_ = scene.copied_view(upload);
        std::vector<std::string> bvh_warnings;
        Bvh bvh = build_bvh(scene.view(), BvhBuildOptions{}, bvh_warnings);
        for (auto& w : bvh_warnings) warnings.push_back(w);
        BvhView bv = bvh.view();
        bv.nodes = static_cast<const BvhNode*>(upload(bvh.nodes.data(), bvh.nodes.size() * sizeof(BvhNode)));
        bv.tris = static_cast<const BvhTri*>(upload(bvh.tris.data(), bvh.tris.size() * sizeof(BvhTri)));
        tracer_ = Tracer{bv, sv_};

        width_ = scene.view().camera.width;
        height_ = scene.view().camera.height;
        id_bits_ = bits_for(uint32_t(std::max(0, scene.view().num_materials - 1)));
        const size_t px3 = size_t(width_) * height_ * 3;
        sum_.grow(px3);
        iter_.grow(px3);
        check(cudaMemset(sum_.data(), 0, px3 * sizeof(double)), "cudaMemset");
        check(cudaMallocHost(&host_sum_, px3 * sizeof(double)), "cudaMallocHost");
        std::fill(host_sum_, host_sum_ + px3, 0.0);
        small_.grow(4);
        counters_.grow(kCtrCount);
        check(cudaMallocHost(&host_int_, 4 * sizeof(int)), "cudaMallocHost");
        check(cudaMallocHost(&host_counters_, kCtrCount * sizeof(unsigned long long)),
              "cudaMallocHost");
        check(cudaMemset(counters_.data(), 0, kCtrCount * sizeof(unsigned long long)), "cudaMemset");
        check(cudaDeviceSynchronize(), "scene upload");
    } catch (const std::runtime_error& e) {
        // a CUDA error while setting up means this GPU cannot render the scene: fall back
        release();
        throw CudaUnavailable(e.what());
    }
}

Renderer::~Renderer() { release(); }

void Renderer::release() {
    cudaSetDevice(device_);  // no throw: this runs in the destructor too
    if (stream_) cudaStreamSynchronize(stream_);
    if (copy_stream_) cudaStreamSynchronize(copy_stream_);
    for (void* p : scene_mem_) cudaFree(p);
    if (host_sum_) cudaFreeHost(host_sum_);
    if (host_int_) cudaFreeHost(host_int_);
    if (host_counters_) cudaFreeHost(host_counters_);
    if (sum_ready_) cudaEventDestroy(sum_ready_);
    if (copy_done_) cudaEventDestroy(copy_done_);
    if (stream_) cudaStreamDestroy(stream_);
    if (copy_stream_) cudaStreamDestroy(copy_stream_);
    scene_mem_.clear();
    host_sum_ = nullptr;
    host_int_ = nullptr;
    host_counters_ = nullptr;
    sum_ready_ = copy_done_ = nullptr;
    stream_ = copy_stream_ = nullptr;
}

int Renderer::read_int(const int* d) {
    check(cudaMemcpyAsync(host_int_, d, sizeof(int), cudaMemcpyDeviceToHost, stream_),
          "cudaMemcpyAsync");
    check(cudaStreamSynchronize(stream_), "cudaStreamSynchronize");
    return *host_int_;
}

void Renderer::ensure_state(int n, int conn_cap) {
    // conn_cap 0: no connection slots (pt, lt and the light pass never queue connections)
    if (n > state_cap_) {
        const size_t m = size_t(n);
        for (auto* a : {&ray_o_, &ray_d_, &throughput_, &radiance_, &shadow_o_, &shadow_d_,
                        &shadow_c_})
            a->grow(m);
        for (auto* a : {&ray_tmin_, &ray_tmax_, &prev_pdf_, &hit_t_, &shadow_tmax_}) a->grow(m);
        rng_.grow(m);
        for (auto* a : {&depth_, &hit_prim_, &queue_, &next_queue_, &scan_, &store_flag_}) a->grow(m);
        hit_uv_.grow(m);
        for (auto* a : {&alive_, &dropped_, &shadow_valid_, &occluded_, &flags_}) a->grow(m);
        power_.grow(m);
        splat_xy_.grow(m);
        keys_.grow(m);
        keys_out_.grow(m);
        if (bidirectional_) {
            dvcm_.grow(m);
            dvc_.grow(m);
            light_id_.grow(m);
            store_.grow(m);
            vertex_.grow(m);
            conn_n_.grow(m);
        }
        state_cap_ = n;
    }
    // connection slots are indexed by slot (< n): sized by this chunk, not the largest one
    const size_t nc = size_t(n) * size_t(conn_cap);
    if (bidirectional_ && conn_cap > 0 && nc > conn_o_.capacity()) {
        conn_o_.grow(nc);
        conn_d_.grow(nc);
        conn_c_.grow(nc);
        conn_tmax_.grow(nc);
    }
    if (bidirectional_ && conn_cap > 0) conn_vis_.grow(size_t(n) * (size_t(conn_cap) + 1));
    ps_ = PathState{ray_o_.data(),      ray_d_.data(),     ray_tmin_.data(),   ray_tmax_.data(),
                    throughput_.data(), radiance_.data(),  rng_.data(),        depth_.data(),
                    prev_pdf_.data(),   alive_.data(),     dropped_.data(),    hit_t_.data(),
                    hit_prim_.data(),   hit_uv_.data(),    shadow_o_.data(),   shadow_d_.data(),
                    shadow_tmax_.data(), shadow_c_.data(), shadow_valid_.data()};
    bs_ = BdptState{dvcm_.data(),     dvc_.data(),       light_id_.data(), store_.data(),
                    vertex_.data(),   splat_xy_.data(),  power_.data(),    std::max(conn_cap, 1),
                    conn_n_.data(),   conn_o_.data(),    conn_d_.data(),   conn_tmax_.data(),
                    conn_c_.data()};
}

// The queue's live slots (alive[slot]), in queue order, become the queue; returns their count.
int Renderer::compact(int n) {
    if (n <= 0) return 0;
    const uint8_t* alive = ps_.alive;
    const int32_t* q = queue_.data();
    uint8_t* f = flags_.data();
    each(stream_, n, [=] __device__(int k) { f[k] = alive[q[k]]; });
    cub_run("DeviceSelect", [&](void* t, size_t& bytes) {
        return cub::DeviceSelect::Flagged(t, bytes, q, f, next_queue_.data(), small_.data(), n,
                                          stream_);
    });
    const int m = read_int(small_.data());
    queue_.swap(next_queue_);
    return m;
}

// Sorts the queue by the paper's key, material type above material id (misses last), on the
// bits in use; skipped when one type would remain (counted as the CPU counts it).
void Renderer::sort_queue(int n) {
    if (!sort_ || n < 2) return;
    auto t = Clock::now();
    const SceneView s = sv_;
    const int32_t* q = queue_.data();
    const int32_t* prim = ps_.hit_prim;
    uint32_t* keys = keys_.data();
    int* mask = small_.data() + 1;
    const int id_bits = id_bits_;
    check(cudaMemsetAsync(mask, 0, sizeof(int), stream_), "cudaMemsetAsync");
    each(stream_, n, [=] __device__(int k) {
        const int tri = prim[q[k]];
        uint32_t type = kMaterialTypeCount, id = 0;
        if (tri >= 0) {
            id = s.tri_material[tri];
            type = s.materials[id].type;
        }
        keys[k] = (type << id_bits) | id;
        warp_or(reinterpret_cast<unsigned*>(mask), 1u << type);
    });
    const uint32_t present = uint32_t(read_int(mask));
    if (__builtin_popcount(present) <= 1) {
        ++stats_->unsorted_bounces;
        stats_->time_sort += seconds_since(t);
        return;
    }
    const int end_bit = id_bits_ + bits_for(uint32_t(31 - __builtin_clz(present)));
    cub_run("DeviceRadixSort", [&](void* t, size_t& bytes) {
        return cub::DeviceRadixSort::SortPairs(t, bytes, keys, keys_out_.data(), q,
                                               next_queue_.data(), n, 0, end_bit, stream_);
    });
    check(cudaStreamSynchronize(stream_), "sort");
    queue_.swap(next_queue_);
    ++stats_->sorted_bounces;
    stats_->time_sort += seconds_since(t);
}

// Closest hits of the queued slots' rays among triangles with `need`'s flags.
void Renderer::trace(int n, uint32_t need) {
    const PathState ps = ps_;
    const int32_t* q = queue_.data();
    const Tracer tr = tracer_;
    timed(stats_->time_trace, [&] {
        each(stream_, n, [=] __device__(int k) {
            const int i = q[k];
            const Ray r{ps.ray_o[i], ps.ray_d[i], ps.ray_tmin[i], ps.ray_tmax[i]};
            const BvhHit h = tr.closest(r, need);
            ps.hit_t[i] = h.t;
            ps.hit_prim[i] = h.prim;
            ps.hit_uv[i] = h.uv;
        });
    });
}

// Light tracing's camera segments against what the camera sees; returns how many were tested.
int64_t Renderer::test_camera_segments(int n) {
    const PathState ps = ps_;
    const int32_t* q = queue_.data();
    const Tracer tr = tracer_;
    uint8_t* occ = occluded_.data();
    unsigned long long* ctr = counters_.data() + kCtrCameraSegments;
    check(cudaMemsetAsync(ctr, 0, sizeof(unsigned long long), stream_), "cudaMemsetAsync");
    timed(stats_->time_shadow, [&] {
        each(stream_, n, [=] __device__(int k) {
            const int i = q[k];
            if (!ps.shadow_valid[i]) return;
            warp_count(ctr);
            const Ray r{ps.shadow_o[i], ps.shadow_d[i], 0.0f, ps.shadow_tmax[i]};
            occ[i] = tr.blocked(r, kBvhNeedCamera) ? 1 : 0;
        });
    });
    check(cudaMemcpyAsync(host_counters_, ctr, sizeof(unsigned long long), cudaMemcpyDeviceToHost,
                          stream_),
          "cudaMemcpyAsync");
    check(cudaStreamSynchronize(stream_), "cudaStreamSynchronize");
    return int64_t(host_counters_[0]);
}

// The bounce's unoccluded camera splats into the iteration (double atomics).
void Renderer::splat(int n) {
    const PathState ps = ps_;
    const int32_t* q = queue_.data();
    const uint8_t* occ = occluded_.data();
    const Vec2* xy = splat_xy_.data();
    const CameraView cam = sv_.camera;
    double* dst = iter_.data();
    const double scale = 1.0 / (double(width_) * double(height_));
    each(stream_, n, [=] __device__(int k) {
        const int i = q[k];
        if (!ps.shadow_valid[i] || occ[i]) return;
        const Vec3 v = ps.shadow_contrib[i];
        splat_pixels(cam, xy[i], scale, [&](int pixel, double f) {
            atomicAdd(dst + 3 * size_t(pixel) + 0, f * v.x);
            atomicAdd(dst + 3 * size_t(pixel) + 1, f * v.y);
            atomicAdd(dst + 3 * size_t(pixel) + 2, f * v.z);
        });
    });
}

// Adds each pixel's samples of the chunk to the iteration, one thread per pixel, in order.
void Renderer::film(int64_t first_path, int n) {
    const int spp_it = set_.spp_per_iteration;
    const int64_t p0 = first_path / spp_it;
    const int np = n / spp_it;
    const Vec3* rad = ps_.radiance;
    double* dst = iter_.data();
    count_dropped(n);
    timed(stats_->time_film, [&] {
        each(stream_, np, [=] __device__(int p) {
            double sum[3] = {0, 0, 0};
            for (int s = 0; s < spp_it; ++s) {
                const Vec3 c = rad[size_t(p) * spp_it + s];
                sum[0] += c.x;
                sum[1] += c.y;
                sum[2] += c.z;
            }
            double* d = dst + size_t(p0 + p) * 3;
            d[0] += sum[0];
            d[1] += sum[1];
            d[2] += sum[2];
        });
    });
}

void Renderer::count_dropped(int n) {
    const uint8_t* dropped = ps_.dropped;
    unsigned long long* ctr = counters_.data() + kCtrDropped;
    each(stream_, n, [=] __device__(int i) {
        if (dropped[i]) warp_count(ctr);
    });
}

PtSettings Renderer::pt_settings() const {
    return PtSettings{set_.max_depth, set_.rr_depth, set_.spp_per_iteration, set_.seed,
                      iteration_};
}

BdptSettings Renderer::bdpt_settings() const {
    return make_bdpt_settings(set_, width_, height_, iteration_, mode_, mis_r_);
}

// As Session::bdpt_samples_per_pass, with the GPU's free memory as the budget: half of what was
// free when the renderer started less the kernels' stack reservation, at most 8 GiB, or
// cache_budget_mb; the bdpt index (four int arrays per vertex) is inside it (cache_costs).
int Renderer::bdpt_samples_per_pass(int spp_it, std::vector<std::string>& warnings) {
    double budget = std::min(8.0 * (1 << 30),
                             0.5 * double(std::max<int64_t>(free_at_start_ - stack_reserve_, 0)));
    if (set_.cache_budget_mb > 0) budget = double(set_.cache_budget_mb) * (1 << 20);
    cache_budget_ = budget * budget_scale_;
    cache_costs_ = cache_costs(mode_ == kBdptOwnPath);
    return cache_samples_per_pass(cache_budget_, vertices_per_path_, cache_costs_, set_.max_depth,
                                  spp_it, width_, height_, "light vertex cache (GPU)",
                                  &split_warned_, warnings);
}

bool Renderer::step(const SessionSettings& settings, uint64_t& iteration, SessionStats& stats,
                    const std::atomic<bool>& cancel, std::vector<std::string>& warnings) {
    use_device();
    for (;;) {
        const SessionStats saved = stats;
        try {
            return try_step(settings, iteration, stats, cancel, warnings);
        } catch (const CudaUnavailable& e) {
            if (chunk_paths_ <= kGpuMinChunkPaths) throw;
            cudaStreamSynchronize(stream_);
            cudaGetLastError();
            stats = saved;
            release_state();
            cache_.release();  // and a smaller light vertex cache: more, smaller passes
            cache_size_ = 0;
            budget_scale_ *= 0.5;
            split_warned_ = false;
            chunk_paths_ /= 2;
            warnings.push_back(std::string("GPU memory is short (") + e.what() + "): " +
                               std::to_string(chunk_paths_) + " paths in flight from now on");
        }
    }
}

void Renderer::release_state() {
    for (auto* a : {&ray_o_, &ray_d_, &throughput_, &radiance_, &shadow_o_, &shadow_d_,
                    &shadow_c_, &power_, &conn_o_, &conn_d_, &conn_c_})
        a->release();
    for (auto* a : {&ray_tmin_, &ray_tmax_, &prev_pdf_, &hit_t_, &shadow_tmax_, &dvcm_, &dvc_,
                    &conn_tmax_})
        a->release();
    for (auto* a : {&depth_, &hit_prim_, &queue_, &next_queue_, &scan_, &store_flag_, &light_id_,
                    &conn_n_, &path_key_, &path_key_out_, &path_vertex_, &path_vertex_in_,
                    &path_offset_})
        a->release();
    for (auto* a : {&alive_, &dropped_, &shadow_valid_, &occluded_, &flags_, &store_, &conn_vis_,
                    &temp_})
        a->release();
    for (auto* a : {&hit_uv_, &splat_xy_}) a->release();
    for (auto* a : {&keys_, &keys_out_}) a->release();
    vertex_.release();
    rng_.release();
    state_cap_ = 0;
}

bool Renderer::try_step(const SessionSettings& settings, uint64_t& iteration, SessionStats& stats,
                        const std::atomic<bool>& cancel, std::vector<std::string>& warnings) {
    set_ = settings;
    stats_ = &stats;
    cancel_ = &cancel;
    iteration_ = iteration;
    const std::string& integ = set_.integrator;
    bidirectional_ = integ == "bdpt" || integ == "lvc" || integ == "cis";
    mode_ = integ == "bdpt" ? kBdptOwnPath : integ == "lvc" ? kLvcUniform : kCisResampled;
    sort_ = set_.sort < 0 ? integ == "cis" : set_.sort != 0;
    const int spp_it = set_.spp_per_iteration;
    const int64_t pixels = int64_t(width_) * height_;
    const size_t px3 = size_t(pixels) * 3;
    check(cudaMemsetAsync(iter_.data(), 0, px3 * sizeof(double), stream_), "cudaMemsetAsync");
    check(cudaMemsetAsync(counters_.data(), 0, kCtrCount * sizeof(unsigned long long), stream_),
          "cudaMemsetAsync");
    if (bidirectional_) {
        // as Session::step_bidirectional: the pilot's rate, passes within the budget, and a
        // pass whose cache would pass it starts the iteration again in smaller passes
        if (!(vertices_per_path_ >= 0.0)) {
            measure_cache_rate();
            if (cancel_->load()) return false;
        }
        const SessionStats saved = *stats_;
        int per_pass = bdpt_samples_per_pass(spp_it, warnings);
        for (;;) {
            std::string over;
            double rate = 0.0;
            const bool ok = run_passes(spp_it, per_pass, &over, &rate);
            if (over.empty()) {
                if (!ok) return false;
                break;
            }
            cache_.release();
            cache_size_ = 0;
            if (per_pass == 1)
                throw std::runtime_error(over + ", at one sample per pass: raise cache_budget_mb, "
                                                "or lower the resolution or max_depth");
            iteration_ = iteration;
            *stats_ = saved;
            check(cudaMemsetAsync(iter_.data(), 0, px3 * sizeof(double), stream_),
                  "cudaMemsetAsync");
            check(cudaMemsetAsync(counters_.data(), 0, kCtrCount * sizeof(unsigned long long),
                                  stream_),
                  "cudaMemsetAsync");
            vertices_per_path_ = std::max(vertices_per_path_, rate);
            per_pass = std::max(1, std::min(per_pass / 2, bdpt_samples_per_pass(spp_it, warnings)));
            if (!restart_warned_) {
                restart_warned_ = true;
                warnings.push_back("light vertex cache (GPU): " + over + "; the iteration ran "
                                   "again in passes of " + std::to_string(per_pass) + " samples");
            }
        }
    } else {
        const int64_t chunk_pixels = std::max<int64_t>(1, chunk_paths_ / spp_it);
        for (int64_t p0 = 0; p0 < pixels; p0 += chunk_pixels) {
            const int64_t np = std::min(chunk_pixels, pixels - p0);
            if (integ == "lt") {
                run_lt_chunk(p0 * spp_it, int(np * spp_it));
            } else {
                run_pt_chunk(p0 * spp_it, int(np * spp_it));
            }
            if (cancel_->load()) return false;
        }
        ++iteration_;
    }
    samples_ += spp_it;
    finish_step();
    iteration = iteration_;
    return true;
}

// The passes of one bidirectional iteration; a pass over the cache budget stops them and says
// why in *over (with the rate it measured), the iteration's sum then holds a partial result.
bool Renderer::run_passes(int spp_it, int per_pass, std::string* over, double* rate) {
    for (int done = 0; done < spp_it;) {
        const int s = std::min(per_pass, spp_it - done);
        set_.spp_per_iteration = s;
        bool ok = false;
        try {
            ok = run_bdpt_iteration();
        } catch (const CacheOverBudget& e) {
            *over = e.what();
            *rate = e.vertices_per_path;
        }
        set_.spp_per_iteration = spp_it;
        if (!over->empty() || !ok) return false;
        ++iteration_;
        done += s;
    }
    return true;
}

// The iteration joins the running sum once the last readback of the sum has finished, then a
// copy of the sum starts on the copy stream (pinned memory): accum() waits for that copy only.
void Renderer::finish_step() {
    std::lock_guard<std::mutex> lock(readback_mutex_);  // image() from another thread waits
    check(cudaStreamWaitEvent(stream_, copy_done_, 0), "cudaStreamWaitEvent");
    const size_t px3 = size_t(width_) * height_ * 3;
    double* sum = sum_.data();
    const double* it = iter_.data();
    each(stream_, int(px3), [=] __device__(int k) { sum[k] += it[k]; }, 256);
    check(cudaMemcpyAsync(host_counters_, counters_.data(), kCtrCount * sizeof(unsigned long long),
                          cudaMemcpyDeviceToHost, stream_),
          "cudaMemcpyAsync");
    check(cudaEventRecord(sum_ready_, stream_), "cudaEventRecord");
    check(cudaStreamWaitEvent(copy_stream_, sum_ready_, 0), "cudaStreamWaitEvent");
    check(cudaMemcpyAsync(host_sum_, sum, px3 * sizeof(double), cudaMemcpyDeviceToHost,
                          copy_stream_),
          "cudaMemcpyAsync");
    check(cudaEventRecord(copy_done_, copy_stream_), "cudaEventRecord");
    samples_copied_ = samples_;  // what the copy that copy_done_ marks holds
    check(cudaStreamSynchronize(stream_), "step");
    stats_->rays_shadow += int64_t(host_counters_[kCtrShadow]);
    stats_->rays_connection += int64_t(host_counters_[kCtrConnection]);
    stats_->nonfinite_dropped += int64_t(host_counters_[kCtrDropped]);
    stats_->device_memory_peak = mem_.peak;
    size_t free_b = 0, total_b = 0;
    if (cudaMemGetInfo(&free_b, &total_b) == cudaSuccess)
        used_peak_ = std::max(used_peak_, free_at_start_ - int64_t(free_b));
    stats_->device_memory_used = used_peak_;
}

std::vector<double> Renderer::accum(int64_t* samples) {
    std::lock_guard<std::mutex> lock(readback_mutex_);
    use_device();
    check(cudaEventSynchronize(copy_done_), "readback");
    const size_t px3 = size_t(width_) * height_ * 3;
    *samples = samples_copied_;
    return std::vector<double>(host_sum_, host_sum_ + px3);
}

}  // namespace cuda_detail

CudaInfo cuda_info() {
    CudaInfo info;
    info.compiled = true;
    const char* off = std::getenv("LANTERN_DISABLE_CUDA");
    if (off && *off && std::string(off) != "0") {
        info.reason = "disabled by LANTERN_DISABLE_CUDA";
        return info;
    }
    int count = 0;
    cudaError_t e = cudaGetDeviceCount(&count);
    if (e != cudaSuccess) {
        cudaGetLastError();
        const std::string err = std::string("CUDA: ") + cudaGetErrorString(e);
        if (e == cudaErrorInsufficientDriver) {
            info.reason = "no NVIDIA driver found, or one too old for this build's CUDA " +
                          std::to_string(CUDART_VERSION / 1000) + "." +
                          std::to_string(CUDART_VERSION % 1000 / 10) + " runtime (" + err + ")";
        } else if (e == cudaErrorNoDevice) {
            info.reason = "no CUDA-capable GPU found (" + err + ")";
        } else {
            info.reason = "the CUDA driver cannot be used (" + err + ")";
        }
        return info;
    }
    if (count == 0) {
        info.reason = "no CUDA device";
        return info;
    }
    cudaDeviceProp prop{};
    if (cudaGetDeviceProperties(&prop, 0) != cudaSuccess) {
        cudaGetLastError();
        info.reason = "cannot read the properties of CUDA device 0";
        return info;
    }
    info.name = prop.name;
    info.memory_bytes = int64_t(prop.totalGlobalMem);
    info.compute_capability = std::to_string(prop.major) + "." + std::to_string(prop.minor);
    cudaFuncAttributes attr{};
    e = cudaFuncGetAttributes(&attr, cuda_detail::probe_kernel);
    if (e != cudaSuccess) {
        cudaGetLastError();
        info.reason = "this build has no kernels for compute capability " +
                      info.compute_capability + " (" + cudaGetErrorString(e) + ")";
        return info;
    }
    info.available = true;
    return info;
}

std::unique_ptr<CudaRenderer> make_cuda_renderer(const HostScene& scene,
                                                 const SessionSettings& settings,
                                                 std::vector<std::string>& warnings) {
    const CudaInfo info = cuda_info();
    if (!info.available) throw CudaUnavailable(info.reason);
    return std::make_unique<cuda_detail::Renderer>(scene, settings, warnings);
}

}  // namespace lantern
