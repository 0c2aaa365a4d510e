// Per-pixel adaptive sampling: the film's counts, halves and the convergence test (adaptive.h).
#include "integrator/adaptive.h"

#include <algorithm>
#include <cmath>

namespace lantern {

int adaptive_auto_min_samples(float threshold) {
    return std::max(4, int(std::ceil(16.0 / std::pow(double(threshold), 0.3))));
}

void AdaptiveFilm::configure(float threshold, int min_samples, int step) {
    threshold_ = threshold > 0.0f ? threshold : 0.0f;
    min_samples_ = !on() ? 0 : min_samples > 0 ? min_samples : adaptive_auto_min_samples(threshold);
    step_ = std::max(1, step);
}

void AdaptiveFilm::reset(int width, int height) {
    width_ = width;
    height_ = height;
    const size_t n = size_t(width) * size_t(height);
    count_.assign(n, 0);
    half_count_.assign(on() ? n : 0, 0);
    half_.assign(on() ? n * 3 : 0, 0.0);
    list_.resize(on() ? n : 0);  // off: no list, every pixel (the film pays nothing more)
    for (size_t p = 0; p < list_.size(); ++p) list_[p] = int32_t(p);
    next_check_ = min_samples_;
    max_error_ = -1.0;
}

bool adaptive_half_a(int64_t first_sample, int spp_it) {
    const uint64_t q = uint64_t(spp_it > 1 ? first_sample / spp_it : first_sample);
    return (__builtin_popcountll(q & 0xaaaaaaaaaaaaaaaaull) & 1) != 0;
}

double adaptive_error(double diff_l1, double intensity) {
    intensity = std::max(intensity, 0.0);
    return diff_l1 / (1e-4 + (intensity < 1.0 ? std::sqrt(intensity) : intensity));
}

void AdaptiveFilm::add(const double* it, std::vector<double>& accum, int spp_it,
                       int64_t first_sample) {
    if (!on()) {
        for (size_t k = 0; k < accum.size(); ++k) accum[k] += it[k];
        for (int32_t& c : count_) c += spp_it;
        return;
    }
    const bool half = adaptive_half_a(first_sample, spp_it);
    for (const int32_t p : list_) {
        double* a = accum.data() + size_t(p) * 3;
        const double* s = it + size_t(p) * 3;
        a[0] += s[0];
        a[1] += s[1];
        a[2] += s[2];
        if (half) {
            double* h = half_.data() + size_t(p) * 3;
            h[0] += s[0];
            h[1] += s[1];
            h[2] += s[2];
            half_count_[p] += spp_it;
        }
        count_[p] += spp_it;
    }
}

void AdaptiveFilm::assume_uniform(int64_t samples) {
    std::fill(count_.begin(), count_.end(), int32_t(samples));
    std::fill(half_count_.begin(), half_count_.end(), 0);
    std::fill(half_.begin(), half_.end(), 0.0);
    if (!on()) return;
    list_.resize(count_.size());
    for (size_t p = 0; p < list_.size(); ++p) list_[p] = int32_t(p);
    next_check_ = std::max<int64_t>(min_samples_, samples + 2 * step_);
}

bool AdaptiveFilm::update(const std::vector<double>& accum, int64_t frame_spp) {
    if (!on() || list_.empty() || frame_spp < next_check_) return false;
    next_check_ = frame_spp + step_;
    // ---- Cycles' error of each active pixel; inactive ones converged when they stopped ----
    const size_t n = count_.size();
    std::vector<uint8_t> noisy(n, 0);
    double worst = 0.0;
    for (const int32_t p : list_) {
        const int32_t c = count_[p], hc = half_count_[p];
        if (hc <= 0 || hc >= c) {  // no two halves yet: keeps sampling
            noisy[p] = 1;
            continue;
        }
        const double* a = accum.data() + size_t(p) * 3;
        const double* h = half_.data() + size_t(p) * 3;
        double diff = 0.0, sum = 0.0;
        for (int k = 0; k < 3; ++k) {
            const double mean = a[k] / c;
            diff += std::fabs(mean - h[k] / hc);
            sum += mean;
        }
        const double err = adaptive_error(diff, sum);
        worst = std::max(worst, err);
        noisy[p] = !(err < double(threshold_));  // NaN keeps sampling
    }
    max_error_ = worst;
    // ---- dilation: a 3x3 box around every noisy pixel keeps sampling ----
    std::vector<uint8_t> row(n, 0);
    for (int y = 0; y < height_; ++y)
        for (int x = 0; x < width_; ++x) {
            const size_t p = size_t(y) * width_ + x;
            row[p] = noisy[p] | (x > 0 ? noisy[p - 1] : 0) | (x + 1 < width_ ? noisy[p + 1] : 0);
        }
    std::vector<int32_t> next;
    next.reserve(list_.size());
    for (int y = 0; y < height_; ++y)
        for (int x = 0; x < width_; ++x) {
            const size_t p = size_t(y) * width_ + x;
            const uint8_t on_now = row[p] | (y > 0 ? row[p - width_] : 0) |
                                   (y + 1 < height_ ? row[p + width_] : 0);
            if (on_now) next.push_back(int32_t(p));
        }
    const bool changed = next != list_;
    list_.swap(next);
    return changed;
}

}  // namespace lantern
