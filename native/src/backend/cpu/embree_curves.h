// Curve segments (accel/curve_bvh.h's CurveSeg) as Embree's ROUND_LINEAR_CURVE geometry: float4
// vertices (x, y, z, radius), joined segments (CurveSeg::flags) sharing their joint's vertex and
// marked with RTC_CURVE_FLAG_NEIGHBOR_* (no sphere at a joint, as accel/curve_hit.h leaves out),
// the others their own two, so the shape is accel/curve_hit.h's swept sphere. primID = the
// segment's place in `segs`.
#pragma once

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
#endif

}  // namespace lantern
