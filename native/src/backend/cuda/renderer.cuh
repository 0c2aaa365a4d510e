// What the CUDA renderer's translation units share (cuda_renderer.cu: set-up, queues, film,
// step; cuda_pt.cu: pt and lt chunks; cuda_bdpt.cu: the light pass; cuda_bdpt_camera.cu: the
// camera pass). Split so that nvcc compiles the heavy stage kernels in parallel. Internal to
// the backend: include only from backend/cuda/*.cu.
#pragma once

#include "backend/cuda/cuda_renderer.h"

#include <cuda_runtime.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <mutex>
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>
#include <cub/device/device_select.cuh>
#include <utility>

#include "accel/bvh.h"
#include "accel/bvh_builder.h"
#include "integrator/bdpt.h"
#include "integrator/lt.h"
#include "integrator/pt.h"
#include "integrator/session.h"
#include "scene/scene.h"

namespace lantern {
namespace cuda_detail {

using Clock = std::chrono::steady_clock;
inline double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

[[noreturn]] inline void fail(cudaError_t e, const char* what) {
    cudaGetLastError();  // clear it where it is not sticky
    const std::string msg = std::string(what) + ": " + cudaGetErrorString(e);
    if (e == cudaErrorMemoryAllocation) throw CudaUnavailable("out of GPU memory (" + msg + ")");
    throw std::runtime_error("CUDA error in " + msg);
}
inline void check(cudaError_t e, const char* what) {
    if (e != cudaSuccess) fail(e, what);
}

// Bytes of device memory held by one renderer, and the most it held at once.
struct MemoryMeter {
    int64_t current = 0, peak = 0;
    void add(int64_t b) {
        current += b;
        peak = std::max(peak, current);
    }
};

// A device array that only grows; grow(n, keep) preserves the first `keep` items.
template <typename T>
class DeviceArray {
public:
    DeviceArray() = default;
    ~DeviceArray() { release(); }
    DeviceArray(const DeviceArray&) = delete;
    DeviceArray& operator=(const DeviceArray&) = delete;
    void bind(MemoryMeter* m) { meter_ = m; }
    T* data() const { return p_; }
    size_t capacity() const { return cap_; }
    void grow(size_t n, size_t keep = 0, cudaStream_t s = 0) {
        if (n <= cap_) return;
        T* p = nullptr;
        check(cudaMalloc(&p, n * sizeof(T)), "cudaMalloc");
        if (keep > 0) {
            cudaError_t e = cudaMemcpyAsync(p, p_, std::min(keep, cap_) * sizeof(T),
                                            cudaMemcpyDeviceToDevice, s);
            if (e == cudaSuccess) e = cudaStreamSynchronize(s);
            if (e != cudaSuccess) {
                cudaFree(p);
                fail(e, "cudaMemcpyAsync");
            }
        }
        release();
        p_ = p;
        cap_ = n;
        if (meter_) meter_->add(int64_t(n * sizeof(T)));
    }
    void release() {
        if (!p_) return;
        cudaFree(p_);
        if (meter_) meter_->current -= int64_t(cap_ * sizeof(T));
        p_ = nullptr;
        cap_ = 0;
    }
    void swap(DeviceArray& o) {
        std::swap(p_, o.p_);
        std::swap(cap_, o.cap_);
    }

private:
    T* p_ = nullptr;
    size_t cap_ = 0;
    MemoryMeter* meter_ = nullptr;
};

template <typename F>
__global__ void each_kernel(int n, F f) {
    const int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) f(i);
}

// Runs f(i) for i in [0, n) on stream s.
template <typename F>
void each(cudaStream_t s, int n, F f, int block = 128) {
    if (n <= 0) return;
    each_kernel<<<(n + block - 1) / block, block, 0, s>>>(n, f);
    check(cudaGetLastError(), "kernel launch");
}

// Ray queries against the device BVH, with the scene's alpha test (scene/alpha.h).
struct Tracer {
    BvhView bvh;
    SceneView s;
    __device__ BvhHit closest(const Ray& r, uint32_t need) const {
        return bvh_intersect(bvh, r, need, BvhAlphaTest{s, r});
    }
    __device__ bool blocked(const Ray& r, uint32_t need) const {
        return bvh_occluded(bvh, r, need, BvhAlphaTest{s, r});
    }
};

// Device counters read back once per step.
enum Counter : int { kCtrShadow, kCtrConnection, kCtrCameraSegments, kCtrDropped, kCtrCount };

constexpr int kGpuChunkPaths = 1 << 21;    // paths in flight per chunk (halved when memory is short)
constexpr int kGpuMinChunkPaths = 1 << 15;
constexpr int kGpuShadowBudget = 1 << 23;  // connection ray slots per camera chunk
// Stack frame of the largest kernel per thread: bdpt_camera_shade measured 16,720 bytes with
// ptxas for sm_90 (its MaterialScratch copies and cis candidates; tools/gpu_check.sh prints the
// frames of the build it makes). The driver reserves it for every resident thread.
constexpr int64_t kShadeStackEstimate = 17 * 1024;

inline int bits_for(uint32_t v) {  // bits to write 0..v
    int b = 0;
    while (b < 32 && (v >> b) != 0) ++b;
    return b;
}

// Public members throughout: nvcc's extended lambdas must not sit in private member functions.
class Renderer final : public CudaRenderer {
public:
    Renderer(const HostScene& scene, const SessionSettings& settings,
             std::vector<std::string>& warnings);
    ~Renderer() override;
    bool step(const SessionSettings& settings, uint64_t& iteration, SessionStats& stats,
              const std::atomic<bool>& cancel, std::vector<std::string>& warnings) override;
    bool try_step(const SessionSettings& settings, uint64_t& iteration, SessionStats& stats,
                  const std::atomic<bool>& cancel, std::vector<std::string>& warnings);
    void release_state();  // the wavefront's arrays (not the scene, the cache or the film)
    std::vector<double> accum() override;
    std::string device_name() const override { return name_; }
    void release();  // everything the constructor made (it may have thrown half-way)

    // ---- schedule pieces ----
    void ensure_state(int n, int conn_cap);
    template <typename F>
    void timed(double& acc, F&& f) {
        auto t = Clock::now();
        f();
        check(cudaStreamSynchronize(stream_), "stage");
        acc += seconds_since(t);
    }
    int read_int(const int* d);
    // A CUB device call: its scratch-size query, then the call on the shared scratch buffer
    // (call(temp, bytes) returns cudaError_t). Earlier calls have finished by then: every CUB
    // call is followed by a readback or a synchronisation.
    template <typename F>
    void cub_run(const char* what, F&& call) {
        size_t bytes = 0;
        check(call(static_cast<void*>(nullptr), bytes), what);
        temp_.grow(std::max<size_t>(bytes, 1));
        check(call(static_cast<void*>(temp_.data()), bytes), what);
    }
    int compact(int n);
    void sort_queue(int n);
    void trace(int n, uint32_t need);
    int64_t test_camera_segments(int n);
    void splat(int n);
    void film(int64_t first_path, int n);
    void count_dropped(int n);
    void run_pt_chunk(int64_t first_path, int n);
    void run_lt_chunk(int64_t first_path, int n);
    bool run_bdpt_iteration();
    void run_light_chunk(int64_t first_path, int n);
    void run_camera_chunk(int64_t first_path, int n);
    void index_cache_by_path(int64_t light_paths);
    int bdpt_samples_per_pass(int spp_it, std::vector<std::string>& warnings);
    BdptSettings bdpt_settings() const;
    PtSettings pt_settings() const;
    void finish_step();

    // ---- device and scene ----
    std::string name_;
    cudaStream_t stream_ = nullptr, copy_stream_ = nullptr;
    cudaEvent_t sum_ready_ = nullptr, copy_done_ = nullptr;
    MemoryMeter mem_;
    std::vector<void*> scene_mem_;
    SceneView sv_{};
    Tracer tracer_{};
    int width_ = 0, height_ = 0;
    int id_bits_ = 0;
    int64_t free_at_start_ = 0;
    int64_t stack_reserve_ = 0;  // local memory the driver will reserve for the shade kernels
    int chunk_paths_ = kGpuChunkPaths;
    double budget_scale_ = 1.0;  // of the cache budget, halved with the chunk
    int64_t used_peak_ = 0;  // free memory at start minus free memory now, at its largest

    // ---- settings of the running step ----
    SessionSettings set_;
    SessionStats* stats_ = nullptr;
    const std::atomic<bool>* cancel_ = nullptr;
    uint64_t iteration_ = 0;
    bool bidirectional_ = false, sort_ = false;
    int mode_ = 0, conn_cap_ = 0;
    float mis_r_ = 1.0f;
    double vertices_per_path_ = -1.0;
    bool pilot_ = false, split_warned_ = false;
    int64_t pilot_count_ = 0;

    // ---- wavefront state (PathState / BdptState / LightPathState slots) ----
    int state_cap_ = 0, conn_state_cap_ = 0;
    DeviceArray<Vec3> ray_o_, ray_d_, throughput_, radiance_, shadow_o_, shadow_d_, shadow_c_;
    DeviceArray<float> ray_tmin_, ray_tmax_, prev_pdf_, hit_t_, shadow_tmax_;
    DeviceArray<Rng> rng_;
    DeviceArray<int32_t> depth_, hit_prim_, queue_, next_queue_, scan_, store_flag_;
    DeviceArray<Vec2> hit_uv_;
    DeviceArray<uint8_t> alive_, dropped_, shadow_valid_, occluded_, flags_;
    DeviceArray<float> dvcm_, dvc_;
    DeviceArray<int32_t> light_id_, conn_n_;
    DeviceArray<uint8_t> store_, conn_vis_;
    DeviceArray<LightVertex> vertex_;
    DeviceArray<Vec3> power_, conn_o_, conn_d_, conn_c_;
    DeviceArray<Vec2> splat_xy_;
    DeviceArray<float> conn_tmax_;
    DeviceArray<uint32_t> keys_, keys_out_;
    PathState ps_{};
    BdptState bs_{};
    // light vertex cache and its per-path index (bdpt)
    DeviceArray<LightVertex> cache_;
    int64_t cache_size_ = 0;
    DeviceArray<int32_t> path_key_, path_key_out_, path_vertex_, path_vertex_in_, path_offset_;
    // film: the iteration's sum, the running sum, its pinned host copy
    DeviceArray<double> iter_, sum_;
    double* host_sum_ = nullptr;
    std::mutex readback_mutex_;  // finish_step's re-recording of copy_done_ against accum()
    // small things
    DeviceArray<uint8_t> temp_;
    DeviceArray<int> small_;  // [0] selected count, [1] present-type mask, [2] scan total
    DeviceArray<unsigned long long> counters_;
    int* host_int_ = nullptr;
    unsigned long long* host_counters_ = nullptr;
};

}  // namespace cuda_detail
}  // namespace lantern
