// What the CUDA renderer's translation units share (cuda_renderer.cu: set-up, queues, film,
// step; cuda_pt.cu: pt and lt chunks; cuda_bdpt.cu: the light pass; cuda_bdpt_camera.cu: the
// camera pass). Split so that nvcc compiles the heavy stage kernels in parallel. Internal to
// the backend: include only from backend/cuda/*.cu.
#pragma once

#include "backend/cuda/cuda_renderer.h"

#include <cuda_runtime.h>

#include "backend/cuda/cuda_exec.cuh"  // fail / check, DeviceArray, each, warp reductions

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <mutex>
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
    std::vector<double> accum(int64_t* samples) override;
    // Every call that launches work or touches device memory selects the renderer's device
    // first: steps run on another thread than the one that made the renderer.
    void use_device() const { check(cudaSetDevice(device_), "cudaSetDevice"); }
    bool run_passes(int spp_it, int per_pass, std::string* over, double* rate);
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
    void measure_cache_rate();
    void run_light_chunk(int64_t first_path, int n);
    void run_camera_chunk(int64_t first_path, int n);
    void index_cache_by_path(int64_t light_paths);
    int bdpt_samples_per_pass(int spp_it, std::vector<std::string>& warnings);
    BdptSettings bdpt_settings() const;
    PtSettings pt_settings() const;
    void finish_step();

    // ---- device and scene ----
    std::string name_;
    int device_ = 0;
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
    bool pilot_ = false, split_warned_ = false, restart_warned_ = false;
    int64_t pilot_count_ = 0;
    double cache_budget_ = 0.0;
    CacheCosts cache_costs_{};
    int64_t pass_light_paths_ = 0;
    int64_t samples_ = 0, samples_copied_ = 0;  // per pixel in sum_, and in the host copy

    // ---- wavefront state (PathState / BdptState / LightPathState slots) ----
    int state_cap_ = 0, conn_state_cap_ = 0;
    DeviceArray<Vec3> ray_o_, ray_d_, throughput_, radiance_, shadow_o_, shadow_d_, shadow_c_;
    DeviceArray<Vec3> prev_p_, prev_n_;  // PathState::prev_p / prev_n (light tree MIS)
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
