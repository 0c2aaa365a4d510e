// The schedule of the bidirectional integrators (bdpt, lvc, cis): Algorithms 1 and 2 of the paper.
// One iteration = a light pass over L = width x height x spp_per_iteration light paths (trace,
// sort, shade, store vertices into the cache in queue order, splat to the camera), then a camera
// pass in chunks (trace, sort, shade = emission + next event + connections + next bounce, then
// all shadow rays of the bounce as one batch, compact). Every reduction runs in queue order, so
// the image has the same bits for any thread count.
#include <algorithm>
#include <chrono>
#include <cmath>

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

int cache_samples_per_pass(double budget, double vertices_per_path, int max_depth, int spp_it,
                           int width, int height, const char* what, bool* warned,
                           std::vector<std::string>& warnings) {
    const double vpp = vertices_per_path > 0.0 ? vertices_per_path : std::min(max_depth - 1, 4);
    const double per_spp = double(width) * height *
                           (std::max(vpp, 0.5) * sizeof(LightVertex) + 2 * sizeof(int32_t));
    const int per_pass = int(std::clamp(budget / per_spp, 1.0, double(spp_it)));
    if (per_pass < spp_it && !*warned) {
        *warned = true;
        warnings.push_back(std::string(what) + ": " + std::to_string(spp_it) +
                           " samples per iteration run as passes of " + std::to_string(per_pass) +
                           " to stay within " + std::to_string(int(budget / (1 << 20))) + " MiB");
    }
    return per_pass;
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

bool Session::run_bdpt_iteration() {
    const int spp_it = settings_.spp_per_iteration;
    const int64_t light_paths = int64_t(width_) * height_ * spp_it;
    // ---- MIS count of a connection, r = N L / |C| ----
    // bdpt connects to every vertex of one light path: r = 1. lvc and cis take N picks out of
    // |C| vertices from L paths. r comes from the previous iteration's cache (the first
    // iteration: a small pilot light pass with its own random numbers), so the MIS weights never
    // depend on the paths they weight: any fixed r keeps the weights a partition of unity.
    auto t = Clock::now();
    if (mode_ == kBdptOwnPath) {
        mis_r_ = 1.0f;
    } else {
        if (!(vertices_per_path_ >= 0.0)) {
            const int pilot = int(std::min<int64_t>(light_paths, 1 << 14));
            pilot_ = true;
            cache_.clear();
            run_light_chunk(0, pilot);
            pilot_ = false;
            vertices_per_path_ = double(pilot_count_) / pilot;
            if (cancel_.load()) return false;
        }
        mis_r_ = vertices_per_path_ > 0.0 ? float(settings_.connections / vertices_per_path_)
                                          : 1.0f;
    }
    // ---- light pass ----
    cache_.clear();
    for (int64_t p0 = 0; p0 < light_paths; p0 += kChunkPaths) {
        run_light_chunk(p0, int(std::min<int64_t>(kChunkPaths, light_paths - p0)));
        if (cancel_.load()) return false;
    }
    stats_.cache_vertices = int64_t(cache_.size());
    vertices_per_path_ = double(cache_.size()) / double(light_paths);
    stats_.time_light_pass += seconds_since(t);
    t = Clock::now();
    if (mode_ == kBdptOwnPath) {
        path_offset_.assign(size_t(light_paths) + 1, 0);
        for (const LightVertex& v : cache_) ++path_offset_[size_t(v.path) + 1];
        for (size_t k = 1; k < path_offset_.size(); ++k) path_offset_[k] += path_offset_[k - 1];
        path_vertex_.resize(cache_.size());
        std::vector<int32_t> fill(path_offset_.begin(), path_offset_.end() - 1);
        for (size_t k = 0; k < cache_.size(); ++k) path_vertex_[fill[cache_[k].path]++] = int32_t(k);
    }
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
        if (cache_.size() + add > cache_.capacity())
            cache_.reserve(std::max(cache_.size() + add, 2 * cache_.capacity()));
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
