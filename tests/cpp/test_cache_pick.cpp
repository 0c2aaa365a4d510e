// The light vertex cache pick (integrator/bdpt.h, cache_pick) over a synthetic cache of more
// than 2^24 vertices: every vertex is reachable, each by floor or ceil of 2^32 / size of the
// 2^32 random words (uniform to within one word). The 24-bit float pick it replaced,
// int(u * size), is checked on the same size to reach only about 2^24 of them.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "integrator/bdpt.h"

using namespace lantern;

namespace {

// The first 32-bit word that picks index k: ceil(k 2^32 / n).
uint32_t first_word(uint64_t k, uint64_t n) { return uint32_t(((k << 32) + n - 1) / n); }

}  // namespace

TEST(CachePick, EveryVertexOfALargeCacheIsReachable) {
    const int32_t n = 25'000'003;  // 1920 x 1080 x 4 spp holds about 25M vertices
    ASSERT_GT(n, 1 << 24);
    const uint64_t lo = (uint64_t(1) << 32) / uint64_t(n), hi = lo + 1;
    EXPECT_EQ(cache_pick(0u, n), 0);
    EXPECT_EQ(cache_pick(0xFFFFFFFFu, n), n - 1);
    int64_t bad = 0;
    for (int64_t k = 0; k < n; ++k) {
        const uint32_t w = first_word(uint64_t(k), uint64_t(n));
        // the words picking k are [w, next): a non-empty, contiguous range of lo or hi words
        const uint64_t next = k + 1 < n ? first_word(uint64_t(k + 1), uint64_t(n))
                                        : (uint64_t(1) << 32);
        const uint64_t count = next - w;
        const bool ok = cache_pick(w, n) == k && (k == 0 || cache_pick(w - 1, n) == k - 1) &&
                        (count == lo || count == hi);
        bad += !ok;
        if (!ok && bad < 5) ADD_FAILURE() << "vertex " << k << ": first word " << w << ", "
                                          << count << " words";
    }
    EXPECT_EQ(bad, 0);
}

TEST(CachePick, TheFloatPickLeavesMostOfALargeCacheUnreachable) {
    // every value the old pick could draw: u = j / 2^24, index = min(int(u * n), n - 1)
    const int32_t n = 25'000'003;
    std::vector<uint8_t> hit(size_t(n), 0);
    const float size = float(n);
    for (uint32_t j = 0; j < (1u << 24); ++j) {
        const float u = float(j) * 0x1p-24f;
        hit[size_t(min_int(int(u * size), n - 1))] = 1;
    }
    int64_t reached = 0;
    for (uint8_t h : hit) reached += h;
    EXPECT_LE(reached, int64_t(1) << 24);
    EXPECT_LT(double(reached) / n, 0.7);  // the defect the integer pick removes
}

TEST(CachePick, SmallCachesStayInRange) {
    for (int32_t n : {1, 2, 3, 7, 1000, (1 << 24) - 1, 1 << 24, (1 << 24) + 1}) {
        EXPECT_EQ(cache_pick(0u, n), 0) << n;
        EXPECT_EQ(cache_pick(0xFFFFFFFFu, n), n - 1) << n;
        EXPECT_EQ(cache_pick(0x80000000u, n), n / 2) << n;
    }
}
