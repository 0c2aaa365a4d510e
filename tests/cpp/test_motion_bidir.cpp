// Motion blur's times in the light-path integrators (integrator/bdpt_motion.h,
// docs/motion_blur.md): bdpt's light path j takes camera path j's time, pt's (the camera
// sample's stream), and a pixel's times over its samples are stratified; lvc's and cis's passes
// take one time each, the same for every path of the pass, stratified over passes. Negative
// controls: the light path's own stream (lt's time) is not its camera path's, and the pass times
// of a different seed differ.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "integrator/bdpt_motion.h"

using namespace lantern;

namespace {

BdptSettings settings(int32_t mode, uint64_t seed, uint64_t iteration, int spp) {
    BdptSettings st{};
    st.mode = mode;
    st.seed = seed;
    st.iteration = iteration;
    st.spp_per_iteration = spp;
    return st;
}

// Whether n values in [0, 1) fall one in each of n equal strata.
bool one_per_stratum(const std::vector<float>& t) {
    std::vector<int> count(t.size(), 0);
    for (float x : t) {
        const size_t k = size_t(x * float(t.size()));
        if (k >= t.size() || count[k]++) return false;
    }
    return true;
}

}  // namespace

TEST(MotionBidir, BdptLightPathTakesItsCameraPathsTime) {
    int same_as_own_stream = 0;
    for (uint64_t it = 0; it < 3; ++it)
        for (int64_t path = 0; path < 2000; ++path) {
            const BdptSettings st = settings(kBdptOwnPath, 7, it, 4);
            const float t = bdpt_time(st, path);
            EXPECT_EQ(t, motion_time(Rng::for_camera(7, it, 4, path))) << it << " " << path;
            EXPECT_GE(t, 0.0f);
            EXPECT_LT(t, 1.0f);
            // (negative control) the light path's own stream would give another time
            same_as_own_stream +=
                t == motion_time(Rng::for_path(7 ^ 0x4C5643ull, it, uint64_t(path)));
        }
    EXPECT_LT(same_as_own_stream, 5);
}

TEST(MotionBidir, BdptPixelTimesAreStratified) {
    // a pixel's 16 samples, one per iteration or 16 in one: one time in each sixteenth
    for (int64_t pixel : {0, 5, 1234}) {
        std::vector<float> per_iteration, at_once;
        for (uint64_t it = 0; it < 16; ++it)
            per_iteration.push_back(bdpt_time(settings(kBdptOwnPath, 3, it, 1), pixel));
        for (int64_t k = 0; k < 16; ++k)
            at_once.push_back(bdpt_time(settings(kBdptOwnPath, 3, 0, 16), pixel * 16 + k));
        EXPECT_TRUE(one_per_stratum(per_iteration)) << pixel;
        EXPECT_TRUE(one_per_stratum(at_once)) << pixel;
    }
}

TEST(MotionBidir, PassTimeIsSharedAndStratifiedOverPasses) {
    for (int32_t mode : {int32_t(kLvcUniform), int32_t(kCisResampled)}) {
        std::vector<float> passes, other_seed;
        for (uint64_t pass = 0; pass < 64; ++pass) {
            const BdptSettings st = settings(mode, 11, pass, 2);
            const float t = bdpt_time(st, 0);
            for (int64_t path : {1, 17, 4095, 100000}) EXPECT_EQ(bdpt_time(st, path), t);
            passes.push_back(t);
            other_seed.push_back(bdpt_time(settings(mode, 12, pass, 2), 0));
        }
        EXPECT_TRUE(one_per_stratum(std::vector<float>(passes.begin(), passes.begin() + 16)));
        EXPECT_TRUE(one_per_stratum(passes));
        EXPECT_NE(passes, other_seed);  // (negative control: the seed scrambles them)
    }
}
