// Per-pixel connection counts chosen from the render's own iterations (issue 27, item 2;
// SessionSettings::connection_allocation: lvc, cis, auto's kept cis iterations): host code the
// CPU and the GPU sessions share; what it chooses is a map of (N, M) per pixel
// (integrator/pixel_conn.h) that the stages read.
//
// - Settings: a small range of (N, M) from the session's (N, M): low (N = 0; N = 1, M = 2
//   where the scene has a delta light, whose paths through a specular vertex only connections
//   may sample), half (N/2, M/2), full (N, M), double (2N, 2M, at most 64), duplicates dropped.
// - Pilot: the first four iterations are kept in the image; pixel (x, y) renders setting
//   (x + 2y + i/2) mod K (K settings) in iteration i: two settings, each in two consecutive
//   iterations (a pair), and an 8 x 8 tile 32 pairs of each setting of four.
// - Variance per tile and setting: the mean over its pairs (two consecutive iterations of one
//   pixel in one setting) of (v1 - v2)^2 / 2, v the iteration's luminance; every iteration
//   adds pairs (after the pilot, the tile's chosen setting's). Cost per pixel sample and
//   setting from the counters (counts, never clocks): rays, half a ray per connection ray,
//   0.15 of a ray per cis candidate (kConnectionRayCost, kCandidateCost: fitted to CPU time),
//   as base + N x (connection work per unit of N) + M x (candidate work per unit of M).
// - Choice: the map that minimises (sum of the tiles' variances) x (sum of their costs), the
//   image's error at a given time: each tile takes argmin V + lambda C with lambda = V / C of
//   the map, iterated to a fixed point. Made at the pilot's end and again at iterations 8, 16,
//   32, ... from every iteration before. Each map is fixed before its iteration and chosen
//   from earlier iterations only, each iteration an unbiased estimate weighted equally: the
//   image stays unbiased. Same seed, same bits.
#pragma once

#include <cstdint>
#include <vector>

namespace lantern {

struct SessionStats;
struct SceneView;

class ConnectionAllocation {
public:
    static constexpr int kTile = 8;
    static constexpr int kPilot = 4;  // iterations (a power of two)
    // Cost of a connection ray and of a cis candidate in rays of the rest of the iteration
    // (whose rays carry the shading, the sort and the light pass): a fit to CPU time on the
    // 2-core box, 64 x 64, uniform maps N 0..10, M 1..20 (Cornell box 0.50 and 0.13-0.15,
    // room_area_point 0.43 and 0.145; bench/results/2026-12-04-auto6). Allocation's 0.36 of a
    // ray per candidate (auto's choice between pt and cis) counts a connection ray as a ray.
    static constexpr double kConnectionRayCost = 0.5;
    static constexpr double kCandidateCost = 0.15;

    ConnectionAllocation(int width, int height, int connections, int candidates, bool allow_zero);
    // Whether a scene's paths stay sampled without connections (no delta light).
    static bool zero_allowed(const SceneView& s);
    // The map of the next iteration (2 bytes a pixel).
    const std::vector<uint8_t>& map() const { return map_; }
    // After an iteration rendered with map(): its sum (3 doubles a pixel, spp samples each)
    // and the counters before and after it.
    void observe(const double* sum, int spp, const SessionStats& before,
                 const SessionStats& after);
    bool piloting() const { return seen_ < pilot_; }
    int pilot_iterations() const { return pilot_; }
    int choices() const { return choices_; }  // maps chosen so far (0 while piloting)
    double mean_connections() const;          // of map()
    // the settings (N, M) of the range
    const std::vector<int>& settings_n() const { return set_n_; }
    const std::vector<int>& settings_m() const { return set_m_; }
    // pixels of each setting in map() (after the pilot)
    std::vector<int64_t> setting_pixels() const;

private:
    void pilot_map();  // the pattern of iteration seen_
    void decide();
    void fill_tile(int tx, int ty, int k);
    int tile_of(int x, int y) const { return (y / kTile) * tiles_x_ + x / kTile; }

    int w_, h_, tiles_x_, tiles_y_;
    int pilot_ = 0, seen_ = 0, choices_ = 0, full_ = 0;
    std::vector<int> set_n_, set_m_;   // the range: K settings
    std::vector<uint8_t> map_;         // (N, M) per pixel
    std::vector<uint8_t> setting_;     // per pixel: its setting in map_
    std::vector<int8_t> tile_choice_;  // per tile: its setting after the pilot
    std::vector<float> pending_;       // per pixel: the first of a pair (luminance)
    std::vector<int8_t> pending_k_;    // ... its setting, -1: none
    std::vector<double> pair_sum_;     // per tile x setting: sum of (v1 - v2)^2 / 2
    std::vector<int64_t> pair_count_;  // ... pairs
    // counters over every observed iteration: pixel samples, sum over them of N and of M
    // (M where N > 0), work (rays + candidates), connection rays, candidates' work
    double samples_ = 0.0, sum_n_ = 0.0, sum_m_ = 0.0;
    double work_ = 0.0, conn_work_ = 0.0, cand_work_ = 0.0;
};

}  // namespace lantern
