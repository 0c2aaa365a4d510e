// The CUDA executor: backend/cpu/cpu_exec.h's interface on a GPU (device arrays on the shared
// meter, each() as a kernel, CUB's stable select / scan / radix sort, integer reductions with one
// atomic per warp, ray queries against the device BVH, splats with double atomics, readback,
// timing with a stream synchronisation, the out-of-memory policy). Ray queries are
// accel/scene_query.h's: the one-level BVH, or with a SceneQueryView on the device (moving
// meshes: the two-level BVH; strands: accel/curve_query.h) what CpuBackend's built-in BVH does. Every call selects the device
// first: steps run on another thread than the one that made it. tests/cuda/exec_conformance.cu
// checks it against tests/cpp/exec_conformance.h's references.
#pragma once

#include <cuda_runtime.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <cooperative_groups.h>
#include <cooperative_groups/reduce.h>
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>
#include <cub/device/device_select.cuh>
#include <string>
#include <utility>

#include "accel/boundary_hits.h"
#include "accel/bvh.h"
#include "accel/scene_query.h"
#include "backend/cpu/embree_accel.h"  // RayKind (plain enum)
#include "backend/cuda/cuda_renderer.h"
#include "integrator/lt.h"
#include "integrator/wavefront_cache.h"

namespace lantern {
namespace cuda_detail {

[[noreturn]] inline void fail(cudaError_t e, const char* what) {
    cudaGetLastError();  // clear it where it is not sticky
    const std::string msg = std::string(what) + ": " + cudaGetErrorString(e);
    if (e == cudaErrorMemoryAllocation) throw CudaUnavailable("out of GPU memory (" + msg + ")");
    throw std::runtime_error("CUDA error in " + msg);
}
inline void check(cudaError_t e, const char* what) {
    if (e != cudaSuccess) fail(e, what);
}

// A device array that only grows; grow(n, keep) preserves the first `keep` items. The meter
// holds old and new together while a growth copies.
template <typename T>
class DeviceArray {
public:
    DeviceArray() = default;
    explicit DeviceArray(MemoryMeter* m) : meter_(m) {}
    ~DeviceArray() { release(); }
    DeviceArray(const DeviceArray&) = delete;
    DeviceArray& operator=(const DeviceArray&) = delete;
    DeviceArray(DeviceArray&& o) noexcept : meter_(o.meter_) { swap(o); }
    void bind(MemoryMeter* m) { meter_ = m; }
    T* data() const { return p_; }
    size_t capacity() const { return cap_; }
    void grow(size_t n, size_t keep = 0, cudaStream_t s = 0) {
        if (n <= cap_) return;
        T* p = nullptr;
        cudaError_t e = cudaMalloc(&p, n * sizeof(T));
        if (e != cudaSuccess) fail(e, "cudaMalloc");
        if (meter_) meter_->add(int64_t(n * sizeof(T)));  // old and new alive together
        if (keep > 0) {
            e = cudaMemcpyAsync(p, p_, std::min(keep, cap_) * sizeof(T),
                                cudaMemcpyDeviceToDevice, s);
            if (e == cudaSuccess) e = cudaStreamSynchronize(s);
            if (e != cudaSuccess) {
                cudaFree(p);
                if (meter_) meter_->sub(int64_t(n * sizeof(T)));
                fail(e, "cudaMemcpyAsync");
            }
        }
        release();
        p_ = p;
        cap_ = n;
    }
    void grow_keep(size_t n, size_t keep) { grow(n, keep); }
    void release() {
        if (!p_) return;
        cudaFree(p_);
        if (meter_) meter_->sub(int64_t(cap_ * sizeof(T)));
        p_ = nullptr;
        cap_ = 0;
    }
    void swap(DeviceArray& o) {
        std::swap(p_, o.p_);
        std::swap(cap_, o.cap_);
    }
    void upload(const T* host, size_t n, size_t at = 0) {
        if (n) check(cudaMemcpy(p_ + at, host, n * sizeof(T), cudaMemcpyHostToDevice), "upload");
    }
    void download(T* host, size_t n, size_t at = 0) const {
        if (n) check(cudaMemcpy(host, p_ + at, n * sizeof(T), cudaMemcpyDeviceToHost), "readback");
    }

private:
    T* p_ = nullptr;
    size_t cap_ = 0;
    MemoryMeter* meter_ = nullptr;
};

// The functor stays in kernel-parameter memory (__grid_constant__): the stages take the captured
// SceneView and states by reference, which would otherwise make ptxas copy them to the stack.
// Blocks of up to 256 threads, 2 per SM at least: at most 128 registers per thread (ptxas spills
// the rest; docs/cuda_backend.md "Kernel resources" has what each kernel spills).
// A grid-stride loop: a launch may have fewer threads than items (each() below).
template <typename F>
__global__ void __launch_bounds__(256, 2) each_kernel(int n, const __grid_constant__ F f) {
    const int step = int(gridDim.x * blockDim.x);
    for (int i = int(blockIdx.x * blockDim.x + threadIdx.x); i < n; i += step) f(i);
}

// Threads of one launch at most once the renderer has per-thread scratch (thread_scratch.h;
// 2^17 x 768 B = 96 MiB of program registers): an H200 holds 132 SMs x 512 resident threads at
// 128 registers (67,584), so the 128-register kernels lose no occupancy.
constexpr int kDeviceThreads = 1 << 17;

// Runs f(i) for i in [0, n) on stream s, with at most max_threads threads (0: one per item).
template <typename F>
void each(cudaStream_t s, int n, F f, int block = 128, int max_threads = 0) {
    if (n <= 0) return;
    int blocks = (n + block - 1) / block;
    if (max_threads > 0) blocks = std::max(1, std::min(blocks, max_threads / block));
    each_kernel<<<blocks, block, 0, s>>>(n, f);
    check(cudaGetLastError(), "kernel launch");
}

// Device counters, reduced per warp first: the lanes that reach the call (a coalesced group)
// add their total with one atomic; a mask is OR-ed with one atomic per warp.
__device__ inline void warp_add(unsigned long long* ctr, unsigned long long v) {
    namespace cg = cooperative_groups;
    const cg::coalesced_group g = cg::coalesced_threads();
    const unsigned long long all = cg::reduce(g, v, cg::plus<unsigned long long>());
    if (g.thread_rank() == 0) atomicAdd(ctr, all);
}
__device__ inline void warp_count(unsigned long long* ctr) {
    namespace cg = cooperative_groups;
    const cg::coalesced_group g = cg::coalesced_threads();
    if (g.thread_rank() == 0) atomicAdd(ctr, (unsigned long long)g.size());
}
__device__ inline void warp_or(unsigned* mask, unsigned bits) {
    namespace cg = cooperative_groups;
    const cg::coalesced_group g = cg::coalesced_threads();
    const unsigned all = cg::reduce(g, bits, cg::bit_or<unsigned>());
    if (g.thread_rank() == 0) atomicOr(mask, all);
}

// What a ray query reads, in device memory (CudaExec::set_rays / set_query copy it there): a
// kernel holds one pointer to it, and a query is a call with the pointer and the ray, so that
// no stage copies the 880-byte SceneView into its own frame to pass it by reference (the last
// try passed SceneView& to __noinline__ parts: camera_chunk #2.3 went from 1,952 B of stack
// to 2,336-2,512 B; docs/cuda_backend.md "Strands and motion blur").
struct RayQuery {
    BvhView bvh;         // the one-level BVH (empty where x.two_level)
    SceneView s;         // the alpha test's
    SceneQueryView x;    // moving meshes' two levels, the strands
    int32_t has_x = 0;   // 0: bvh alone
};

__device__ inline uint32_t query_need(int kind) {  // kind: RayKind as int
    return kind == int(RayKind::kCamera)   ? kBvhNeedCamera
           : kind == int(RayKind::kShadow) ? kBvhNeedShadow
                                           : kBvhNeedIndirect;
}

// The parts of accel/scene_query.h, each a call of its own: a query holds the stack of one
// traversal at a time (flat: 512 B, two levels: 768 B, strands: 256 B), the largest in its
// cumulative stack, not their sum.
static __device__ __noinline__ BvhHit query_flat(const RayQuery* q, const Ray r, uint32_t need) {
    return bvh_intersect(q->bvh, r, need, BvhAlphaTest{q->s, r});
}
static __device__ __noinline__ bool query_flat_any(const RayQuery* q, const Ray r, uint32_t need) {
    return bvh_occluded(q->bvh, r, need, BvhAlphaTest{q->s, r});
}
static __device__ __noinline__ BvhHit query_tlas(const RayQuery* q, const Ray r, uint32_t need) {
    return tlas_intersect(q->x.tlas, r, need, BvhAlphaTest{q->s, r});
}
static __device__ __noinline__ bool query_tlas_any(const RayQuery* q, const Ray r, uint32_t need) {
    return tlas_occluded(q->x.tlas, r, need, BvhAlphaTest{q->s, r});
}
static __device__ __noinline__ CurveBvhHit query_curve(const RayQuery* q, const Ray r, int kind,
                                                       float tmax) {
    return curve_query_closest(q->x.curves, r, kind, tmax);
}
static __device__ __noinline__ bool query_curve_any(const RayQuery* q, const Ray r, int kind) {
    return curve_query_occluded(q->x.curves, r, kind);
}
// accel/scene_query.h's parts as those calls
struct QueryCalls {
    const RayQuery* q;
    __device__ BvhHit flat(const Ray& r, uint32_t need) const { return query_flat(q, r, need); }
    __device__ bool flat_any(const Ray& r, uint32_t need) const {
        return query_flat_any(q, r, need);
    }
    __device__ BvhHit tlas(const TlasView&, const Ray& r, uint32_t need) const {
        return query_tlas(q, r, need);
    }
    __device__ bool tlas_any(const TlasView&, const Ray& r, uint32_t need) const {
        return query_tlas_any(q, r, need);
    }
    __device__ CurveBvhHit curve(const CurveQueryView&, const Ray& r, int kind, float tmax) const {
        return query_curve(q, r, kind, tmax);
    }
    __device__ bool curve_any(const CurveQueryView&, const Ray& r, int kind) const {
        return query_curve_any(q, r, kind);
    }
};
__device__ inline int query_curve_kind(int kind) {  // curve_query.h's: 0 camera, 1, 2 shadow
    return kind == int(RayKind::kCamera) ? 0 : (kind == int(RayKind::kShadow) ? 2 : 1);
}
// One call per query, whatever the scene holds (kind: RayKind as int).
static __device__ __noinline__ BvhHit query_closest(const RayQuery* q, const Ray r, int kind) {
    const uint32_t need = query_need(kind);
    if (!q->has_x) return query_flat(q, r, need);
    return scene_query_closest_parts(q->x, r, query_curve_kind(kind), need, QueryCalls{q});
}
static __device__ __noinline__ bool query_occluded_collect(const RayQuery* q, const Ray r,
                                                           BoundaryHits* out) {
    if (q->has_x) {
        out->n = -1;
        return false;
    }
    return bvh_occluded_collect(q->bvh, r, out, BvhAlphaTest{q->s, r});
}
static __device__ __noinline__ bool query_occluded(const RayQuery* q, const Ray r, int kind) {
    const uint32_t need = query_need(kind);
    if (!q->has_x) return query_flat_any(q, r, need);
    return scene_query_occluded_parts(q->x, r, query_curve_kind(kind), need, QueryCalls{q});
}

}  // namespace cuda_detail

// Public members throughout: nvcc's extended lambdas must not sit in private member functions.
class CudaExec {
public:
    template <typename T>
    using Array = cuda_detail::DeviceArray<T>;
    static constexpr bool kGpu = true;
    static constexpr bool kDeterministicSplats = false;  // double atomics

    explicit CudaExec(int device = 0) : device_(device) {
        use_device();
        cuda_detail::check(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking),
                           "cudaStreamCreate");
        cuda_detail::check(cudaMallocHost(&host_, 4 * sizeof(unsigned long long)),
                           "cudaMallocHost");
        small_.bind(&meter_);
        temp_.bind(&meter_);
        scratch_keys_.bind(&meter_);
        scratch_values_.bind(&meter_);
        flags_.bind(&meter_);
        query_.bind(&meter_);
        small_.grow(4);
    }
    ~CudaExec() {
        cudaSetDevice(device_);
        if (stream_) cudaStreamSynchronize(stream_);  // the arrays free after this, on device_
        if (host_) cudaFreeHost(host_);
        if (stream_) cudaStreamDestroy(stream_);
    }
    CudaExec(const CudaExec&) = delete;
    CudaExec& operator=(const CudaExec&) = delete;

    void use_device() const { cuda_detail::check(cudaSetDevice(device_), "cudaSetDevice"); }
    // Ray queries against a BVH already on the device, with the scene's alpha test (s: the
    // device copy's view); both go to the device (cuda_detail::RayQuery) before the next kernel.
    void set_rays(const BvhView& bvh, const SceneView& s) {
        bvh_ = bvh;
        scene_ = s;
        upload_query();
    }
    // The two-level BVH and the strands (a SceneQueryView over device arrays, from
    // accel/scene_query_build.h's scene_query_copied).
    void set_query(const SceneQueryView& x) {
        x_ = x;
        has_x_ = 1;
        upload_query();
    }
    void upload_query() {
        use_device();
        cuda_detail::RayQuery h;
        h.bvh = bvh_;
        h.s = scene_;
        h.x = x_;
        h.has_x = has_x_;
        query_.grow(1);
        sync();  // no kernel of the stream reads the previous one any more
        cuda_detail::check(cudaMemcpy(query_.data(), &h, sizeof h, cudaMemcpyHostToDevice),
                           "cudaMemcpy (ray query)");
    }
    template <typename T>
    Array<T> array() {
        return Array<T>(&meter_);
    }
    MemoryMeter& meter() { return meter_; }
    cudaStream_t stream() const { return stream_; }
    const char* name() const { return "cuda"; }
    void sync() { cuda_detail::check(cudaStreamSynchronize(stream_), "cudaStreamSynchronize"); }

    // Every kernel of the executor (each() and CUB's) runs on the one stream, in order: kernels
    // using SceneView's per-thread scratch (program registers, cis candidates, mix leaves)
    // never overlap, so they share its max_threads_ columns; the CUDA renderer sets the cap
    // once it allocates any of them (integrator/thread_scratch.h).
    template <typename F>
    void each(int n, F f, int block = 128) {
        use_device();
        cuda_detail::each(stream_, n, f, block, max_threads_);
    }
    void set_max_threads(int threads) { max_threads_ = threads; }

    // ---- reductions (one atomic per warp) ----
    template <typename F>
    int64_t count(int n, F pred) {
        unsigned long long* ctr = counter();
        each(n, [=] __device__(int k) {
            if (pred(k)) cuda_detail::warp_count(ctr);
        });
        return int64_t(read_counter());
    }
    template <typename F>
    int64_t sum_of(int n, F value) {  // value(k) -> an integer >= 0
        unsigned long long* ctr = counter();
        each(n, [=] __device__(int k) { cuda_detail::warp_add(ctr, (unsigned long long)value(k)); });
        return int64_t(read_counter());
    }
    template <typename T>
    int64_t sum(const T* in, int n) {  // of values >= 0 (flags and counts): unsigned counters
        return sum_of(n, [=] __device__(int k) { return in[k]; });
    }
    template <typename F>
    uint32_t bits_or(int n, F bits) {
        unsigned* mask = reinterpret_cast<unsigned*>(counter());
        each(n, [=] __device__(int k) { cuda_detail::warp_or(mask, bits(k)); });
        return uint32_t(read_counter());
    }

    // ---- exclusive scan (in and out differ); returns the total ----
    int64_t exclusive_scan(const int32_t* in, int n, int32_t* out) {
        if (n <= 0) return 0;
        cub_run("DeviceScan", [&](void* t, size_t& bytes) {
            return cub::DeviceScan::ExclusiveSum(t, bytes, in, out, n, stream_);
        });
        int32_t last[2];
        cuda_detail::check(cudaMemcpyAsync(&last[0], out + n - 1, sizeof(int32_t),
                                           cudaMemcpyDeviceToHost, stream_), "readback");
        cuda_detail::check(cudaMemcpyAsync(&last[1], in + n - 1, sizeof(int32_t),
                                           cudaMemcpyDeviceToHost, stream_), "readback");
        sync();
        return int64_t(last[0]) + last[1];
    }

    // ---- stable select (flags per item, or per slot through the queue) ----
    int select_flagged(const int32_t* in, const uint8_t* flags, int n, int32_t* out,
                       bool flags_of_item = true) {
        if (n <= 0) return 0;
        const uint8_t* f = flags;
        if (!flags_of_item) {
            flags_.grow(size_t(n));
            uint8_t* g = flags_.data();
            each(n, [=] __device__(int k) { g[k] = flags[in[k]]; });
            f = g;
        }
        int* count = reinterpret_cast<int*>(small_.data());
        cub_run("DeviceSelect", [&](void* t, size_t& bytes) {
            return cub::DeviceSelect::Flagged(t, bytes, in, f, out, count, n, stream_);
        });
        return int(read_counter_int(count));
    }

    // ---- stable radix sort of pairs on key bits [begin_bit, end_bit), in place ----
    void sort_pairs(uint32_t* keys, int32_t* values, int n, int begin_bit, int end_bit) {
        if (n < 2 || end_bit <= begin_bit) return;
        scratch_keys_.grow(size_t(n));
        scratch_values_.grow(size_t(n));
        uint32_t* ko = scratch_keys_.data();
        int32_t* vo = scratch_values_.data();
        cub_run("DeviceRadixSort", [&](void* t, size_t& bytes) {
            return cub::DeviceRadixSort::SortPairs(t, bytes, keys, ko, values, vo, n, begin_bit,
                                                   end_bit, stream_);
        });
        cuda_detail::check(cudaMemcpyAsync(keys, ko, size_t(n) * sizeof(uint32_t),
                                           cudaMemcpyDeviceToDevice, stream_), "sort copy");
        cuda_detail::check(cudaMemcpyAsync(values, vo, size_t(n) * sizeof(int32_t),
                                           cudaMemcpyDeviceToDevice, stream_), "sort copy");
        sync();
    }

    // ---- ray queries over [0, n): ray_of(k) -> Ray; hit(k, t, prim, uv) / blocked(k, bool) ----
    template <typename RayOf, typename Out>
    void closest(int n, RayKind kind, RayOf ray_of, Out hit) {
        const Rays q = rays();
        each(n, [=] __device__(int k) {
            const BvhHit h = q.closest(ray_of(k), kind);
            hit(k, h.t, h.prim, h.uv);
        });
    }
    template <typename RayOf, typename Out>
    void occluded(int n, RayOf ray_of, Out blocked) {  // shadow rays
        const Rays q = rays();
        each(n, [=] __device__(int k) { blocked(k, q.occluded(ray_of(k), RayKind::kShadow)); });
    }

    // A ray query one thread of an each() makes: value-captured by the schedule's kernels (one
    // pointer: cuda_detail::RayQuery in device memory).
    struct Rays {
        const cuda_detail::RayQuery* q;
        __device__ bool occluded(const Ray& r, RayKind kind) const {
            return cuda_detail::query_occluded(q, r, int(kind));
        }
        __device__ BvhHit closest(const Ray& r, RayKind kind) const {  // pt_shadow_medium
            return cuda_detail::query_closest(q, r, int(kind));
        }
        // a shadow ray through media: blocked, or the volume boundaries it crosses (pt_volume.h);
        // with two levels or strands not gathered (n -1: the caller's loop of closest queries,
        // as BvhAccel does for two levels)
        __device__ bool occluded_collect(const Ray& r, BoundaryHits* out) const {
            return cuda_detail::query_occluded_collect(q, r, out);
        }
    };
    Rays rays() const { return Rays{query_.data()}; }

    // ---- light-tracing splats (double atomics); with `slots`, item k is slot slots[k] ----
    void splat(int n, const uint8_t* valid, const Vec2* xy, const Vec3* value,
               const CameraView& cam, double scale, double* image,
               const int32_t* slots = nullptr) {
        each(n, [=] __device__(int k) {
            const int i = slots ? slots[k] : k;
            if (!valid[i]) return;
            const Vec3 v = value[i];
            splat_pixels(cam, xy[i], scale, [&](int pixel, double f) {
                atomicAdd(image + 3 * size_t(pixel) + 0, f * v.x);
                atomicAdd(image + 3 * size_t(pixel) + 1, f * v.y);
                atomicAdd(image + 3 * size_t(pixel) + 2, f * v.z);
            });
        });
    }

    template <typename F>
    void timed(double& acc, F&& f) {
        const auto t = std::chrono::steady_clock::now();
        f();
        sync();
        acc += std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
    }

    // ---- budget and out-of-memory policy ----
    static CacheCosts cache_costs(bool bdpt_index) { return lantern::cache_costs(bdpt_index); }
    // Out of GPU memory arrives as CudaUnavailable: the renderer halves its paths in flight and
    // the cache budget, down to a floor, then the session goes on on the CPU.
    static bool out_of_memory(const std::exception& e) {
        return dynamic_cast<const CudaUnavailable*>(&e) != nullptr;
    }

    // A CUB device call: its scratch-size query, then the call on the shared scratch.
    template <typename F>
    void cub_run(const char* what, F&& call) {
        use_device();
        size_t bytes = 0;
        cuda_detail::check(call(static_cast<void*>(nullptr), bytes), what);
        temp_.grow(std::max<size_t>(bytes, 1));
        cuda_detail::check(call(static_cast<void*>(temp_.data()), bytes), what);
    }
    unsigned long long* counter() {
        cuda_detail::check(cudaMemsetAsync(small_.data(), 0, sizeof(unsigned long long), stream_),
                           "cudaMemsetAsync");
        return small_.data();
    }
    unsigned long long read_counter() {
        cuda_detail::check(cudaMemcpyAsync(host_, small_.data(), sizeof(unsigned long long),
                                           cudaMemcpyDeviceToHost, stream_), "readback");
        sync();
        return host_[0];
    }
    int read_counter_int(const int* d) {
        cuda_detail::check(cudaMemcpyAsync(host_, d, sizeof(int), cudaMemcpyDeviceToHost, stream_),
                           "readback");
        sync();
        return *reinterpret_cast<const int*>(host_);
    }

    int device_ = 0;
    int max_threads_ = 0;  // threads per launch at most (0: one per item)
    cudaStream_t stream_ = nullptr;
    MemoryMeter meter_;
    Array<unsigned long long> small_;
    Array<uint8_t> temp_, flags_;
    Array<uint32_t> scratch_keys_;
    Array<int32_t> scratch_values_;
    unsigned long long* host_ = nullptr;
    BvhView bvh_{};
    SceneView scene_{};
    SceneQueryView x_{};
    int32_t has_x_ = 0;
    Array<cuda_detail::RayQuery> query_;  // one, what Rays points at
};

}  // namespace lantern
