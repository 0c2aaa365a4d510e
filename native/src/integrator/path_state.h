// Struct-of-arrays state of the wavefront: one slot per path of an iteration. Stages read and
// write slots by path index; queues are arrays of path indices rebuilt in order (compaction),
// so the result never depends on scheduling.
#pragma once

#include "core/rng.h"

namespace lantern {

struct PathState {
    // the ray to trace next
    Vec3* ray_o;
    Vec3* ray_d;
    float* ray_tmin;
    float* ray_tmax;
    // path
    Vec3* throughput;
    Vec3* radiance;
    Rng* rng;
    int32_t* depth;        // segments traced so far (the camera ray is segment 1)
    float* prev_pdf_w;     // solid-angle pdf of the BSDF sample that made the current ray
    uint8_t* alive;        // continue after this bounce
    uint8_t* dropped;      // a non-finite contribution was discarded
    // closest hit of the current ray (filled by the backend)
    float* hit_t;
    int32_t* hit_prim;     // triangle index or -1
    Vec2* hit_uv;          // barycentrics of vertices 1 and 2
    // one shadow ray per path and bounce
    Vec3* shadow_o;
    Vec3* shadow_d;
    float* shadow_tmax;
    Vec3* shadow_contrib;
    uint8_t* shadow_valid;
};

struct PtSettings {
    int32_t max_depth;     // 1: emitters seen directly, 2: direct light, ... (as Mitsuba)
    int32_t rr_depth;      // Russian roulette from this depth on; 0 = off
    int32_t spp_per_iteration;
    uint64_t seed;
    uint64_t iteration;
};

LANTERN_HD inline void add_radiance(const PathState& ps, int i, Vec3 c) {
    if (is_finite(c)) {
        ps.radiance[i] += c;
    } else {
        ps.dropped[i] = 1;
    }
}

}  // namespace lantern
