// What embree_accel.cpp and embree_instances.cpp share: the intersect context that carries the
// world-space ray into the alpha filter of instanced geometry (Embree hands filters the ray in
// the instance's space; the stochastic alpha test must see the ray the flat scene sees).
#pragma once

#include "backend/cpu/embree_loader.h"

#if LANTERN_HAVE_EMBREE
namespace lantern {

struct EmbreeWorldContext {
    RTCIntersectContext ctx;  // first: Embree passes &ctx to the filter as args->context
    float o[3], d[3];
};

}  // namespace lantern
#endif
