// Ray against one round linear curve segment: the union of the spheres swept from (p0, r0) to
// (p1, r1), i.e. a cone tangent to both end spheres plus the spheres' outer caps (Embree's
// ROUND_LINEAR_CURVE shape). Host+device; the first entry only (tmin < t <= tmax): a ray that
// starts inside the strand sees nothing of it, so a ray leaving a strand's surface does not hit
// it again. The hit carries the surface normal and the axial parameter u in [0, 1].
#pragma once

#include "core/math.h"

namespace lantern {

// Ends of a segment that join the next segment of a strand (CurveSeg::flags): no end sphere.
constexpr int kCurveJoinStart = 1, kCurveJoinEnd = 2;
// A segment that moves over the shutter (CurveSeg::flags; docs/motion_blur.md "Strands"): its
// keys at the steps are in CurveKeys, and a ray meets it lerped at the ray's time.
constexpr int kCurveMoves = 4;

struct CurveHit {
    float t;
    float u;   // along the segment: the axis point whose sphere the hit lies on
    Vec3 n;    // outward unit normal (geometric)
};

// Nearest entry of o + t w (w need not be unit) into the sphere (c, r) with t in (tmin, tmax]:
// the smaller root only, so an origin inside (smaller root <= 0 <= tmin) sees no entry. o should
// lie near the sphere (curve_hit_segment moves it there), or the roots lose their precision.
LANTERN_HD inline bool curve_hit_sphere(Vec3 o, Vec3 w, Vec3 c, float r, float tmin, float tmax,
                                        float* t) {
    const Vec3 q = o - c;
    const float a = dot(w, w), b = dot(q, w);
    const Vec3 f = q - w * (b / a);  // the discriminant as r^2 - |q x w|^2 / a (RTG ch. 7)
    const float disc = a * (r * r - dot(f, f));
    if (!(disc >= 0.0f)) return false;
    const float tt = (-b - sqrtf(disc)) / a;
    if (!(tt > tmin && tt <= tmax)) return false;
    *t = tt;
    return true;
}

// joins: kCurveJoinStart / kCurveJoinEnd, the ends whose sphere is left out (a joint)
LANTERN_HD inline bool curve_hit_segment(Vec3 o, Vec3 w, Vec3 p0, float r0, Vec3 p1, float r1,
                                         float tmin, float tmax, CurveHit* hit, int joins = 0) {
    // radii: at least 0 and not both 0 (a tip of radius 0 is a cone to a point); else no surface
    if (!(r0 >= 0.0f && r1 >= 0.0f && r0 + r1 > 0.0f)) return false;
    // ---- Solve from the ray's point nearest the segment's middle ----
    // far rays on thin strands: from o itself, |q|^2 - s0^2 (a radius^2 of 1e-5 out of 10) kept
    // too few bits and t came out ~1e-4 off (found against Embree, test_curve_embree)
    const float shift = dot((p0 + p1) * 0.5f - o, w) / dot(w, w);
    o = o + w * shift;
    tmin -= shift;
    tmax -= shift;
    const Vec3 axis = p1 - p0;
    const float len = length(axis);
    bool found = false;
    float best = tmax, t;
    // ---- End spheres ----
    if (r0 > 0.0f && !(joins & kCurveJoinStart) && curve_hit_sphere(o, w, p0, r0, tmin, best, &t)) {
        best = t;
        hit->u = 0.0f;
        hit->n = (o + w * t - p0) / r0;
        found = true;
    }
    if (r1 > 0.0f && !(joins & kCurveJoinEnd) && curve_hit_sphere(o, w, p1, r1, tmin, best, &t)) {
        best = t;
        hit->u = 1.0f;
        hit->n = (o + w * t - p1) / r1;
        found = true;
    }
    // ---- The cone tangent to both (none when one sphere holds the other) ----
    const float sin_b = len > 0.0f ? (r0 - r1) / len : 1.0f;
    if (fabsf(sin_b) < 1.0f) {
        // a point x at axial s = (x - p0).d and distance rho from the axis lies on the cone when
        // rho cos_b = r0 - s sin_b, for s between the tangency planes r0 sin_b and len + r1 sin_b
        const Vec3 d = axis / len, q = o - p0;
        const float cos2 = 1.0f - sin_b * sin_b;
        const float s0 = dot(q, d), ws = dot(w, d), e0 = r0 - s0 * sin_b;
        const float a = cos2 * dot(w, w) - ws * ws;
        const float hb = cos2 * (dot(q, w) - s0 * ws) + ws * sin_b * e0;
        const float c = cos2 * (dot(q, q) - s0 * s0) - e0 * e0;
        const float disc = hb * hb - a * c;
        if (disc >= 0.0f && fabsf(a) > 0.0f) {
            const float sq = sqrtf(disc);
            const float roots[2] = {(-hb - sq) / a, (-hb + sq) / a};
            for (int k = 0; k < 2; ++k) {
                const float tc = roots[k];
                if (!(tc > tmin && tc < best)) continue;
                const float s = s0 + tc * ws;
                if (s < r0 * sin_b || s > len + r1 * sin_b || r0 - s * sin_b < 0.0f) continue;
                // entry only: the normal faces the ray
                const Vec3 x = q + w * tc, radial = x - d * s;
                const float rho = length(radial);
                if (!(rho > 0.0f)) continue;
                const Vec3 n = radial * (sqrtf(cos2) / rho) + d * sin_b;
                if (dot(n, w) >= 0.0f) continue;
                best = tc;
                hit->n = n;
                // the sphere through x is centred where the normal line meets the axis
                hit->u = clampf((s - rho * sin_b / sqrtf(cos2)) / len, 0.0f, 1.0f);
                found = true;
                break;
            }
        }
    }
    if (found) hit->t = best + shift;
    return found;
}

}  // namespace lantern
