// Per-pixel adaptive sampling (issue 17), host code: each pixel keeps its own sample count and
// a second sum of half its samples (the "half" buffer, adaptive_half_a); every `step` samples
// past the minimum, Cycles' error (adaptive_error, I the pixel's mean, A the mean of its half)
// decides which pixels have converged, the unconverged ones are
// dilated by one pixel (a 3x3 box, so that an edge's neighbours keep sampling), and the rest
// become the camera pass's pixel list. A pixel adds an iteration's sum (camera paths and the
// light paths' splats of that iteration alike) only while it is active: each of its
// iterations is then a whole, unbiased estimate of it, and its value is their mean.
#pragma once

#include <cstdint>
#include <vector>

namespace lantern {

class AdaptiveFilm {
public:
    // threshold <= 0: off (every pixel samples every iteration). min_samples 0: Cycles'
    // automatic minimum, max(4, ceil(16 / threshold^0.3)).
    void configure(float threshold, int min_samples, int step);
    bool on() const { return threshold_ > 0.0f; }
    // Empties the film for width x height pixels: every pixel active.
    void reset(int width, int height);
    // Adds an iteration's sum (3 doubles a pixel, every pixel's) of spp_it samples, the
    // sampler's indices first_sample on, to accum for the active pixels only, and to their
    // halves when those samples are in half A.
    void add(const double* iteration_sum, std::vector<double>& accum, int spp_it,
             int64_t first_sample);
    // After add(): the convergence test when frame_spp (the iterations' samples) is due; true
    // when the active pixels changed.
    bool update(const std::vector<double>& accum, int64_t frame_spp);
    // Every pixel at `samples` (a render taken over from the GPU: no halves, checked anew).
    void assume_uniform(int64_t samples);

    // The camera pass's pixels in order; null while every pixel is active.
    const int32_t* pixel_list() const { return all_active() ? nullptr : list_.data(); }
    int64_t active_count() const { return on() ? int64_t(list_.size()) : int64_t(count_.size()); }
    bool all_active() const { return active_count() == int64_t(count_.size()); }
    bool converged() const { return on() && list_.empty(); }
    const std::vector<int32_t>& samples() const { return count_; }  // per pixel
    double max_error() const { return max_error_; }  // the worst active pixel's, last check
    int min_samples() const { return min_samples_; }

private:
    float threshold_ = 0.0f;
    int min_samples_ = 0, step_ = 4;
    int width_ = 0, height_ = 0;
    int64_t next_check_ = 0;
    std::vector<int32_t> count_, half_count_, list_;
    std::vector<double> half_;
    double max_error_ = -1.0;
};

// Cycles' automatic minimum before the first convergence check.
int adaptive_auto_min_samples(float threshold);
// Whether the samples first_sample.. of an iteration go to half A. Not every other sample:
// the QMC sampler's even-indexed points fill only half of a pixel's first dimensions, so such
// a half differs from the mean by far more than the noise. As Cycles (after Christensen et
// al., progressive multi-jittered sequences, 10.2.1): the parity of the index's odd bits,
// which splits a (0,2)-sequence into two well-spread halves; an iteration of spp_it > 1
// samples (an aligned block) goes whole, by its own index.
bool adaptive_half_a(int64_t first_sample, int spp_it);
// Cycles' per-pixel error: |I - A|_1 over the intensity I_r + I_g + I_b's square root below 1
// and the intensity itself from 1 on (brighter pixels need less: Cycles' note on exposure).
double adaptive_error(double diff_l1, double intensity);

}  // namespace lantern
