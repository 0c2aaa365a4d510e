// AdaptiveFilm (integrator/adaptive.h) on synthetic sums: Cycles' error, the halves, the 3x3
// dilation, min samples, and that a stopped pixel adds nothing more.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <vector>

#include "integrator/adaptive.h"

namespace lantern {
namespace {

constexpr int kW = 7, kH = 6;

// One iteration of one sample: every pixel sees `v`, pixel `noisy` alternates v +- d by half.
std::vector<double> iteration(int64_t sample, int noisy, double v, double d) {
    std::vector<double> it(size_t(kW) * kH * 3, v);
    const double x = v + (adaptive_half_a(sample, 1) ? d : -d);
    for (int c = 0; c < 3; ++c) it[size_t(noisy) * 3 + c] = x;
    return it;
}

TEST(AdaptiveFilm, OnlyTheNoisyPixelsBoxKeepsSampling) {
    AdaptiveFilm f;
    f.configure(0.01f, 8, 4);
    f.reset(kW, kH);
    std::vector<double> accum(size_t(kW) * kH * 3, 0.0);
    const int noisy = 2 * kW + 3;  // (x 3, y 2)
    for (int64_t s = 0; s < 8; ++s) {
        EXPECT_EQ(f.pixel_list(), nullptr);  // all active before the first check
        f.add(iteration(s, noisy, 0.2, 0.1).data(), accum, 1, s);
        f.update(accum, s + 1);
    }
    std::set<int> active(f.pixel_list(), f.pixel_list() + f.active_count());
    std::set<int> box;
    for (int y = 1; y <= 3; ++y)
        for (int x = 2; x <= 4; ++x) box.insert(y * kW + x);
    EXPECT_EQ(active, box);
    // |I - A|_1 = 3 x 0.1 over sqrt(0.6) (R + G + B < 1)
    EXPECT_NEAR(f.max_error(), 0.3 / (1e-4 + std::sqrt(0.6)), 1e-9);
    // a stopped pixel keeps its sum and count: later iterations do not reach it
    const double before = accum[0];
    f.add(iteration(8, noisy, 5.0, 0.1).data(), accum, 1, 8);
    EXPECT_EQ(accum[0], before);
    EXPECT_EQ(f.samples()[0], 8);
    EXPECT_EQ(f.samples()[noisy], 9);
}

TEST(AdaptiveFilm, NothingStopsBeforeMinSamplesOrWhenOff) {
    AdaptiveFilm f;
    f.configure(1e3f, 12, 4);
    f.reset(kW, kH);
    std::vector<double> accum(size_t(kW) * kH * 3, 0.0);
    for (int64_t s = 0; s < 12; ++s) {
        EXPECT_FALSE(f.converged());
        f.add(iteration(s, 0, 0.5, 0.0).data(), accum, 1, s);
        f.update(accum, s + 1);
    }
    EXPECT_TRUE(f.converged());
    AdaptiveFilm off;
    off.configure(0.0f, 0, 4);
    off.reset(kW, kH);
    EXPECT_FALSE(off.on());
    std::vector<double> a2(size_t(kW) * kH * 3, 0.0);
    for (int64_t s = 0; s < 32; ++s) {
        off.add(iteration(s, 0, 0.5, 0.0).data(), a2, 1, s);
        EXPECT_FALSE(off.update(a2, s + 1));
    }
    EXPECT_EQ(off.pixel_list(), nullptr);
    EXPECT_EQ(off.active_count(), kW * kH);
}

TEST(AdaptiveFilm, CyclesErrorAndHalves) {
    EXPECT_NEAR(adaptive_error(0.3, 0.25), 0.3 / (1e-4 + 0.5), 1e-12);  // sqrt below 1
    EXPECT_NEAR(adaptive_error(0.3, 4.0), 0.3 / (1e-4 + 4.0), 1e-12);   // itself above
    int in_a = 0;
    for (int s = 0; s < 64; ++s) in_a += adaptive_half_a(s, 1);
    EXPECT_EQ(in_a, 32);
    for (int s = 0; s < 64; s += 4)  // each aligned block of 4 splits 2 / 2
        EXPECT_EQ(adaptive_half_a(s, 1) + adaptive_half_a(s + 1, 1) + adaptive_half_a(s + 2, 1) +
                      adaptive_half_a(s + 3, 1),
                  2);
    EXPECT_FALSE(adaptive_half_a(0, 1));
    EXPECT_TRUE(adaptive_half_a(2, 1));
    EXPECT_EQ(adaptive_auto_min_samples(0.01f), 64);
}

}  // namespace
}  // namespace lantern
