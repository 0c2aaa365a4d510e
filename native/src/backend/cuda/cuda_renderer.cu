// The CUDA backend: the schedule every backend runs (integrator/wavefront.h, schedule_pt.h,
// schedule_lt.h, schedule_bdpt.h) instantiated on CudaExec (cuda_exec.cuh) in cuda_schedule_*.cu,
// one translation unit per part so that they compile side by side. What is left here is
// CUDA-only: the scene and BVH upload (moving meshes' two levels and the strands' query through
// accel/scene_query_build.h, host code tested on the CPU), the GPU's cache budget and out-of-memory policy, the
// film's running sum with its pinned readback on a copy stream (the next iteration's kernels run
// while it drains; only the final add into the sum waits for it). cuda_info() is in
// backend/cuda_info.cu.
#include <algorithm>
#include <mutex>

#include "accel/bvh_builder.h"
#include "accel/scene_query_build.h"
#include "backend/cuda/cuda_exec.cuh"
#include "integrator/thread_scratch.h"
#include "integrator/wavefront.h"
#include "scene/scene.h"

namespace lantern {
namespace cuda_detail {

constexpr int kGpuChunkPaths = 1 << 21;  // paths in flight per chunk (halved when memory is short)
constexpr int kGpuMinChunkPaths = 1 << 15;
constexpr int kGpuShadowBudget = 1 << 23;  // connection ray slots per camera chunk
// Stack frame of the largest kernel, at most CI's limit for every kernel (tools/test.sh's
// cuda_kernel_check: 2 KB; the largest measured, the camera pass's events stage, 1,984 B with
// ptxas 13.0.88 for sm_90, 2026-12-05, docs/cuda_backend.md): the driver reserves it for every
// resident thread, the budget leaves it.
constexpr int64_t kShadeStackEstimate = 2048;

// Public members throughout: nvcc's extended lambdas must not sit in private member functions.
class Renderer final : public CudaRenderer {
public:
    Renderer(const HostScene& scene, std::vector<std::string>& warnings) {
        try {
            ex_ = std::make_unique<CudaExec>(0);
            w_.bind(&ex_->meter());
            iter_.bind(&ex_->meter());
            sum_.bind(&ex_->meter());
            scratch_.bind(&ex_->meter());
            cudaDeviceProp prop{};
            check(cudaGetDeviceProperties(&prop, ex_->device_), "cudaGetDeviceProperties");
            name_ = prop.name;
            size_t free_b = 0, total_b = 0;
            check(cudaMemGetInfo(&free_b, &total_b), "cudaMemGetInfo");
            free_at_start_ = int64_t(free_b);
            stack_reserve_ = kShadeStackEstimate * int64_t(prop.maxThreadsPerMultiProcessor) *
                             int64_t(prop.multiProcessorCount);
            check(cudaStreamCreateWithFlags(&copy_stream_, cudaStreamNonBlocking), "stream");
            for (cudaEvent_t* ev : {&sum_ready_, &copy_done_})
                check(cudaEventCreateWithFlags(ev, cudaEventDisableTiming), "event");
            check(cudaEventRecord(copy_done_, copy_stream_), "cudaEventRecord");
            // the scene, array by array, then the BVH (built on the host, copied as it is)
            auto upload = [&](const void* host, size_t bytes) -> void* {
                if (!host || bytes == 0) return nullptr;
                void* d = nullptr;
                check(cudaMalloc(&d, bytes), "cudaMalloc (scene)");
                scene_mem_.push_back(d);
                ex_->meter().add(int64_t(bytes));
                check(cudaMemcpy(d, host, bytes, cudaMemcpyHostToDevice), "cudaMemcpy (scene)");
                return d;
            };
            sv_ = scene.copied_view(upload);
            const bool scratch = scratch_.prepare_scene(scene.view(), sv_, kDeviceThreads);
            // moving meshes: two levels, as CpuBackend's (Session::start_cpu_backend); strands:
            // their query beside (accel/scene_query.h), both on the device behind one pointer
            const SceneView& hv = scene.view();
            const bool two_level = hv.motion.num_objects > 0;
            Bvh bvh = two_level ? Bvh{} : build_bvh(hv, BvhBuildOptions{}, warnings);
            BvhView bv = bvh.view();
            bv.nodes = static_cast<const BvhNode*>(upload(bvh.nodes.data(), bvh.nodes.size() * sizeof(BvhNode)));
            bv.tris = static_cast<const BvhTri*>(upload(bvh.tris.data(), bvh.tris.size() * sizeof(BvhTri)));
            ex_->set_rays(bv, sv_);
            if (scene_query_needed(hv)) {
                SceneQuery q;
                scene_query_build(q, hv, two_level ? &scene.mesh_ranges() : nullptr, 0, warnings);
                ex_->set_query(scene_query_copied(
                    q, [&](const void* h, size_t b) -> const void* { return upload(h, b); }, sv_));
            }
            if (scratch) ex_->set_max_threads(kDeviceThreads);
            width_ = scene.view().camera.width;
            height_ = scene.view().camera.height;
            sum_.grow(px3());
            iter_.grow(px3());
            check(cudaMemset(sum_.data(), 0, px3() * sizeof(double)), "cudaMemset");
            check(cudaMallocHost(&host_sum_, px3() * sizeof(double)), "cudaMallocHost");
            std::fill(host_sum_, host_sum_ + px3(), 0.0);
            check(cudaDeviceSynchronize(), "scene upload");
        } catch (const std::runtime_error& e) {
            // a CUDA error while setting up means this GPU cannot render the scene: fall back
            release();
            throw CudaUnavailable(e.what());
        }
    }
    ~Renderer() override { release(); }
    void release() {  // everything the constructor made outside arrays (no throw)
        if (ex_) cudaSetDevice(ex_->device_);
        if (copy_stream_) cudaStreamSynchronize(copy_stream_);
        for (void* p : scene_mem_) cudaFree(p);
        scene_mem_.clear();
        if (host_sum_) cudaFreeHost(host_sum_);
        if (sum_ready_) cudaEventDestroy(sum_ready_);
        if (copy_done_) cudaEventDestroy(copy_done_);
        if (copy_stream_) cudaStreamDestroy(copy_stream_);
        host_sum_ = nullptr;
        sum_ready_ = copy_done_ = nullptr;
        copy_stream_ = nullptr;
    }
    size_t px3() const { return size_t(width_) * height_ * 3; }
    std::string device_name() const override { return name_; }

    // Out of memory inside a step: the step starts again with half as many paths in flight and
    // half the cache budget (more, smaller passes), down to kGpuMinChunkPaths; only then does
    // the session hear of it (and go on on the CPU).
    bool step(const SessionSettings& set, uint64_t& iteration, SessionStats& stats,
              const std::atomic<bool>& cancel, std::vector<std::string>& warnings) override {
        ex_->use_device();
        for (;;) {
            const SessionStats saved = stats;
            try {
                return try_step(set, iteration, stats, cancel, warnings);
            } catch (const CudaUnavailable& e) {
                if (chunk_paths_ <= kGpuMinChunkPaths) throw;
                cudaStreamSynchronize(ex_->stream());
                cudaGetLastError();
                stats = saved;
                w_.release_state();
                w_.release_cache();
                budget_scale_ *= 0.5;
                w_.split_warned = false;
                chunk_paths_ /= 2;
                warnings.push_back(std::string("GPU memory is short (") + e.what() + "): " +
                                   std::to_string(chunk_paths_) + " paths in flight from now on");
            }
        }
    }
    bool try_step(const SessionSettings& set, uint64_t& iteration, SessionStats& stats,
                  const std::atomic<bool>& cancel, std::vector<std::string>& warnings) {
        check(cudaMemsetAsync(iter_.data(), 0, px3() * sizeof(double), ex_->stream()), "memset");
        WavefrontStep st(set, width_, height_, iteration, iter_.data(), &stats, &cancel,
                         &warnings);
        st.chunk_paths = chunk_paths_;
        st.shadow_budget = kGpuShadowBudget;
        if (scratch_.prepare_integrator(set.integrator, sv_, kDeviceThreads)) {
            ex_->set_max_threads(kDeviceThreads);  // launches of at most the scratch's columns
            ex_->set_rays(ex_->bvh_, sv_);
        }
        st.cache_budget = gpu_cache_budget(free_at_start_, stack_reserve_ + scratch_.bytes(),
                                           set.cache_budget_mb, budget_scale_);
        st.cache_name = "light vertex cache (GPU)";
        if (!wf::run_iteration(*ex_, w_, sv_, st)) return false;
        samples_ += set.spp_per_iteration;
        finish_step(stats);
        iteration = st.iteration;
        return true;
    }

    // The iteration joins the running sum once the last readback of the sum has finished, then
    // a copy of the sum starts on the copy stream (pinned memory): accum() waits for it only.
    void finish_step(SessionStats& stats) {
        std::lock_guard<std::mutex> lock(readback_mutex_);  // accum() from another thread waits
        cudaStream_t s = ex_->stream();
        check(cudaStreamWaitEvent(s, copy_done_, 0), "cudaStreamWaitEvent");
        double* sum = sum_.data();
        const double* it = iter_.data();
        ex_->each(int(px3()), [=] __device__(int k) { sum[k] += it[k]; }, 256);
        check(cudaEventRecord(sum_ready_, s), "cudaEventRecord");
        check(cudaStreamWaitEvent(copy_stream_, sum_ready_, 0), "cudaStreamWaitEvent");
        check(cudaMemcpyAsync(host_sum_, sum, px3() * sizeof(double), cudaMemcpyDeviceToHost,
                              copy_stream_),
              "cudaMemcpyAsync");
        check(cudaEventRecord(copy_done_, copy_stream_), "cudaEventRecord");
        samples_copied_ = samples_;  // what the copy that copy_done_ marks holds
        ex_->sync();
        stats.device_memory_peak = ex_->meter().peak;
        size_t free_b = 0, total_b = 0;
        if (cudaMemGetInfo(&free_b, &total_b) == cudaSuccess)
            used_peak_ = std::max(used_peak_, free_at_start_ - int64_t(free_b));
        stats.device_memory_used = used_peak_;
    }
    std::vector<double> accum(int64_t* samples) override {
        std::lock_guard<std::mutex> lock(readback_mutex_);
        ex_->use_device();
        check(cudaEventSynchronize(copy_done_), "readback");
        *samples = samples_copied_;
        return std::vector<double>(host_sum_, host_sum_ + px3());
    }

    std::unique_ptr<CudaExec> ex_;  // first: the arrays below free into its meter
    Wavefront<CudaExec> w_;
    DeviceArray<double> iter_, sum_;  // the iteration's sum, the running sum
    ThreadScratch<CudaExec> scratch_;  // SceneView's per-thread scratch (thread_scratch.h)
    std::string name_;
    cudaStream_t copy_stream_ = nullptr;
    cudaEvent_t sum_ready_ = nullptr, copy_done_ = nullptr;
    std::vector<void*> scene_mem_;
    SceneView sv_{};
    int width_ = 0, height_ = 0;
    int chunk_paths_ = kGpuChunkPaths;
    double budget_scale_ = 1.0;
    int64_t free_at_start_ = 0, stack_reserve_ = 0, used_peak_ = 0;
    int64_t samples_ = 0, samples_copied_ = 0;  // per pixel in sum_, and in the host copy
    double* host_sum_ = nullptr;
    std::mutex readback_mutex_;  // finish_step's re-recording of copy_done_ against accum()
};

}  // namespace cuda_detail

std::unique_ptr<CudaRenderer> make_cuda_renderer(const HostScene& scene, const SessionSettings&,
                                                 std::vector<std::string>& warnings) {
    const CudaInfo info = cuda_info();
    if (!info.available) throw CudaUnavailable(info.reason);
    return std::make_unique<cuda_detail::Renderer>(scene, warnings);
}

}  // namespace lantern
