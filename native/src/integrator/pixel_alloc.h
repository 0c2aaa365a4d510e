// Per-pixel connection counts chosen from the render's own iterations (issue 27, item 2;
// SessionSettings::connection_allocation: lvc, cis, auto's kept cis iterations): host code a
// session of any backend shares; what it chooses is a map of (N, M) per pixel
// (integrator/pixel_conn.h) that the stages read. (The CPU session drives it; the GPU's does
// not take a map yet.)
//
// - Pilot: the first kPilot iterations are kept in the image and alternate two pixel
//   checkerboards of "low" and "full" counts (full: the session's N, M; low: N = 0, or N = 1,
//   M = 2 where the scene has a delta light, whose paths through a specular vertex only
//   connections may sample), so that every pixel has kPilot / 2 iterations of each.
// - Estimates per 8 x 8 tile: the sum over its pixels of each setting's per-iteration
//   luminance variance; cost per pixel sample from the counters (rays, 0.36 of a ray per cis
//   candidate, Allocation::kCandidateCost): the low setting's the iteration's cost without the
//   connections and candidates, the full setting's that plus their cost per full pixel.
// - Choice: each tile the setting of lower variance x cost, fixed for the rest of the render.
//   Every map is fixed before its iteration and chosen from earlier iterations only, each
//   iteration an unbiased estimate weighted equally: the image stays unbiased. Deterministic
//   quantities only (counts, never clocks): same seed, same bits.
#pragma once

#include <cstdint>
#include <vector>

namespace lantern {

struct SessionStats;
struct SceneView;

class ConnectionAllocation {
public:
    static constexpr int kTile = 8;
    static constexpr int kPilot = 4;

    ConnectionAllocation(int width, int height, int connections, int candidates, bool allow_zero);
    // Whether a scene's paths stay sampled without connections (no delta light).
    static bool zero_allowed(const SceneView& s);
    // The map of the next iteration (2 bytes a pixel).
    const std::vector<uint8_t>& map() const { return map_; }
    // After an iteration rendered with map(): its sum (3 doubles a pixel, spp samples each)
    // and the counters before and after it.
    void observe(const double* sum, int spp, const SessionStats& before,
                 const SessionStats& after);
    bool piloting() const { return seen_ < kPilot; }
    double mean_connections() const;  // of map()

private:
    void pilot_map();  // the checkerboard of iteration seen_
    void decide();

    int w_, h_, n_, m_;
    int low_n_, low_m_;
    int seen_ = 0;
    std::vector<uint8_t> map_;
    std::vector<double> sum_[2], sum2_[2];  // per pixel: each setting's luminance (low, full)
    std::vector<int32_t> count_[2];
    double base_work_ = 0.0, conn_work_ = 0.0;  // summed over the pilot
    int64_t samples_ = 0, full_samples_ = 0;    // pixel samples, ... of the full setting
};

}  // namespace lantern
