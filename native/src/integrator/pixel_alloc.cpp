// ConnectionAllocation (pixel_alloc.h): the range of settings, the pilot's pattern, the pairs'
// variances, the counters' costs, the choice and its repetition.
#include "integrator/pixel_alloc.h"

#include <algorithm>

#include "integrator/session.h"
#include "scene/scene_view.h"

namespace lantern {

ConnectionAllocation::ConnectionAllocation(int width, int height, int connections,
                                           int candidates, bool allow_zero)
    : w_(width), h_(height) {
    tiles_x_ = (w_ + kTile - 1) / kTile;
    tiles_y_ = (h_ + kTile - 1) / kTile;
    const int n = std::max(1, connections), m = std::max(1, candidates);
    const int range[4][2] = {{allow_zero ? 0 : 1, allow_zero ? 0 : std::min(m, 2)},
                             {std::max(1, n / 2), std::max(1, m / 2)},
                             {n, m},
                             {std::min(64, 2 * n), std::min(64, 2 * m)}};
    for (const auto& s : range) {
        bool dup = false;
        for (size_t k = 0; k < set_n_.size(); ++k)
            dup = dup || (set_n_[k] == s[0] && (s[0] == 0 || set_m_[k] == s[1]));
        if (dup) continue;
        set_n_.push_back(s[0]);
        set_m_.push_back(s[0] > 0 ? s[1] : 0);
    }
    for (size_t k = 0; k < set_n_.size(); ++k)
        if (set_n_[k] == n) full_ = int(k);
    const size_t px = size_t(w_) * h_, nk = set_n_.size();
    pilot_ = kPilot;
    map_.assign(px * 2, 0);
    setting_.assign(px, 0);
    tile_choice_.assign(size_t(tiles_x_) * tiles_y_, -1);
    pending_.assign(px, 0.0f);
    pending_k_.assign(px, int8_t(-1));
    pair_sum_.assign(tile_choice_.size() * nk, 0.0);
    pair_count_.assign(tile_choice_.size() * nk, 0);
    pilot_map();
}

bool ConnectionAllocation::zero_allowed(const SceneView& s) {
    for (int k = 0; k < s.num_lights; ++k) {
        const Light& l = s.lights[k];
        if ((l.type == kLightPoint || l.type == kLightSpot) && !(l.radius > 0.0f)) return false;
        if (l.type == kLightSun && l.cos_sun >= 1.0f) return false;
    }
    return true;
}

void ConnectionAllocation::pilot_map() {
    const int nk = int(set_n_.size());
    for (int y = 0; y < h_; ++y)
        for (int x = 0; x < w_; ++x) {
            const size_t p = size_t(y) * w_ + x;
            const int k = (x + 2 * y + seen_ / 2) % nk;  // (two iterations, the same k)
            setting_[p] = uint8_t(k);
            map_[2 * p] = uint8_t(set_n_[k]);
            map_[2 * p + 1] = uint8_t(set_m_[k]);
        }
}

void ConnectionAllocation::fill_tile(int tx, int ty, int k) {
    for (int y = ty * kTile; y < std::min(h_, (ty + 1) * kTile); ++y)
        for (int x = tx * kTile; x < std::min(w_, (tx + 1) * kTile); ++x) {
            const size_t p = size_t(y) * w_ + x;
            setting_[p] = uint8_t(k);
            map_[2 * p] = uint8_t(set_n_[k]);
            map_[2 * p + 1] = uint8_t(set_m_[k]);
        }
}

void ConnectionAllocation::observe(const double* sum, int spp, const SessionStats& before,
                                   const SessionStats& after) {
    if (!sum) return;
    const int nk = int(set_n_.size());
    double sn = 0.0, sm = 0.0;
    for (int y = 0; y < h_; ++y)
        for (int x = 0; x < w_; ++x) {
            const size_t p = size_t(y) * w_ + x;
            const int k = setting_[p];
            sn += set_n_[k];
            sm += set_m_[k];
            const double* c = sum + 3 * p;
            const float v = float((0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]) / spp);
            if (pending_k_[p] == k) {  // the second of a pair
                const double d = double(v) - double(pending_[p]);
                const size_t t = size_t(tile_of(x, y)) * nk + k;
                pair_sum_[t] += 0.5 * d * d;
                ++pair_count_[t];
                pending_k_[p] = -1;
            } else {
                pending_[p] = v;
                pending_k_[p] = int8_t(k);
            }
        }
    const auto rays = [](const SessionStats& s) {
        return double(s.rays_camera + s.rays_indirect + s.rays_shadow + s.rays_light +
                      s.rays_connection + s.rays_light_tracing);
    };
    const double conn = kConnectionRayCost * double(after.rays_connection - before.rays_connection);
    const double cand = kCandidateCost * double(after.cis_candidates - before.cis_candidates);
    work_ += rays(after) - rays(before) - double(after.rays_connection - before.rays_connection) +
             conn + cand;
    conn_work_ += conn;
    cand_work_ += cand;
    samples_ += double(w_) * h_ * spp;
    sum_n_ += sn * spp;
    sum_m_ += sm * spp;
    ++seen_;
    if (piloting())
        pilot_map();
    else if (seen_ == pilot_ || (seen_ >= 2 * pilot_ && (seen_ & (seen_ - 1)) == 0))
        decide();  // at the pilot's end, then at iterations 8, 16, 32, ...
}

void ConnectionAllocation::decide() {
    const int nk = int(set_n_.size());
    const size_t nt = tile_choice_.size();
    // cost of a pixel sample in setting k: base + N x per unit of N + M x per unit of M
    const double per_n = sum_n_ > 0.0 ? conn_work_ / sum_n_ : 0.0;
    const double per_m = sum_m_ > 0.0 ? cand_work_ / sum_m_ : 0.0;
    const double base = std::max(0.0, work_ - conn_work_ - cand_work_) / std::max(samples_, 1.0);
    std::vector<double> cost(nk);
    for (int k = 0; k < nk; ++k) cost[k] = base + set_n_[k] * per_n + set_m_[k] * per_m;
    // per tile and setting: variance (sum over its pixels) and cost of one iteration; a
    // setting without pairs in a tile is never chosen there
    std::vector<double> var(nt * nk, -1.0), tc(nt * nk, 0.0);
    for (int ty = 0; ty < tiles_y_; ++ty)
        for (int tx = 0; tx < tiles_x_; ++tx) {
            const size_t t = size_t(ty) * tiles_x_ + tx;
            const double pixels = double(std::min(w_, (tx + 1) * kTile) - tx * kTile) *
                                  double(std::min(h_, (ty + 1) * kTile) - ty * kTile);
            for (int k = 0; k < nk; ++k) {
                const int64_t n = pair_count_[t * nk + k];
                if (n > 0) var[t * nk + k] = pair_sum_[t * nk + k] / double(n) * pixels;
                tc[t * nk + k] = cost[k] * pixels;
            }
        }
    // argmin over maps of V x C: each tile argmin V + lambda C, lambda = V / C of the map
    std::vector<int8_t> choice(tile_choice_);
    for (size_t t = 0; t < nt; ++t)
        if (choice[t] < 0 || var[t * nk + choice[t]] < 0.0) choice[t] = int8_t(full_);  // (a start: (N, M))
    for (int round = 0; round < 32; ++round) {
        double v = 0.0, c = 0.0;
        for (size_t t = 0; t < nt; ++t) {
            v += std::max(0.0, var[t * nk + choice[t]]);
            c += tc[t * nk + choice[t]];
        }
        const double lambda = c > 0.0 ? v / c : 0.0;
        bool changed = false;
        for (size_t t = 0; t < nt; ++t) {
            int best = choice[t];
            double best_f = var[t * nk + best] >= 0.0
                                ? var[t * nk + best] + lambda * tc[t * nk + best]
                                : 1e300;
            for (int k = 0; k < nk; ++k) {
                if (var[t * nk + k] < 0.0) continue;
                const double f = var[t * nk + k] + lambda * tc[t * nk + k];
                if (f < best_f) best = k, best_f = f;
            }
            changed = changed || best != choice[t];
            choice[t] = int8_t(best);
        }
        if (!changed) break;
    }
    tile_choice_ = choice;
    for (int ty = 0; ty < tiles_y_; ++ty)
        for (int tx = 0; tx < tiles_x_; ++tx)
            fill_tile(tx, ty, tile_choice_[size_t(ty) * tiles_x_ + tx]);
    ++choices_;
}

double ConnectionAllocation::mean_connections() const {
    double s = 0.0;
    for (size_t p = 0; p < map_.size(); p += 2) s += map_[p];
    return map_.empty() ? 0.0 : s / double(map_.size() / 2);
}

std::vector<int64_t> ConnectionAllocation::setting_pixels() const {
    std::vector<int64_t> n(set_n_.size(), 0);
    for (uint8_t k : setting_) ++n[k];
    return n;
}

}  // namespace lantern
