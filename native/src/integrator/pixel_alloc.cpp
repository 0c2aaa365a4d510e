// ConnectionAllocation (pixel_alloc.h): the pilot's checkerboards, its estimates, the choice.
#include "integrator/pixel_alloc.h"

#include <algorithm>

#include "integrator/allocation.h"
#include "integrator/session.h"
#include "scene/scene_view.h"

namespace lantern {

ConnectionAllocation::ConnectionAllocation(int width, int height, int connections,
                                           int candidates, bool allow_zero)
    : w_(width), h_(height), n_(connections), m_(candidates) {
    low_n_ = allow_zero ? 0 : 1;
    low_m_ = allow_zero ? 0 : std::min(candidates, 2);
    map_.assign(size_t(w_) * h_ * 2, 0);
    for (int k = 0; k < 2; ++k) {
        sum_[k].assign(size_t(w_) * h_, 0.0);
        sum2_[k].assign(size_t(w_) * h_, 0.0);
        count_[k].assign(size_t(w_) * h_, 0);
    }
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
    for (int y = 0; y < h_; ++y)
        for (int x = 0; x < w_; ++x) {
            const bool full = (x + y + seen_) % 2 == 1;
            uint8_t* e = &map_[2 * (size_t(y) * w_ + x)];
            e[0] = uint8_t(full ? n_ : low_n_);
            e[1] = uint8_t(full ? m_ : low_m_);
        }
}

void ConnectionAllocation::observe(const double* sum, int spp, const SessionStats& before,
                                   const SessionStats& after) {
    if (!piloting() || !sum) return;
    int64_t full = 0;
    for (int y = 0; y < h_; ++y)
        for (int x = 0; x < w_; ++x) {
            const size_t p = size_t(y) * w_ + x;
            const int k = (x + y + seen_) % 2 == 1 ? 1 : 0;  // (pilot_map's)
            full += k;
            const double* c = sum + 3 * p;
            const double v = (0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]) / spp;
            sum_[k][p] += v;
            sum2_[k][p] += v * v;
            ++count_[k][p];
        }
    const auto rays = [](const SessionStats& s) {
        return double(s.rays_camera + s.rays_indirect + s.rays_shadow + s.rays_light +
                      s.rays_connection + s.rays_light_tracing);
    };
    const double conn = double(after.rays_connection - before.rays_connection) +
                        Allocation::kCandidateCost *
                            double(after.cis_candidates - before.cis_candidates);
    const double all = rays(after) - rays(before) +
                       Allocation::kCandidateCost *
                           double(after.cis_candidates - before.cis_candidates);
    base_work_ += all - conn;
    conn_work_ += conn;
    samples_ += int64_t(w_) * h_ * spp;
    full_samples_ += full * spp;
    ++seen_;
    if (piloting())
        pilot_map();
    else
        decide();
}

void ConnectionAllocation::decide() {
    // cost of a pixel sample: the low setting's (connections of the low pixels, N = 1, are
    // counted as the full ones' per connection: a small share), the full setting's
    const double c_low = base_work_ / double(std::max<int64_t>(samples_, 1));
    const double c_full = c_low + conn_work_ / double(std::max<int64_t>(full_samples_, 1));
    for (int ty = 0; ty < h_; ty += kTile)
        for (int tx = 0; tx < w_; tx += kTile) {
            double var[2] = {0.0, 0.0};
            for (int y = ty; y < std::min(h_, ty + kTile); ++y)
                for (int x = tx; x < std::min(w_, tx + kTile); ++x) {
                    const size_t p = size_t(y) * w_ + x;
                    for (int k = 0; k < 2; ++k) {
                        const int n = count_[k][p];
                        if (n < 2) continue;
                        const double mean = sum_[k][p] / n;
                        var[k] += std::max(0.0, (sum2_[k][p] - n * mean * mean) / (n - 1));
                    }
                }
            const bool full = var[1] * c_full < var[0] * c_low;
            for (int y = ty; y < std::min(h_, ty + kTile); ++y)
                for (int x = tx; x < std::min(w_, tx + kTile); ++x) {
                    uint8_t* e = &map_[2 * (size_t(y) * w_ + x)];
                    e[0] = uint8_t(full ? n_ : low_n_);
                    e[1] = uint8_t(full ? m_ : low_m_);
                }
        }
    for (int k = 0; k < 2; ++k) {  // no longer needed
        std::vector<double>().swap(sum_[k]);
        std::vector<double>().swap(sum2_[k]);
        std::vector<int32_t>().swap(count_[k]);
    }
}

double ConnectionAllocation::mean_connections() const {
    double s = 0.0;
    for (size_t p = 0; p < map_.size(); p += 2) s += map_[p];
    return map_.empty() ? 0.0 : s / double(map_.size() / 2);
}

}  // namespace lantern
