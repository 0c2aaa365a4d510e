// Struct-of-arrays state of the wavefront: one slot per path of an iteration. Stages read and
// write slots by path index; queues are arrays of path indices rebuilt in order (compaction),
// so the result never depends on scheduling.
#pragma once

#include "core/offset.h"
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
    // the previous surface vertex as the light tree saw it (point, light_pick_normal), for the
    // pick probability in the MIS weight of emission a BSDF-sampled ray finds
    Vec3* prev_p;
    Vec3* prev_n;
    // 1: the last scattering's kind does not see the world (SceneView::world_rays; pt, and
    // only written where the scene hides the world from some kind; may be null otherwise)
    uint8_t* world_hidden = nullptr;
    // participating media (integrator/pt_volume.h): the medium the current ray and the shadow
    // ray travel in (SceneView::media, -1: none); read only where SceneView::num_media > 0
    int32_t* medium = nullptr;
    int32_t* shadow_medium = nullptr;
    // a second shadow ray per path and bounce, from a medium point that equiangular sampling
    // chose along the segment (pt_volume.h); allocated only where the scene has media
    Vec3* vshadow_o = nullptr;
    Vec3* vshadow_d = nullptr;
    float* vshadow_tmax = nullptr;
    Vec3* vshadow_contrib = nullptr;
    int32_t* vshadow_medium = nullptr;
    uint8_t* vshadow_valid = nullptr;
    int32_t* vshadow_light = nullptr;  // its light, as shadow_light (shadow linking)
    // the RayKinds of the scattering that made the current ray (pt, integrator/
    // pt_ray_visibility.h: written where SceneView::tri_rays or light_rays is set; bdpt's camera
    // pass keeps a restricted bit beside them, lt its walk's kinds: where SceneView::rays_hidden
    // is set, bidir_ray_visibility.h, lt_ray_visibility.h); may be null
    uint8_t* ray_kind = nullptr;
    // light linking: the receiver set of the vertex the current ray left (pt, integrator/
    // pt_light_linking.h); written only where SceneView::light_receivers is set, may be null
    uint8_t* recv_set = nullptr;
    // shadow linking: the light of the slot's next-event shadow ray (pt_light_linking.h);
    // written only where SceneView::light_blockers is set, may be null
    int32_t* shadow_light = nullptr;
    // lt's first segment's walk in media (integrator/lt_medium.h lt_walk_ratio): the optical
    // depth it crossed less pt's shadow ray's over the closed stretches, and where (distance
    // from the light's point) pt's shadow ray's last stretch starts; allocated only in media
    Vec3* walk_tau = nullptr;
    float* walk_t0 = nullptr;

    // lt's first segment's walk (integrator/lt_linking.h): the surfaces it passed so far. lt
    // traces no next-event rays of its own, so it keeps the count in shadow_light's slots.
    LANTERN_HD int32_t& walk_passed(int i) const { return shadow_light[i]; }
    // shadow linking with MIS (pt_linked_mis): the MIS weight of slot i's next event, applied
    // once its shadow ray passed no surface (shadow_contrib holds weight 1); allocated only
    // where SceneView::light_blockers is set (pt), may be null
    float* shadow_mis = nullptr;
};

struct PtSettings {
    int32_t max_depth;     // 1: emitters seen directly, 2: direct light, ... (as Mitsuba)
    int32_t rr_depth;      // Russian roulette from this depth on; 0 = off
    int32_t spp_per_iteration;
    uint64_t seed;
    uint64_t iteration;
    int32_t light_candidates = 1;  // pt's next-event estimation: M > 1 resamples M light
                                   // samples (integrator/nee_resample.h), 1 the plain one
};

// Russian roulette on the throughput `beta` once `depth` has reached rr_depth (0: off): survives
// with probability min(sqrt(max component), 0.95) and is reweighted; false when the path ends.
// The square root ends dim paths later than min(max component) would: with the default
// rr_depth 4 it halved pt's noise at equal time on a world-lit stage, whose light arrives only
// at the end of a path, and cost nothing elsewhere (bench/results/2026-12-01-roulette/).
LANTERN_HD inline bool russian_roulette(Vec3& beta, int depth, int rr_depth, Rng& rng) {
    if (rr_depth <= 0 || depth < rr_depth) return true;
    float q = fminf(sqrtf(max_component(beta)), 0.95f);
    if (!(rng.uniform() < q)) return false;
    beta = beta / q;
    return true;
}

// The slot's next ray leaves p (geometric normal ng) along wi, sampled with pdf_w; `scale` is
// the scene's offset scale (offset.h).
LANTERN_HD inline void set_next_ray(const PathState& ps, int i, Vec3 p, Vec3 ng, Vec3 wi,
                                    float pdf_w, float scale) {
    ps.ray_o[i] = offset_ray_origin(p, ng, wi, scale);
    ps.ray_d[i] = wi;
    ps.ray_tmin[i] = 0.0f;
    ps.ray_tmax[i] = kInf;
    ps.prev_pdf_w[i] = pdf_w;
    ps.alive[i] = 1;
}

LANTERN_HD inline void add_radiance(const PathState& ps, int i, Vec3 c) {
    if (is_finite(c)) {
        ps.radiance[i] += c;
    } else {
        ps.dropped[i] = 1;
    }
}

}  // namespace lantern
