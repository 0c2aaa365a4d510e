// What embree_accel.cpp and embree_instances.cpp share: the intersect context that carries the
// world-space ray into the alpha filter of instanced geometry (Embree hands filters the ray in
// the instance's space; the stochastic alpha test must see the ray the flat scene sees).
#pragma once

#include "accel/boundary_hits.h"
#include "backend/cpu/embree_loader.h"

#if LANTERN_HAVE_EMBREE
namespace lantern {

struct EmbreeWorldContext {
    RTCIntersectContext ctx;  // first: Embree passes &ctx to the filter as args->context
    float o[3], d[3];
};

// The context of EmbreeAccel::occluded_collect: its boundary geometries' filter records each
// hit in `out` (accel/boundary_hits.h) and rejects it.
struct EmbreeCollectContext {
    RTCIntersectContext ctx;  // first, as above
    BoundaryHits* out;
};

}  // namespace lantern
#endif
