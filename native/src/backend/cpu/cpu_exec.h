// The CPU executor: the primitives a wavefront schedule is written against (DESIGN.md: arrays
// with a memory meter, each, stable flagged select, exclusive scan, stable radix sort of
// (key, value) pairs on a bit range, integer reductions, ray queries over a queue, splats,
// readback, stage timing, the memory budget and the out-of-memory policy) on the thread pool
// and Embree or the built-in BVH. Every primitive is deterministic: blocks are cut by size, not
// by thread, and combined in block order, so results never depend on the thread count.
// backend/cuda/cuda_exec.cuh is the same interface on a GPU; tests/cpp/exec_conformance.h
// checks both against plain references.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <utility>
#include <vector>

#if defined(__unix__)
#include <unistd.h>
#endif

#include "backend/backend.h"
#include "integrator/lt.h"
#include "integrator/wavefront_cache.h"

namespace lantern {

// An array in the executor's memory (host memory here) that only grows. grow() discards the
// contents, grow_keep() keeps a prefix (the meter sees old and new together while it copies).
template <typename T>
class HostArray {
public:
    HostArray() = default;
    explicit HostArray(MemoryMeter* m) : meter_(m) {}
    HostArray(HostArray&& o) noexcept { *this = std::move(o); }
    HostArray& operator=(HostArray&& o) noexcept {
        if (this != &o) {
            release();
            p_ = std::move(o.p_);
            cap_ = o.cap_;
            meter_ = o.meter_;
            o.cap_ = 0;
        }
        return *this;
    }
    ~HostArray() { release(); }
    void bind(MemoryMeter* m) { meter_ = m; }
    T* data() const { return p_.get(); }
    size_t capacity() const { return cap_; }
    void grow(size_t n) {
        if (n <= cap_) return;
        release();
        allocate(n);
    }
    void grow_keep(size_t n, size_t keep) {
        if (n <= cap_) return;
        std::unique_ptr<T[]> old = std::move(p_);
        const size_t old_cap = cap_;
        allocate(n);  // old and new alive together: the meter holds both
        if (keep > 0) std::memcpy(p_.get(), old.get(), std::min(keep, old_cap) * sizeof(T));
        old.reset();
        if (meter_) meter_->sub(int64_t(old_cap * sizeof(T)));
    }
    void swap(HostArray& o) {
        std::swap(p_, o.p_);
        std::swap(cap_, o.cap_);
    }
    void release() {
        if (!p_) return;
        p_.reset();
        if (meter_) meter_->sub(int64_t(cap_ * sizeof(T)));
        cap_ = 0;
    }
    void upload(const T* host, size_t n, size_t at = 0) {
        if (n) std::memcpy(p_.get() + at, host, n * sizeof(T));
    }
    void download(T* host, size_t n, size_t at = 0) const {
        if (n) std::memcpy(host, p_.get() + at, n * sizeof(T));
    }

private:
    void allocate(size_t n) {
        if (meter_) meter_->add(int64_t(n * sizeof(T)));
        try {
            p_.reset(new T[n]());  // zeroed, as a std::vector's new items
        } catch (...) {
            if (meter_) meter_->sub(int64_t(n * sizeof(T)));
            throw;
        }
        cap_ = n;
    }
    std::unique_ptr<T[]> p_;
    size_t cap_ = 0;
    MemoryMeter* meter_ = nullptr;
};

class CpuExec {
public:
    template <typename T>
    using Array = HostArray<T>;
    static constexpr bool kGpu = false;
    static constexpr bool kDeterministicSplats = true;  // splats add in queue order
    static constexpr int kBlock = 1 << 14;  // items per block of a select, scan, sort, reduce

    // The primitives alone, on a pool of its own (conformance tests: no ray queries).
    explicit CpuExec(int threads) : own_(std::make_unique<ThreadPool>(threads)), pool_(own_.get()) {}
    // Ray queries through `backend` (Embree or the built-in BVH) and its pool.
    explicit CpuExec(CpuBackend& backend) : rays_(&backend), pool_(&backend.pool()) {}

    template <typename T>
    Array<T> array() {
        return Array<T>(&meter_);
    }
    MemoryMeter& meter() { return meter_; }
    int threads() const { return pool_->size(); }
    const char* name() const { return "cpu"; }
    void sync() {}

    // ---- each: f(k) for k in [0, n), any order, any thread ----
    template <typename F>
    void each(int n, F&& f, int grain = 256) {
        if (n <= 0) return;
        pool_->parallel_for(n, grain, [&](int b, int e) {
            for (int k = b; k < e; ++k) f(k);
        });
    }

    // ---- reductions over [0, n) (sums in int64, block order) ----
    template <typename F>
    int64_t count(int n, F&& pred) {
        return block_sum(n, [&](int b, int e) {
            int64_t c = 0;
            for (int k = b; k < e; ++k) c += pred(k) ? 1 : 0;
            return c;
        });
    }
    template <typename F>
    int64_t sum_of(int n, F&& value) {  // value(k) -> an integer
        return block_sum(n, [&](int b, int e) {
            int64_t c = 0;
            for (int k = b; k < e; ++k) c += int64_t(value(k));
            return c;
        });
    }
    template <typename T>
    int64_t sum(const T* in, int n) {
        return block_sum(n, [&](int b, int e) {
            int64_t c = 0;
            for (int k = b; k < e; ++k) c += int64_t(in[k]);
            return c;
        });
    }
    template <typename F>
    uint32_t bits_or(int n, F&& bits) {
        const int nb = blocks(n);
        std::vector<uint32_t> part(size_t(nb), 0u);
        each(nb, [&](int j) {
            uint32_t m = 0;
            for (int k = j * kBlock, e = std::min(n, (j + 1) * kBlock); k < e; ++k) m |= bits(k);
            part[size_t(j)] = m;
        }, 1);
        uint32_t m = 0;
        for (uint32_t p : part) m |= p;
        return m;
    }

    // ---- exclusive scan: out[k] = in[0] + ... + in[k-1]; returns the total ----
    int64_t exclusive_scan(const int32_t* in, int n, int32_t* out) {
        const int nb = blocks(n);
        std::vector<int64_t> base(size_t(nb) + 1, 0);
        each(nb, [&](int j) {
            int64_t s = 0;
            for (int k = j * kBlock, e = std::min(n, (j + 1) * kBlock); k < e; ++k) s += in[k];
            base[size_t(j) + 1] = s;
        }, 1);
        for (int j = 0; j < nb; ++j) base[size_t(j) + 1] += base[size_t(j)];
        each(nb, [&](int j) {
            int64_t s = base[size_t(j)];
            for (int k = j * kBlock, e = std::min(n, (j + 1) * kBlock); k < e; ++k) {
                const int32_t v = in[k];  // in and out may be the same array
                out[k] = int32_t(s);
                s += v;
            }
        }, 1);
        return base[size_t(nb)];
    }

    // ---- stable select: the items of `in` whose flag is set, in order; returns their count.
    // flags_of_item: flags[k] belongs to in[k]; otherwise flags are indexed by the item's value
    // (a queue of slots with per-slot flags). in and out must differ.
    int select_flagged(const int32_t* in, const uint8_t* flags, int n, int32_t* out,
                       bool flags_of_item = true) {
        const int nb = blocks(n);
        std::vector<int> base(size_t(nb) + 1, 0);
        auto flag = [&](int k) { return flags[flags_of_item ? k : in[k]] != 0; };
        each(nb, [&](int j) {
            int c = 0;
            for (int k = j * kBlock, e = std::min(n, (j + 1) * kBlock); k < e; ++k) c += flag(k);
            base[size_t(j) + 1] = c;
        }, 1);
        for (int j = 0; j < nb; ++j) base[size_t(j) + 1] += base[size_t(j)];
        each(nb, [&](int j) {
            int m = base[size_t(j)];
            for (int k = j * kBlock, e = std::min(n, (j + 1) * kBlock); k < e; ++k)
                if (flag(k)) out[m++] = in[k];
        }, 1);
        return base[size_t(nb)];
    }

    // ---- stable LSD radix sort of (keys[k], values[k]) on key bits [begin_bit, end_bit), in
    // place (scratch from this executor). Bits outside the range do not order the pairs.
    void sort_pairs(uint32_t* keys, int32_t* values, int n, int begin_bit, int end_bit);

    // ---- ray queries over [0, n): ray_of(k) -> Ray; hit(k, t, prim, uv) / blocked(k, bool) ----
    template <typename RayOf, typename Out>
    void closest(int n, RayKind kind, RayOf&& ray_of, Out&& hit) {
        each(n, [&](int k) {
            const HitRecord h = rays_->intersect(ray_of(k), kind);
            hit(k, h.t, h.prim, h.uv);
        });
    }
    template <typename RayOf, typename Out>
    void occluded(int n, RayOf&& ray_of, Out&& blocked) {
        each(n, [&](int k) { blocked(k, rays_->occluded(ray_of(k))); });
    }

    // A ray query one item of an each() can make: value-captured by the schedule's kernels.
    // occluded(r, kind): a shadow ray (kShadow), or any hit among what `kind` sees.
    struct Rays {
        const CpuBackend* b;
        HitRecord closest(const Ray& r, RayKind kind) const { return b->intersect(r, kind); }
        bool occluded(const Ray& r, RayKind kind) const {
            return kind == RayKind::kShadow ? b->occluded(r) : b->intersect(r, kind).prim >= 0;
        }
        // a shadow ray through media: blocked, or the volume boundaries it crosses (pt_volume.h)
        bool occluded_collect(const Ray& r, BoundaryHits* out) const {
            return b->occluded_collect(r, out);
        }
    };
    Rays rays() const { return Rays{rays_}; }

    // ---- light-tracing splats: for k in queue order with valid[k], value[k] through the pixel
    // filter at raster position xy[k] into image (3 doubles per pixel), scaled by `scale`.
    // With `slots`, item k reads valid, xy and value at slots[k] (a queue of path slots).
    void splat(int n, const uint8_t* valid, const Vec2* xy, const Vec3* value,
               const CameraView& cam, double scale, double* image,
               const int32_t* slots = nullptr) {
        for (int k = 0; k < n; ++k) {
            const int i = slots ? slots[k] : k;
            if (!valid[i]) continue;
            const Vec3 v = value[i];
            splat_pixels(cam, xy[i], scale, [&](int pixel, double f) {
                double* d = image + size_t(pixel) * 3;
                d[0] += f * v.x;
                d[1] += f * v.y;
                d[2] += f * v.z;
            });
        }
    }

    // ---- stage timing: f, then a synchronisation, its seconds added to acc ----
    template <typename F>
    void timed(double& acc, F&& f) {
        const auto t = std::chrono::steady_clock::now();
        f();
        sync();
        acc += std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
    }

    // ---- memory budget of a pass's light vertex cache, and the out-of-memory policy ----
    // a quarter of the physical memory, at most 4 GiB; cache_budget_mb > 0 overrides it
    static double cache_budget(int cache_budget_mb) {
        double budget = 4.0 * (1 << 30);
#if defined(__unix__)
        const double phys = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
        if (phys > 0) budget = std::min(budget, 0.25 * phys);
#endif
        if (cache_budget_mb > 0) budget = double(cache_budget_mb) * (1 << 20);
        return budget;
    }
    static CacheCosts cache_costs(bool bdpt_index) { return lantern::cache_costs(bdpt_index); }
    // Host memory runs out as std::bad_alloc: the step fails with a message that says what to
    // lower (the session keeps the image of the finished steps).
    static bool out_of_memory(const std::exception& e) {
        return dynamic_cast<const std::bad_alloc*>(&e) != nullptr;
    }

private:
    static int blocks(int n) { return n <= 0 ? 0 : (n + kBlock - 1) / kBlock; }
    template <typename F>
    int64_t block_sum(int n, F&& part_of) {
        const int nb = blocks(n);
        std::vector<int64_t> part(size_t(nb), 0);
        each(nb, [&](int j) { part[size_t(j)] = part_of(j * kBlock, std::min(n, (j + 1) * kBlock)); }, 1);
        int64_t s = 0;
        for (int64_t p : part) s += p;
        return s;
    }

    std::unique_ptr<ThreadPool> own_;
    CpuBackend* rays_ = nullptr;
    ThreadPool* pool_ = nullptr;
    MemoryMeter meter_;
    HostArray<uint32_t> sort_keys_{&meter_};
    HostArray<int32_t> sort_values_{&meter_};
};

// Passes of up to 8 bits; per block a histogram, then offsets digit-major, block-minor: each
// pass is a stable counting sort, whatever the thread count.
inline void CpuExec::sort_pairs(uint32_t* keys, int32_t* values, int n, int begin_bit,
                                int end_bit) {
    if (n < 2 || end_bit <= begin_bit) return;
    sort_keys_.grow(size_t(n));
    sort_values_.grow(size_t(n));
    uint32_t* k_in = keys;
    int32_t* v_in = values;
    uint32_t* k_out = sort_keys_.data();
    int32_t* v_out = sort_values_.data();
    const int nb = blocks(n);
    std::vector<int> hist;
    for (int bit = begin_bit; bit < end_bit; bit += 8) {
        const int width = std::min(8, end_bit - bit);
        const int radix = 1 << width;
        const uint32_t mask = uint32_t(radix - 1);
        hist.assign(size_t(nb) * radix, 0);
        each(nb, [&](int j) {
            int* h = &hist[size_t(j) * radix];
            for (int k = j * kBlock, e = std::min(n, (j + 1) * kBlock); k < e; ++k)
                ++h[(k_in[k] >> bit) & mask];
        }, 1);
        int acc = 0;  // exclusive offsets, digit-major then block
        for (int d = 0; d < radix; ++d)
            for (int j = 0; j < nb; ++j) {
                int& h = hist[size_t(j) * radix + d];
                const int c = h;
                h = acc;
                acc += c;
            }
        each(nb, [&](int j) {
            int* h = &hist[size_t(j) * radix];
            for (int k = j * kBlock, e = std::min(n, (j + 1) * kBlock); k < e; ++k) {
                const int at = h[(k_in[k] >> bit) & mask]++;
                k_out[at] = k_in[k];
                v_out[at] = v_in[k];
            }
        }, 1);
        std::swap(k_in, k_out);
        std::swap(v_in, v_out);
    }
    if (k_in != keys) {  // an odd number of passes: the result is in the scratch
        std::memcpy(keys, k_in, size_t(n) * sizeof(uint32_t));
        std::memcpy(values, v_in, size_t(n) * sizeof(int32_t));
    }
}

}  // namespace lantern
