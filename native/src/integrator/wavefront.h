// The wavefront schedule, written once for every backend (issue 13): Wavefront<Exec> owns the
// slot arrays, the queues and the light vertex cache in the executor's memory; the schedule
// (this file's stages, schedule_pt.h, schedule_lt.h, schedule_bdpt.h) is plain host code that
// calls the executor's primitives (backend/cpu/cpu_exec.h, backend/cuda/cuda_exec.cuh) with
// kernels written as LANTERN_KERNEL lambdas over the host+device stages of pt.h, lt.h, bdpt.h.
// Kernels capture by value only: slot pointers, PathState / BdptState, settings, the scene view
// and the executor's ray queries, never the Wavefront (its arrays cannot be copied) or `this`.
// Every queue is rebuilt by a stable select and every reduction is an integer one, so the CPU's
// images have the same bits for any thread count. Host code.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "integrator/bdpt.h"
#include "integrator/lt.h"
#include "integrator/path_state.h"
#include "integrator/session.h"
#include "integrator/wavefront_cache.h"

#if defined(__CUDACC__)
#define LANTERN_KERNEL [=] __device__
#else
#define LANTERN_KERNEL [=]
#endif

namespace lantern {

inline int bits_for(uint32_t v) {  // bits to write 0..v
    int b = 0;
    while (b < 32 && (v >> b) != 0) ++b;
    return b;
}

// What one step asks of the schedule; the backend sets its sizes and budget.
struct WavefrontStep {
    WavefrontStep(const SessionSettings& s, int w, int h, uint64_t it, double* out,
                  SessionStats* st, const std::atomic<bool>* c, std::vector<std::string>* warn)
        : set(s), width(w), height(h), iteration(it), sum(out), stats(st), cancel(c),
          warnings(warn) {}
    SessionSettings set;            // spp_per_iteration is a pass's while a pass runs
    int width = 0, height = 0;
    uint64_t iteration = 0;         // random-number stream of the running pass
    double* sum = nullptr;          // the iteration's sum in the executor's memory (3 per pixel)
    SessionStats* stats = nullptr;
    const std::atomic<bool>* cancel = nullptr;
    std::vector<std::string>* warnings = nullptr;
    int chunk_paths = 1 << 18;      // paths in flight per chunk
    int shadow_budget = 1 << 21;    // connection slots per camera chunk
    double cache_budget = 0.0;      // bytes of a pass's cache and its bdpt index
    const char* cache_name = "light vertex cache";
    // adaptive sampling (integrator/adaptive.h): the camera pass's pixels, in order, in the
    // executor's memory; null: every pixel. Light passes still start on every light sample.
    const int32_t* pixel_list = nullptr;
    int64_t pixel_count = 0;
    int64_t camera_pixels() const {
        return pixel_list ? pixel_count : int64_t(width) * int64_t(height);
    }
    bool cancelled() const { return cancel->load(); }
    PtSettings pt_settings() const {  // the camera paths' (pt) and the light paths' (lt)
        return PtSettings{set.max_depth, set.rr_depth, set.spp_per_iteration, set.seed, iteration,
                          set.light_candidates};
    }
};

template <class Exec>
struct Wavefront {
    template <typename T>
    using Array = typename Exec::template Array<T>;

    // ---- slots (PathState, LightPathState, BdptState) and queues ----
    Array<Vec3> ray_o, ray_d, throughput, radiance, shadow_o, shadow_d, shadow_c, power;
    Array<Vec3> prev_p, prev_n;  // PathState::prev_p / prev_n (the light tree's MIS)
    Array<float> ray_tmin, ray_tmax, prev_pdf, hit_t, shadow_tmax, dvcm, dvc, dpt0, dpt1;
    Array<Rng> rng;
    Array<int32_t> depth, hit_prim, queue, next_queue, flag, scan, light_id, conn_n;
    Array<int32_t> medium, shadow_medium;
    Array<int32_t> shadow_light;  // PathState::shadow_light (pt, shadow linking)  // PathState::medium / shadow_medium (pt in media)
    Array<Vec2> hit_uv, splat_xy;
    Array<uint8_t> alive, dropped, shadow_valid, visible, store, world_hidden, ray_kind;
    Array<uint8_t> recv_set;  // PathState::recv_set (pt, light linking)
    Array<uint32_t> keys;
    // PathState::vshadow_* (pt's equiangular shadow rays in media): grown only when `media`
    Array<Vec3> vshadow_o, vshadow_d, vshadow_c;
    Array<float> vshadow_tmax;
    Array<int32_t> vshadow_medium, vshadow_light;
    Array<uint8_t> vshadow_valid;
    Array<Vec3> walk_tau;  // PathState::walk_tau / walk_t0 (lt's first segment in media)
    Array<float> walk_t0;
    bool media = false;  // set by the schedule before resize: the scene has media
    // set by lt's schedule before resize: a shadow-linked light in media (walk_tau, walk_t0)
    bool lt_walk = false;
    // set by pt's schedule before resize: a light is shadow-linked (PathState::shadow_mis)
    bool linked = false;
    Array<float> shadow_mis;
    // set by the bidirectional camera pass before resize: an object casts no shadow (without
    // media; BdptState::shadow_wn then holds next event's ratio, bidir_no_shadow.h)
    bool no_shadow = false;
    // BdptState's media fields (bdpt_medium.h): grown only when `media` and bidirectional
    Array<float> seg_fwd, seg_rev, shadow_wn, shadow_wf;
    Array<int32_t> seg_flags, shadow_kind;
    Array<float> conn_wn, conn_wf;  // n x conn_cap, as conn_c
    Array<int32_t> conn_kind, conn_medium;
    Array<Vec3> shadow_mom, conn_mom;  // (moments in media: bdpt_medium_finish_c)
    Array<LightVertex> vertex;
    Array<Vec3> conn_o, conn_d, conn_c;  // n x conn_cap connection slots
    Array<float> conn_tmax;
    Array<uint8_t> conn_vis;             // GPU: n x (conn_cap + 1) shadow results
    // camera pass: each slot's vertex for the events stage (BdptState::cam_z, cam_rng, cam_on)
    Array<CameraVertex> cam_z;
    Array<Rng> cam_rng;
    Array<uint8_t> cam_on;
    // subsurface: the walk exits' white Lambert lobe, one Material the exit stage points its
    // camera vertex at (bdpt_sss_exit; off a GPU thread's stack)
    Array<Material> sss_white;
    int cap = 0;
    PathState ps{};
    BdptState bs{};

    // ---- the light vertex cache and its bdpt index, on a meter of their own ----
    MemoryMeter cache_meter;
    Array<LightVertex> cache;
    int64_t cache_size = 0;
    Array<uint32_t> path_key;
    Array<int32_t> path_vertex, path_offset;

    // ---- what the schedule carries across steps ----
    bool bidirectional = false, sort = false, pilot = false;
    bool split_warned = false, restart_warned = false;
    int mode = 0, conn_cap = 0;
    float mis_r = 1.0f;
    Array<uint8_t> conn_map;  // SessionSettings::connection_map of the pass (conn_map_on)
    bool conn_map_on = false;
    double vertices_per_path = -1.0;  // cache vertices per light path (< 0: not measured)
    int64_t pilot_count = 0, pass_light_paths = 0;
    CacheCosts cache_costs{};

    template <typename F>
    void for_slots(F&& f) {  // every integrator's
        for (auto* a : {&ray_o, &ray_d, &throughput, &radiance, &shadow_o, &shadow_d, &shadow_c,
                        &power, &prev_p, &prev_n})
            f(*a);
        for (auto* a : {&ray_tmin, &ray_tmax, &prev_pdf, &hit_t, &shadow_tmax}) f(*a);
        for (auto* a : {&depth, &hit_prim, &queue, &next_queue, &flag, &scan, &medium,
                        &shadow_medium, &shadow_light})
            f(*a);
        for (auto* a : {&hit_uv, &splat_xy}) f(*a);
        for (auto* a : {&alive, &dropped, &shadow_valid, &visible, &world_hidden, &ray_kind,
                        &recv_set})
            f(*a);
        f(rng);
        f(keys);
    }
    template <typename F>
    void for_media(F&& f) {  // pt's in media
        for (auto* a : {&vshadow_o, &vshadow_d, &vshadow_c}) f(*a);
        f(vshadow_tmax);
        f(vshadow_medium);
        f(vshadow_light);
        f(vshadow_valid);
    }
    template <typename F>
    void for_bdpt(F&& f) {  // the bidirectional integrators' (connection slots apart)
        for (auto* a : {&dvcm, &dvc, &dpt0, &dpt1}) f(*a);
        for (auto* a : {&light_id, &conn_n}) f(*a);
        f(store);
        f(vertex);
    }
    template <typename F>
    void for_bdpt_media(F&& f) {  // the bidirectional integrators' in media (per slot)
        for (auto* a : {&seg_fwd, &seg_rev, &shadow_wn, &shadow_wf}) f(*a);
        for (auto* a : {&seg_flags, &shadow_kind}) f(*a);
        f(shadow_mom);
    }
    template <typename F>
    void for_state(F&& f) {
        for_slots(f);
        for_media(f);
        for_bdpt(f);
        for_bdpt_media(f);
        f(walk_tau);
        f(walk_t0);
        for (auto* a : {&conn_wn, &conn_wf}) f(*a);
        for (auto* a : {&conn_kind, &conn_medium}) f(*a);
        for (auto* a : {&conn_o, &conn_d, &conn_c, &conn_mom}) f(*a);
        f(conn_tmax);
        f(conn_vis);
        f(cam_z);
        f(cam_rng);
        f(cam_on);
        f(sss_white);
        f(shadow_mis);
    }
    // Arrays on the executor's meter; the cache's meter reports to it too.
    void bind(MemoryMeter* m) {
        for_state([&](auto& a) { a.bind(m); });
        cache_meter.parent = m;
        cache.bind(&cache_meter);
        path_key.bind(&cache_meter);
        path_vertex.bind(&cache_meter);
        path_offset.bind(&cache_meter);
    }
    void release_state() {
        for_state([](auto& a) { a.release(); });
        cap = 0;
    }
    void release_index() {
        path_key.release();
        path_vertex.release();
        path_offset.release();
    }
    void release_cache() {
        release_index();
        cache.release();
        cache_size = 0;
    }

    // Slots for n paths; conn_cap > 0: n x conn_cap connection slots (the camera pass).
    void resize(int n, int conn_slots, bool gpu) {
        const size_t m = size_t(n);  // a growth discards the contents: slots are per chunk
        for_slots([&](auto& a) { a.grow(m); });
        if (bidirectional) for_bdpt([&](auto& a) { a.grow(m); });
        if (media) for_media([&](auto& a) { a.grow(m); });
        if (lt_walk) {
            walk_tau.grow(m);
            walk_t0.grow(m);
        }
        if (media && bidirectional) for_bdpt_media([&](auto& a) { a.grow(m); });
        if (no_shadow && bidirectional && !media) shadow_wn.grow(m);
        if (linked) shadow_mis.grow(m);
        cap = std::max(cap, n);
        const size_t nc = size_t(n) * size_t(std::max(conn_slots, 1));
        if (bidirectional && conn_slots > 0) {
            conn_o.grow(nc);
            conn_d.grow(nc);
            conn_c.grow(nc);
            conn_tmax.grow(nc);
            if (gpu) conn_vis.grow(size_t(n) * (size_t(conn_slots) + 1));
            cam_z.grow(m);
            cam_rng.grow(m);
            cam_on.grow(m);
            if (media) {
                conn_wn.grow(nc);
                conn_wf.grow(nc);
                conn_kind.grow(nc);
                conn_medium.grow(nc);
                conn_mom.grow(nc);
            }
        }
        ps = PathState{ray_o.data(),      ray_d.data(),     ray_tmin.data(),   ray_tmax.data(),
                       throughput.data(), radiance.data(),  rng.data(),        depth.data(),
                       prev_pdf.data(),   alive.data(),     dropped.data(),    hit_t.data(),
                       hit_prim.data(),   hit_uv.data(),    shadow_o.data(),   shadow_d.data(),
                       shadow_tmax.data(), shadow_c.data(), shadow_valid.data(),
                       prev_p.data(),     prev_n.data(),    world_hidden.data(),
                       medium.data(),     shadow_medium.data()};
        ps.ray_kind = ray_kind.data();
        ps.recv_set = recv_set.data();
        ps.shadow_light = shadow_light.data();
        ps.shadow_mis = linked ? shadow_mis.data() : nullptr;
        if (media) {
            ps.vshadow_o = vshadow_o.data();
            ps.vshadow_d = vshadow_d.data();
            ps.vshadow_tmax = vshadow_tmax.data();
            ps.vshadow_contrib = vshadow_c.data();
            ps.vshadow_medium = vshadow_medium.data();
            ps.vshadow_valid = vshadow_valid.data();
            ps.vshadow_light = vshadow_light.data();
        }
        if (lt_walk) {
            ps.walk_tau = walk_tau.data();
            ps.walk_t0 = walk_t0.data();
        }
        bs = BdptState{dvcm.data(),     dvc.data(),      light_id.data(),   store.data(),
                       vertex.data(),   splat_xy.data(), power.data(),      std::max(conn_slots, 1),
                       conn_n.data(),   conn_o.data(),   conn_d.data(),     conn_tmax.data(),
                       conn_c.data(),   dpt0.data(),     dpt1.data()};
        bs.prev_ng = power.data();  // (the camera pass's use of the light pass's slots)
        bs.cam_z = cam_z.data();
        bs.cam_rng = cam_rng.data();
        bs.cam_on = cam_on.data();
        bs.cam_conn = light_id.data();  // (the camera pass's use of the light pass's slots)
        if (media && bidirectional) {
            bs.seg_fwd = seg_fwd.data();
            bs.seg_rev = seg_rev.data();
            bs.seg_flags = seg_flags.data();
            bs.shadow_wn = shadow_wn.data();
            bs.shadow_wf = shadow_wf.data();
            bs.shadow_kind = shadow_kind.data();
            bs.conn_wn = conn_wn.data();
            bs.conn_wf = conn_wf.data();
            bs.conn_kind = conn_kind.data();
            bs.conn_medium = conn_medium.data();
            bs.shadow_mom = shadow_mom.data();
            bs.conn_mom = conn_mom.data();
        } else if (no_shadow && bidirectional) {
            bs.shadow_wn = shadow_wn.data();
        }
    }

};

namespace wf {

// The global path index (pixel x spp + sample) of the camera pass's k-th path: through the
// adaptive pixel list when there is one.
LANTERN_HD inline int64_t camera_path(const int32_t* list, int spp, int64_t k) {
    return list ? int64_t(list[k / spp]) * spp + k % spp : k;
}

using Clock = std::chrono::steady_clock;
inline double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Closest hits of the queued slots' rays; camera rays see only camera-visible triangles.
// motion: the rays carry their path's time (motion blur, scene/motion.h).
template <class Exec>
void trace(Exec& ex, Wavefront<Exec>& w, int n, bool camera, SessionStats& stats,
           bool motion = false) {
    const PathState ps = w.ps;
    const int32_t* q = w.queue.data();
    auto hit = LANTERN_KERNEL(int k, float t, int32_t prim, Vec2 uv) {
        const int i = q[k];
        ps.hit_t[i] = t;
        ps.hit_prim[i] = prim;
        ps.hit_uv[i] = uv;
    };
    const RayKind kind = camera ? RayKind::kCamera : RayKind::kIndirect;
    ex.timed(stats.time_trace, [&] {
        if (motion) {  // each ray at its path's time (its own loop: still scenes pay nothing)
            ex.closest(
                n, kind,
                LANTERN_KERNEL(int k) {
                    const int i = q[k];
                    Ray r{ps.ray_o[i], ps.ray_d[i], ps.ray_tmin[i], ps.ray_tmax[i]};
                    r.time = motion_time(ps.rng[i]);
                    return r;
                },
                hit);
            return;
        }
        ex.closest(
            n, kind,
            LANTERN_KERNEL(int k) {
                const int i = q[k];
                return Ray{ps.ray_o[i], ps.ray_d[i], ps.ray_tmin[i], ps.ray_tmax[i]};
            },
            hit);
    });
}

// The queue's live slots, in queue order (a stable select), become the queue.
template <class Exec>
int compact(Exec& ex, Wavefront<Exec>& w, int n) {
    if (n <= 0) return 0;
    const int m = ex.select_flagged(w.queue.data(), w.ps.alive, n, w.next_queue.data(), false);
    w.queue.swap(w.next_queue);
    return m;
}

// Stable sort of the queue by the material type of each slot's hit (misses last), on the bits
// in use; skipped when one type would remain.
template <class Exec>
void sort_queue(Exec& ex, Wavefront<Exec>& w, const SceneView s, int n, SessionStats& stats) {
    if (!w.sort || n < 2) return;
    const auto t = Clock::now();
    const int32_t* q = w.queue.data();
    const int32_t* prim = w.ps.hit_prim;
    uint32_t* keys = w.keys.data();
    ex.each(n, LANTERN_KERNEL(int k) {
        const int tri = prim[q[k]];
        keys[k] = tri < 0 ? uint32_t(kMaterialTypeCount)
                          : uint32_t(s.materials[s.tri_material[tri]].type);
    });
    const uint32_t present = ex.bits_or(n, LANTERN_KERNEL(int k) { return 1u << keys[k]; });
    if (__builtin_popcount(present) <= 1) {
        ++stats.unsorted_bounces;
    } else {
        ex.sort_pairs(keys, w.queue.data(), n, 0, bits_for(uint32_t(31 - __builtin_clz(present))));
        ++stats.sorted_bounces;
    }
    stats.time_sort += seconds_since(t);
}

template <class Exec>
void count_dropped(Exec& ex, Wavefront<Exec>& w, int n, SessionStats& stats) {
    const uint8_t* d = w.ps.dropped;
    stats.nonfinite_dropped += ex.count(n, LANTERN_KERNEL(int i) { return d[i] != 0; });
}

// Adds each pixel's samples of the chunk to the iteration's sum, one item per pixel, in order.
template <class Exec>
void film(Exec& ex, Wavefront<Exec>& w, WavefrontStep& st, int64_t first_path, int n) {
    const int spp_it = st.set.spp_per_iteration;
    const int64_t p0 = first_path / spp_it;
    const Vec3* rad = w.ps.radiance;
    const int32_t* list = st.pixel_list;
    double* dst = st.sum;
    ex.timed(st.stats->time_film, [&] {
        count_dropped(ex, w, n, *st.stats);
        ex.each(n / spp_it, LANTERN_KERNEL(int p) {
            double sum[3] = {0, 0, 0};
            for (int s = 0; s < spp_it; ++s) {
                const Vec3 c = rad[size_t(p) * spp_it + s];
                sum[0] += c.x;
                sum[1] += c.y;
                sum[2] += c.z;
            }
            double* d = dst + size_t(list ? list[p0 + p] : p0 + p) * 3;
            d[0] += sum[0];
            d[1] += sum[1];
            d[2] += sum[2];
        });
    });
}

// Light tracing's camera segments against what the camera sees: visible[slot] for the splat.
// Returns how many were tested.
template <class Exec>
int64_t camera_segments(Exec& ex, Wavefront<Exec>& w, int n, SessionStats& stats) {
    const PathState ps = w.ps;
    const int32_t* q = w.queue.data();
    uint8_t* vis = w.visible.data();
    const auto rays = ex.rays();
    int64_t tested = 0;
    ex.timed(stats.time_shadow, [&] {
        tested = ex.count(n, LANTERN_KERNEL(int k) { return ps.shadow_valid[q[k]] != 0; });
        ex.each(n, LANTERN_KERNEL(int k) {
            const int i = q[k];
            uint8_t v = 0;
            if (ps.shadow_valid[i]) {
                const Ray r{ps.shadow_o[i], ps.shadow_d[i], 0.0f, ps.shadow_tmax[i]};
                v = rays.occluded(r, RayKind::kCamera) ? 0 : 1;
            }
            vis[i] = v;
        });
    });
    return tested;
}

// The bounce's visible camera splats into the iteration's sum, in queue order on the CPU.
template <class Exec>
void splat(Exec& ex, Wavefront<Exec>& w, const SceneView& s, WavefrontStep& st, int n) {
    // 1 / (L / spp): L light paths for spp camera samples a pixel (lt: L = width height spp;
    // lvc, cis: SessionSettings::light_path_fraction of that)
    const double pixels = double(st.width) * double(st.height);
    const double scale = !w.bidirectional || w.pass_light_paths == int64_t(pixels) *
                                                                     st.set.spp_per_iteration
                             ? 1.0 / pixels
                             : double(st.set.spp_per_iteration) / double(w.pass_light_paths);
    ex.splat(n, w.visible.data(), w.splat_xy.data(), w.ps.shadow_contrib, s.camera, scale,
             st.sum, w.queue.data());
}

// ---- the integrators' chunks and iterations (schedule_pt.h, schedule_lt.h, schedule_bdpt.h;
// a backend instantiates them where it includes those headers) ----
template <class Exec>
void pt_chunk(Exec& ex, Wavefront<Exec>& w, const SceneView s, WavefrontStep& st,
              int64_t first_path, int n);
template <class Exec>
void lt_chunk(Exec& ex, Wavefront<Exec>& w, const SceneView s, WavefrontStep& st,
              int64_t first_path, int n);
template <class Exec>
bool bidirectional_iteration(Exec& ex, Wavefront<Exec>& w, const SceneView& s,
                             WavefrontStep& st);

// Sets the integrator's flags (pt, lt, bdpt, lvc, cis).
template <class Exec>
void configure(Wavefront<Exec>& w, const SessionSettings& set) {
    const std::string& integ = set.integrator;
    w.bidirectional = integ == "bdpt" || integ == "lvc" || integ == "cis";
    w.mode = integ == "bdpt" ? kBdptOwnPath : integ == "lvc" ? kLvcUniform : kCisResampled;
    w.sort = set.sort < 0 ? integ == "cis" : set.sort != 0;
}

// One iteration of st.set.spp_per_iteration samples into st.sum (zeroed by the caller); false
// when cancelled. st.iteration counts the random-number streams used, as passes draw their own.
template <class Exec>
bool run_iteration(Exec& ex, Wavefront<Exec>& w, const SceneView& s, WavefrontStep& st) {
    configure(w, st.set);
    if (w.bidirectional) return bidirectional_iteration(ex, w, s, st);
    const int spp_it = st.set.spp_per_iteration;
    const bool lt = st.set.integrator == "lt";
    const int64_t pixels = lt ? int64_t(st.width) * st.height : st.camera_pixels();
    const int64_t chunk_pixels = std::max<int64_t>(1, st.chunk_paths / spp_it);
    for (int64_t p0 = 0; p0 < pixels; p0 += chunk_pixels) {
        const int64_t np = std::min(chunk_pixels, pixels - p0);
        if (lt) {
            lt_chunk(ex, w, s, st, p0 * spp_it, int(np * spp_it));
        } else {
            pt_chunk(ex, w, s, st, p0 * spp_it, int(np * spp_it));
        }
        if (st.cancelled()) return false;
    }
    ++st.iteration;
    return true;
}

}  // namespace wf
}  // namespace lantern
