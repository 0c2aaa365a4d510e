// The volume boundaries a shadow ray crosses, gathered in the same traversal that asks whether
// anything else blocks it (host+device): pt's shadow rays through media (integrator/pt_volume.h
// pt_shadow_transmittance). The query's filter records each boundary hit (kVolumeBoundary,
// after the alpha test) here and rejects it, so the traversal goes on; any other caster's hit is
// accepted and stops it. Unblocked, the record holds every boundary crossing on the segment,
// unordered (a triangle the structure holds twice, Embree's spatial splits, is recorded once).
// n -1: not gathered (more than kMax crossings, or a structure that cannot gather: Embree's and
// the BVH's two levels): the caller takes the closest-hit loop.
#pragma once

#include <cstdint>

#include "accel/bvh.h"

namespace lantern {

struct BoundaryHits {
    static constexpr int kMax = 8;
    int32_t n = 0;
    float t[kMax];
    int32_t prim[kMax];
    Vec2 uv[kMax];
    // Records a boundary hit; false once there is no room (n becomes -1: stop the query).
    LANTERN_HD bool add(int32_t p, float hit_t, Vec2 hit_uv) {
        if (n < 0) return false;
        for (int k = 0; k < n; ++k)
            if (prim[k] == p) return true;  // the same triangle again (a split reference)
        if (n == kMax) {
            n = -1;
            return false;
        }
        t[n] = hit_t;
        prim[n] = p;
        uv[n] = hit_uv;
        ++n;
        return true;
    }
};

// The built-in BVH's collector (accel/bvh.h bvh_traverse's Collect): boundaries recorded and
// passed over, every other triangle a hit; out of room, a hit (the query stops, n is -1).
struct BvhCollectBoundaries {
    BoundaryHits* out;
    static constexpr bool kOn = true;
    LANTERN_HD bool pass(uint32_t flags, int32_t prim, float t, float u, float v) const {
        if (!(flags & kVolumeBoundary)) return false;
        return out->add(prim, t, Vec2{u, v});
    }
};

// Whether a shadow caster that is not a volume boundary lies on the segment (tmin, tmax]; if
// not, *out holds the boundaries on it (out->n -1: more than kMax, the answer is no answer).
template <typename Accept = BvhAcceptAll>
LANTERN_HD inline bool bvh_occluded_collect(const BvhView& bvh, const Ray& ray, BoundaryHits* out,
                                            const Accept& accept = Accept()) {
    out->n = 0;
    return bvh_traverse<true>(bvh, ray, kBvhNeedShadow, accept, BvhTriAsStored(),
                              BvhCollectBoundaries{out})
               .prim >= 0;
}

}  // namespace lantern
