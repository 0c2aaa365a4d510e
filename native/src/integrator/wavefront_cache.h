// The light vertex cache's memory, for every backend: what one pass needs (the vertices and, for
// bdpt, the per-path index), how many samples a pass may take to stay within a budget, and what
// capacity the cache takes at a pass's start and when it must grow. Growth is exact (to the
// vertices stored so far plus the measured rate times the paths still to come), and a growth
// whose transient peak (old and new array alive together) would pass the budget throws
// CacheOverBudget: the session splits the iteration into more passes, or at one sample per pass
// reports that the cache does not fit. Host code only.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "integrator/bdpt.h"

namespace lantern {

// Bytes a meter holds now and the most it held at once, transient peaks included: an owner adds
// a new allocation before it frees the old one. A meter with a parent (the cache's, under the
// executor's) passes every change on, so the parent sees the whole.
struct MemoryMeter {
    int64_t current = 0, peak = 0;
    MemoryMeter* parent = nullptr;
    void add(int64_t b) {
        current += b;
        peak = std::max(peak, current);
        if (parent) parent->add(b);
    }
    void sub(int64_t b) {
        current -= b;
        if (parent) parent->sub(b);
    }
};

// Bytes of one pass's cache per stored vertex and per light path.
struct CacheCosts {
    double per_vertex = sizeof(LightVertex);  // the vertex and its index entries (bdpt)
    double per_path = 0.0;                    // the bdpt index's entries per light path
};

// bdpt indexes the cache by light path, the same way on every backend (schedule_bdpt.h): the
// path keys and path_vertex, with the sort's scratch copy of both (16 B per vertex), and
// path_offset (4 B per path). lvc and cis keep no index.
inline CacheCosts cache_costs(bool bdpt_index) {
    CacheCosts c;
    if (bdpt_index) {
        c.per_vertex += 4 * sizeof(int32_t);
        c.per_path = sizeof(int32_t);
    }
    return c;
}

// Margin of a pass's first allocation over the vertices its rate predicts (a rate measured on
// other paths: the count of this pass differs by its noise).
constexpr double kCacheSlack = 1.05;
constexpr size_t kCacheSlackVertices = 4096;

inline double cache_bytes(const CacheCosts& c, double vertices, double light_paths) {
    return vertices * c.per_vertex + light_paths * c.per_path;
}

// Thrown by a growth that would pass the budget. `vertices_per_path` is the rate measured up to
// then (vertices stored / light paths started), a better estimate for the next plan.
struct CacheOverBudget : std::runtime_error {
    double vertices_per_path;
    CacheOverBudget(const std::string& what, double vpp)
        : std::runtime_error(what), vertices_per_path(vpp) {}
};

// Samples per light pass so that its cache (vertices, slack, index) fits `budget` bytes: at
// least 1, at most spp_it, from the vertices per light path measured before (< 0: none yet, then
// min(max_depth - 1, 4)). When it splits and *warned is false, appends a warning naming `what`.
inline int cache_samples_per_pass(double budget, double vertices_per_path, const CacheCosts& c,
                                  int max_depth, int spp_it, int width, int height,
                                  const char* what, bool* warned,
                                  std::vector<std::string>& warnings) {
    const double vpp = vertices_per_path > 0.0 ? vertices_per_path : std::min(max_depth - 1, 4);
    const double pixels = double(width) * height;
    const double per_spp = pixels * (std::max(vpp, 0.5) * kCacheSlack * c.per_vertex + c.per_path);
    const double room = budget - double(kCacheSlackVertices) * c.per_vertex;
    const int per_pass = int(std::clamp(room / per_spp, 1.0, double(spp_it)));
    if (per_pass < spp_it && !*warned) {
        *warned = true;
        warnings.push_back(std::string(what) + ": " + std::to_string(spp_it) +
                           " samples per iteration run as passes of " + std::to_string(per_pass) +
                           " to stay within " + std::to_string(int64_t(budget / (1 << 20))) +
                           " MiB");
    }
    return per_pass;
}

// A GPU's cache budget: cache_budget_mb when it is set, else half of the memory that was free
// at the start less what the renderer keeps reserved (the kernels' stacks, per-thread
// scratch), at most 8 GiB; times `scale` (halved with the paths in flight when memory is short).
inline double gpu_cache_budget(int64_t free_at_start, int64_t reserved, int cache_budget_mb,
                               double scale) {
    const double free = double(std::max<int64_t>(free_at_start - reserved, 0));
    return scale * (cache_budget_mb > 0 ? double(cache_budget_mb) * (1 << 20)
                                        : std::min(8.0 * (1 << 30), 0.5 * free));
}

// Vertices the cache can hold when the whole budget, less the index of L paths, is vertices.
inline size_t cache_max_vertices(double budget, const CacheCosts& c, double light_paths) {
    const double v = (budget - light_paths * c.per_path) / c.per_vertex;
    return v > 0.0 ? size_t(v) : 0;
}

// Capacity at the start of a pass of `light_paths` paths: the measured rate with its slack,
// never more than the budget holds (a growth, if the rate was low, then decides).
inline size_t cache_initial_capacity(double vertices_per_path, int64_t light_paths,
                                     double budget, const CacheCosts& c) {
    const double want = std::max(vertices_per_path, 0.0) * double(light_paths) * kCacheSlack +
                        double(kCacheSlackVertices);
    return std::min(size_t(want), cache_max_vertices(budget, c, double(light_paths)));
}

// Capacity to grow to when `need` vertices must fit in a cache of capacity `cap`, after
// `paths_started` of `light_paths` paths have started: exactly `need` plus the measured rate
// times the paths still to come. Throws CacheOverBudget when old and new capacity together (the
// transient of the copy), or the new one with the index, would pass the budget.
inline size_t cache_grow_capacity(size_t need, size_t cap, int64_t paths_started,
                                  int64_t light_paths, double budget, const CacheCosts& c) {
    const double rate = double(need) / double(std::max<int64_t>(paths_started, 1));
    const double rest = double(std::max<int64_t>(light_paths - paths_started, 0));
    size_t want = need + size_t(std::ceil(rate * rest * kCacheSlack));
    const size_t most = cache_max_vertices(budget, c, double(light_paths));
    want = std::min(want, most);
    const double transient = double(cap + want) * sizeof(LightVertex);
    if (want < need || transient > budget) {
        throw CacheOverBudget("the light vertex cache needs " + std::to_string(need) +
                                  " vertices after " + std::to_string(paths_started) + " of " +
                                  std::to_string(light_paths) + " light paths, past its budget of " +
                                  std::to_string(int64_t(budget / (1 << 20))) + " MiB",
                              rate);
    }
    return want;
}

}  // namespace lantern
