// The schedule of the bidirectional integrators (bdpt, lvc, cis): Algorithms 1 and 2 of the paper.
// One iteration = a light pass over L = width x height x spp_per_iteration light paths (trace,
// sort, shade, store vertices into the cache in queue order, splat to the camera), then a camera
// pass in chunks (trace, sort, shade = emission + next event + connections + next bounce, then
// all shadow rays of the bounce as one batch, compact). Every reduction runs in queue order, so
// the image has the same bits for any thread count.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <new>
#include <stdexcept>

#include "backend/backend.h"
#include "integrator/session.h"

namespace lantern {

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}
constexpr int kChunkPaths = 1 << 18;
constexpr int kShadowBudget = 1 << 21;  // connection shadow-ray slots per camera chunk
}  // namespace

BdptSettings make_bdpt_settings(const SessionSettings& s, int width, int height,
                                uint64_t iteration, int mode, float r) {
    const double light_paths = double(width) * height * s.spp_per_iteration;
    BdptSettings st{};
    st.max_depth = s.max_depth;
    st.rr_depth = s.rr_depth;
    st.spp_per_iteration = s.spp_per_iteration;
    st.seed = s.seed;
    st.iteration = iteration;
    st.mode = mode;
    st.connections = s.connections;
    st.candidates = s.candidates;
    st.target = s.cis_target == "bsdf" ? kTargetBsdf : kTargetContribution;
    st.naive_ris = s.naive_ris ? 1 : 0;
    st.r = r;
    st.n_lt = float(light_paths / s.spp_per_iteration);
    st.inv_light_paths = float(1.0 / light_paths);
    return st;
}

BdptSettings Session::bdpt_settings() const {
    return make_bdpt_settings(settings_, width_, height_, iteration_, mode_, mis_r_);
}

void Session::resize_bdpt_state(int n, int conn_cap) {
    resize_state(n);
    if (int(dvcm_.size()) < n) {
        dvcm_.resize(n);
        dvc_.resize(n);
        light_id_.resize(n);
        store_.resize(n);
        vertex_.resize(n);
        conn_n_.resize(n);
        sort_tmp_.resize(n);
    }
    if (int(power_.size()) < n) {
        power_.resize(n);
        splat_xy_.resize(n);
    }
    size_t nc = size_t(n) * std::max(conn_cap, 1);
    if (conn_o_.size() < nc) {
        conn_o_.resize(nc);
        conn_d_.resize(nc);
        conn_c_.resize(nc);
        conn_tmax_.resize(nc);
    }
    bdpt_state_ = BdptState{dvcm_.data(),   dvc_.data(),
                            light_id_.data(), store_.data(),  vertex_.data(),
                            splat_xy_.data(), power_.data(),  conn_cap,       conn_n_.data(),
                            conn_o_.data(),   conn_d_.data(), conn_tmax_.data(),
                            conn_c_.data()};
}

// Stable counting sort of the queue by the material type of each slot's hit (misses last):
// a permutation of slot ids, the payload stays where it is. Skipped when one type would remain.
void Session::sort_queue(int active) {
    if (!sort_ || active < 2) return;
    auto t = Clock::now();
    const SceneView& sv = scene_->view();
    constexpr int kBuckets = kMaterialTypeCount + 1;
    int count[kBuckets] = {};
    auto type_of = [&](int slot) {
        int tri = hit_prim_[slot];
        return tri < 0 ? kMaterialTypeCount : int(sv.materials[sv.tri_material[tri]].type);
    };
    for (int k = 0; k < active; ++k) ++count[type_of(queue_[k])];
    int used = 0;
    for (int b = 0; b < kBuckets; ++b) used += count[b] > 0;
    if (used <= 1) {
        ++stats_.unsorted_bounces;
        stats_.time_sort += seconds_since(t);
        return;
    }
    int start[kBuckets];
    int acc = 0;
    for (int b = 0; b < kBuckets; ++b) {
        start[b] = acc;
        acc += count[b];
    }
    for (int k = 0; k < active; ++k) {
        int slot = queue_[k];
        sort_tmp_[start[type_of(slot)]++] = slot;
    }
    std::copy(sort_tmp_.begin(), sort_tmp_.begin() + active, queue_.begin());
    ++stats_.sorted_bounces;
    stats_.time_sort += seconds_since(t);
}

// ---- An iteration as passes within the cache budget ----
// The cache holds about L x (vertices per light path) x 96 bytes (+ the bdpt index) with
// L = pixels x spp: past the budget, the step runs as several light + camera passes of fewer
// samples each (the same estimator: more, smaller iterations). A pass whose cache would pass the
// budget after all (its paths stored more than the measured rate predicted) stops, and the step
// starts again from its first pass with the rate measured so far and passes of at most half the
// samples; the counts do not depend on scheduling, so neither do the bits.
bool Session::step_bidirectional(int spp_it) {
    if (!(vertices_per_path_ >= 0.0)) {
        measure_cache_rate();
        if (cancel_.load()) return false;
    }
    const uint64_t iteration0 = iteration_;
    const SessionStats stats0 = stats_;
    int per_pass = bdpt_samples_per_pass(spp_it);
    for (;;) {
        std::string over;
        double rate = 0.0;
        for (int done = 0; done < spp_it;) {
            const int s = std::min(per_pass, spp_it - done);
            settings_.spp_per_iteration = s;
            bool ok = false;
            try {
                ok = run_bdpt_iteration();
            } catch (const CacheOverBudget& e) {
                over = e.what();
                rate = e.vertices_per_path;
            } catch (const std::bad_alloc&) {
                settings_.spp_per_iteration = spp_it;
                release_cache();
                throw std::runtime_error(
                    "out of memory for the light vertex cache (" + std::to_string(width_) + "x" +
                    std::to_string(height_) + ", " + std::to_string(s) +
                    " samples per pass); lower the resolution or use integrator 'pt'");
            }
            settings_.spp_per_iteration = spp_it;
            if (!over.empty()) break;
            if (!ok) return false;
            ++iteration_;  // every pass draws its own random numbers
            done += s;
        }
        if (over.empty()) return true;
        release_cache();
        if (per_pass == 1)
            throw std::runtime_error(over + ", at one sample per pass: raise cache_budget_mb, "
                                            "or lower the resolution or max_depth, or use "
                                            "integrator 'pt'");
        iteration_ = iteration0;
        stats_ = stats0;
        stats_.cache_memory_peak = cache_meter_.peak;
        std::fill(iteration_sum_.begin(), iteration_sum_.end(), 0.0);
        vertices_per_path_ = std::max(vertices_per_path_, rate);
        per_pass = std::max(1, std::min(per_pass / 2, bdpt_samples_per_pass(spp_it)));
        if (!restart_warned_) {
            restart_warned_ = true;
            warnings_.push_back("light vertex cache: " + over + "; the iteration ran again in "
                                "passes of " + std::to_string(per_pass) + " samples");
        }
    }
}

// The pilot: a small light pass with its own random numbers, stored nowhere, counts the cache
// vertices per light path before the first iteration (its passes and, for lvc / cis, r).
void Session::measure_cache_rate() {
    const int64_t light_paths = int64_t(width_) * height_ * settings_.spp_per_iteration;
    const int pilot = int(std::min<int64_t>(light_paths, 1 << 14));
    pilot_ = true;
    run_light_chunk(0, pilot);
    pilot_ = false;
    if (!cancel_.load()) vertices_per_path_ = double(pilot_count_) / pilot;
}

void Session::cache_reserve(size_t vertices) {
    const size_t old = cache_.capacity();
    if (vertices <= old) return;
    cache_meter_.add(int64_t(vertices * sizeof(LightVertex)));  // old and new alive together
    cache_.reserve(vertices);
    cache_meter_.add(int64_t((cache_.capacity() - vertices) * sizeof(LightVertex)));
    cache_meter_.sub(int64_t(old * sizeof(LightVertex)));
}

void Session::release_cache(bool vertices) {
    cache_meter_.sub(int64_t((path_offset_.capacity() + path_vertex_.capacity()) * sizeof(int32_t)));
    std::vector<int32_t>().swap(path_offset_);
    std::vector<int32_t>().swap(path_vertex_);
    if (!vertices) return;
    cache_meter_.sub(int64_t(cache_.capacity() * sizeof(LightVertex)));
    std::vector<LightVertex>().swap(cache_);
}

bool Session::run_bdpt_iteration() {
    const int spp_it = settings_.spp_per_iteration;
    const int64_t light_paths = int64_t(width_) * height_ * spp_it;
    // ---- MIS count of a connection, r = N L / |C| ----
    // bdpt connects to every vertex of one light path: r = 1. lvc and cis take N picks out of
    // |C| vertices from L paths. r comes from the previous iteration's cache (the first
    // iteration: a small pilot light pass with its own random numbers), so the MIS weights never
    // depend on the paths they weight: any fixed r keeps the weights a partition of unity.
    auto t = Clock::now();
    mis_r_ = mode_ == kBdptOwnPath || !(vertices_per_path_ > 0.0)
                 ? 1.0f
                 : float(settings_.connections / vertices_per_path_);
    // ---- light pass: the cache starts at the capacity the measured rate predicts ----
    pass_light_paths_ = light_paths;
    const size_t want =
        cache_initial_capacity(vertices_per_path_, light_paths, cache_budget_, cache_costs_);
    cache_.clear();
    release_cache(false);  // the last pass's bdpt index
    if (cache_.capacity() < want ||
        cache_.capacity() > cache_max_vertices(cache_budget_, cache_costs_, double(light_paths)))
        release_cache();  // empty: released before the new one, never both at once
    cache_reserve(want);
    for (int64_t p0 = 0; p0 < light_paths; p0 += kChunkPaths) {
        run_light_chunk(p0, int(std::min<int64_t>(kChunkPaths, light_paths - p0)));
        if (cancel_.load()) return false;
    }
    stats_.cache_vertices = int64_t(cache_.size());
    vertices_per_path_ = double(cache_.size()) / double(light_paths);
    stats_.time_light_pass += seconds_since(t);
    t = Clock::now();
    if (mode_ == kBdptOwnPath) {  // the per-path index, inside the budget (cache_costs)
        path_offset_.assign(size_t(light_paths) + 1, 0);
        cache_meter_.add(int64_t(path_offset_.capacity() * sizeof(int32_t)));
        for (const LightVertex& v : cache_) ++path_offset_[size_t(v.path) + 1];
        for (size_t k = 1; k < path_offset_.size(); ++k) path_offset_[k] += path_offset_[k - 1];
        path_vertex_.resize(cache_.size());
        cache_meter_.add(int64_t(path_vertex_.capacity() * sizeof(int32_t)));
        std::vector<int32_t> fill(path_offset_.begin(), path_offset_.end() - 1);
        const int64_t fill_bytes = int64_t(fill.capacity() * sizeof(int32_t));
        cache_meter_.add(fill_bytes);
        for (size_t k = 0; k < cache_.size(); ++k) path_vertex_[fill[cache_[k].path]++] = int32_t(k);
        cache_meter_.sub(fill_bytes);
    }
    stats_.cache_memory_peak = cache_meter_.peak;
    stats_.time_cache += seconds_since(t);
    // ---- camera pass ----
    t = Clock::now();
    conn_cap_ = mode_ == kBdptOwnPath ? std::max(1, settings_.max_depth - 1)
                                      : settings_.connections;
    const int64_t pixels = int64_t(width_) * height_;
    const int chunk = std::max(spp_it, std::min(kChunkPaths, kShadowBudget / conn_cap_));
    const int64_t chunk_pixels = std::max<int64_t>(1, chunk / spp_it);
    for (int64_t q0 = 0; q0 < pixels; q0 += chunk_pixels) {
        int64_t np = std::min(chunk_pixels, pixels - q0);
        run_camera_chunk(q0 * spp_it, int(np * spp_it));
        if (cancel_.load()) return false;
    }
    stats_.time_camera_pass += seconds_since(t);
    return true;
}

void Session::run_light_chunk(int64_t first_path, int n) {
    resize_bdpt_state(n, conn_cap_);
    const SceneView& sv = scene_->view();
    BdptSettings st = bdpt_settings();
    if (pilot_) {
        st.iteration = ~uint64_t(0);  // its own random numbers
        pilot_count_ = 0;
    }
    const PathState ps = state_;
    const BdptState bs = bdpt_state_;
    auto t = Clock::now();
    backend_->for_all(n, [&](int i) {
        bdpt_light_generate(sv, ps, bs, st, i, first_path + i);
        queue_[i] = i;
    });
    stats_.time_generate += seconds_since(t);
    int active = backend_->compact(queue_.data(), n, ps.alive, next_queue_.data());
    std::swap(queue_, next_queue_);
    while (active > 0 && !cancel_.load()) {
        stats_.rays_light += active;
        trace_queue(active, false);
        sort_queue(active);
        t = Clock::now();
        backend_->for_all(active, [&](int k) {
            int i = queue_[k];
            bdpt_light_shade(sv, ps, bs, st, i, first_path + i);
        });
        stats_.time_shade += seconds_since(t);
        // store vertices in queue order: the cache grows by exactly this bounce's count
        t = Clock::now();
        size_t add = 0;
        for (int k = 0; k < active; ++k) add += store_[queue_[k]];
        if (pilot_) {
            pilot_count_ += int64_t(add);
            active = backend_->compact(queue_.data(), active, ps.alive, next_queue_.data());
            std::swap(queue_, next_queue_);
            continue;
        }
        if (cache_.size() + add > cache_.capacity())  // exact growth, or CacheOverBudget
            cache_reserve(cache_grow_capacity(cache_.size() + add, cache_.capacity(),
                                              first_path + n, pass_light_paths_, cache_budget_,
                                              cache_costs_));
        for (int k = 0; k < active; ++k) {
            int i = queue_[k];
            if (store_[i]) cache_.push_back(vertex_[i]);
        }
        stats_.time_cache += seconds_since(t);
        // light tracing: camera segments against what the camera sees, then splats in order
        stats_.rays_light_tracing += test_camera_segments(active);
        t = Clock::now();
        splat(queue_, active);
        stats_.time_splat += seconds_since(t);
        active = backend_->compact(queue_.data(), active, ps.alive, next_queue_.data());
        std::swap(queue_, next_queue_);
    }
    count_dropped(n);
}

void Session::run_camera_chunk(int64_t first_path, int n) {
    resize_bdpt_state(n, conn_cap_);
    const SceneView& sv = scene_->view();
    BdptSettings st = bdpt_settings();
    const PathState ps = state_;
    const BdptState bs = bdpt_state_;
    const LightCache cache{cache_.data(), int32_t(cache_.size()),
                           mode_ == kBdptOwnPath ? path_offset_.data() : nullptr,
                           mode_ == kBdptOwnPath ? path_vertex_.data() : nullptr};
    auto t = Clock::now();
    backend_->for_all(n, [&](int i) {
        bdpt_camera_generate(sv, ps, bs, st, i, first_path + i);
        queue_[i] = i;
    });
    stats_.time_generate += seconds_since(t);
    int active = n;
    stats_.rays_camera += n;
    bool first = true;
    while (active > 0 && !cancel_.load()) {
        trace_queue(active, first);
        sort_queue(active);
        t = Clock::now();
        backend_->for_all(active, [&](int k) {
            int i = queue_[k];
            bdpt_camera_shade(sv, ps, bs, st, cache, i, first_path + i);
        }, 64);
        stats_.time_shade += seconds_since(t);
        // every shadow ray of the bounce (next event and connections) as one batch
        t = Clock::now();
        int64_t nee = 0, conn = 0;
        for (int k = 0; k < active; ++k) {
            int i = queue_[k];
            nee += ps.shadow_valid[i];
            conn += bs.conn_n[i];
        }
        backend_->for_all(active, [&](int k) {
            int i = queue_[k];
            if (ps.shadow_valid[i]) {
                Ray r{ps.shadow_o[i], ps.shadow_d[i], 0.0f, ps.shadow_tmax[i]};
                if (!backend_->occluded(r)) add_radiance(ps, i, ps.shadow_contrib[i]);
            }
            for (int j = 0; j < bs.conn_n[i]; ++j) {
                size_t e = size_t(i) * bs.conn_cap + j;
                Ray r{bs.conn_o[e], bs.conn_d[e], 0.0f, bs.conn_tmax[e]};
                if (!backend_->occluded(r)) add_radiance(ps, i, bs.conn_c[e]);
            }
        }, 64);
        stats_.rays_shadow += nee;
        stats_.rays_connection += conn;
        stats_.time_shadow += seconds_since(t);
        active = backend_->compact(queue_.data(), active, ps.alive, next_queue_.data());
        std::swap(queue_, next_queue_);
        if (active) stats_.rays_indirect += active;
        first = false;
    }
    if (cancel_.load()) return;
    film(first_path, n);
}

}  // namespace lantern
