// The CPU thread pool: every index of every job runs exactly once, whatever the interleaving of
// jobs with different grains (the race of issue 12 ran [0,256) for a claim of [0,64)), nested
// calls run inline, concurrent callers are serialised, and a failed start joins its threads.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "backend/cpu/thread_pool.h"

using namespace lantern;

namespace {

// Runs `jobs` tiny jobs back to back (a late worker of one job meets the next one), alternating
// grains and sizes, then checks that every index of every job ran exactly once.
void stress(ThreadPool& pool, int jobs) {
    const int grains[] = {64, 256, 1, 7, 100};
    const int sizes[] = {300, 257, 17, 65, 129};
    constexpr int kMaxN = 300;
    std::vector<std::atomic<int>> hits(size_t(jobs) * kMaxN);
    std::atomic<int> too_long{0};
    for (int j = 0; j < jobs; ++j) {
        const int n = sizes[j % 5], grain = grains[(j / 5) % 5];
        std::atomic<int>* h = &hits[size_t(j) * kMaxN];
        pool.parallel_for(n, grain, [&, h, grain](int b, int e) {
            if (e - b > grain) too_long.fetch_add(1);
            for (int i = b; i < e; ++i) h[i].fetch_add(1, std::memory_order_relaxed);
        });
    }
    EXPECT_EQ(too_long.load(), 0) << "chunks longer than their job's grain";
    int wrong = 0;
    for (int j = 0; j < jobs; ++j) {
        for (int i = 0; i < sizes[j % 5]; ++i) {
            const int c = hits[size_t(j) * kMaxN + i].load();
            if (c != 1 && wrong++ < 5) {
                ADD_FAILURE() << "job " << j << " (n " << sizes[j % 5] << ", grain "
                              << grains[(j / 5) % 5] << "): index " << i << " ran " << c
                              << " times";
            }
        }
    }
    EXPECT_EQ(wrong, 0);
}

}  // namespace

TEST(ThreadPool, ThousandsOfTinyJobsWithAlternatingGrainsRunEachIndexOnce) {
    for (int threads : {2, 3, 8}) {
        ThreadPool pool(threads);
        for (int round = 0; round < 4; ++round) stress(pool, 20000);
    }
}

TEST(ThreadPool, NestedCallsRunInline) {
    ThreadPool pool(4);
    std::vector<std::atomic<int>> hits(64 * 64);
    pool.parallel_for(64, 1, [&](int b, int e) {
        for (int i = b; i < e; ++i) {
            pool.parallel_for(64, 4, [&](int b2, int e2) {
                for (int k = b2; k < e2; ++k) hits[i * 64 + k].fetch_add(1);
            });
        }
    });
    for (auto& h : hits) ASSERT_EQ(h.load(), 1);
}

TEST(ThreadPool, ConcurrentCallersAreSerialised) {
    ThreadPool pool(4);
    std::vector<std::thread> callers;
    std::atomic<int> wrong{0};
    for (int c = 0; c < 3; ++c) {
        callers.emplace_back([&] {
            for (int j = 0; j < 300; ++j) {
                std::vector<std::atomic<int>> hits(500);
                pool.parallel_for(500, 3 + j % 50, [&](int b, int e) {
                    for (int i = b; i < e; ++i) hits[i].fetch_add(1);
                });
                for (auto& h : hits) wrong += h.load() != 1;
            }
        });
    }
    for (auto& t : callers) t.join();
    EXPECT_EQ(wrong.load(), 0);
}

TEST(ThreadPool, SingleThreadAndEmptyRanges) {
    ThreadPool pool(1);
    EXPECT_EQ(pool.size(), 1);
    int calls = 0;
    pool.parallel_for(0, 4, [&](int, int) { ++calls; });
    pool.parallel_for(-5, 4, [&](int, int) { ++calls; });
    EXPECT_EQ(calls, 0);
    pool.parallel_for(10, 4, [&](int b, int e) { calls += e - b; });
    EXPECT_EQ(calls, 10);
}
