// Curve segments (accel/curve_bvh.h's CurveSeg) as Embree's ROUND_LINEAR_CURVE geometry: float4
// vertices (x, y, z, radius), joined segments (CurveSeg::flags) sharing their joint's vertex and
// marked with RTC_CURVE_FLAG_NEIGHBOR_* (no sphere at a joint, as accel/curve_hit.h leaves out),
// the others their own two, so the shape is accel/curve_hit.h's swept sphere. primID = the
// segment's place in `segs`.
#pragma once

#include <cmath>
#include <cstddef>

#include "accel/curve_bvh.h"
#include "backend/cpu/embree_loader.h"

namespace lantern {

#if LANTERN_HAVE_EMBREE
// Builds, commits and attaches the geometry to `scene`; returns its geomID. The scene still needs
// its own commit. Segments must have passed curve_segs' radius checks. filter: Embree's
// intersect and occluded filter (curve_accel.cpp keeps entries only), null for none. keys:
// where some segment moves (kCurveMoves), the geometry takes keys.num_steps time steps, a vertex
// buffer each (Embree lerps them at the ray's time, as accel/curve_bvh.h's curve_seg_at).
unsigned embree_attach_curves(const EmbreeApi& e, RTCDevice device, RTCScene scene,
                              const CurveSeg* segs, size_t count,
                              RTCFilterFunctionN filter = nullptr, CurveKeys keys = {});

// A ray's time for Embree's time-step curves of `steps` steps: Embree 3.13.5 reports exits
// (back faces) and misses entries of ROUND_LINEAR_CURVE time steps on rays whose time is exactly
// a step (0, 0.5, 1 of 3: measured, tests/cpp/test_curve_motion.cpp), so such a time is moved
// off the step by 2^-20 of the shutter (the strand moves by that fraction of a step's motion).
inline float embree_curve_time(float time, int steps) {
    if (steps < 2) return time;
    const float x = time * float(steps - 1);
    if (x != floorf(x)) return time;
    const float d = 1.0f / 1048576.0f;
    return time >= 1.0f ? 1.0f - d : time + d;
}
#endif

}  // namespace lantern
