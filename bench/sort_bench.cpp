// Sorting a wavefront's queue by material type on the CPU: the stable counting sort that
// bdpt_session.cpp uses, against thrust::stable_sort_by_key with the host (CPP) backend and
// std::stable_sort, on the queue sizes of a chunk (2^18 paths) and of a paper-sized wavefront
// (1980 x 1080 x 4 = 8.5M). Keys: 3 type bits (5 code paths + misses) or all 27 key bits.
// Build and run: bench/sort_bench.sh (g++ with CCCL's headers, no GPU needed).
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <random>
#include <vector>

#include <thrust/execution_policy.h>
#include <thrust/sort.h>

namespace {

using Clock = std::chrono::steady_clock;

template <typename F>
double best_ms(F&& f, int reps = 7) {
    double best = 1e30;
    for (int r = 0; r < reps; ++r) {
        auto t = Clock::now();
        f();
        best = std::min(best, std::chrono::duration<double, std::milli>(Clock::now() - t).count());
    }
    return best;
}

// What Session::sort_queue does: count per bucket, prefix, scatter (stable).
void counting_sort(const std::vector<uint32_t>& key, std::vector<int32_t>& queue,
                   std::vector<int32_t>& tmp, int buckets) {
    std::vector<int> count(buckets + 1, 0);
    for (int32_t s : queue) ++count[key[s] + 1];
    for (int b = 0; b < buckets; ++b) count[b + 1] += count[b];
    for (int32_t s : queue) tmp[count[key[s]]++] = s;
    queue.swap(tmp);
}

}  // namespace

int main() {
    std::printf("| queue | key bits | counting sort (ms) | thrust host stable_sort_by_key (ms) | "
                "std::stable_sort (ms) |\n|---:|---:|---:|---:|---:|\n");
    for (int n : {1 << 18, 1980 * 1080 * 4}) {
        for (int bits : {3, 27}) {
            std::mt19937 rng(1);
            std::vector<uint32_t> key(n);
            // types 0..4 plus misses (5) for 3 bits; random ids for 27 bits
            for (auto& k : key) k = bits == 3 ? rng() % 6 : rng() & ((1u << 27) - 1);
            std::vector<int32_t> base(n), q(n), tmp(n);
            for (int i = 0; i < n; ++i) base[i] = i;
            double c = -1.0;
            if (bits == 3) {
                c = best_ms([&] {
                    q = base;
                    counting_sort(key, q, tmp, 6);
                });
            }
            std::vector<uint32_t> k2(n);
            double t = best_ms([&] {
                q = base;
                for (int i = 0; i < n; ++i) k2[i] = key[q[i]];
                thrust::stable_sort_by_key(thrust::host, k2.begin(), k2.end(), q.begin());
            });
            double s = best_ms([&] {
                q = base;
                std::stable_sort(q.begin(), q.end(),
                                 [&](int32_t a, int32_t b) { return key[a] < key[b]; });
            });
            if (c >= 0)
                std::printf("| %d | %d | %.2f | %.2f | %.2f |\n", n, bits, c, t, s);
            else
                std::printf("| %d | %d | – | %.2f | %.2f |\n", n, bits, t, s);
        }
    }
    return 0;
}
