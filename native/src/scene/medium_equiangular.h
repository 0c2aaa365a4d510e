// Equiangular sampling of a distance along a ray segment towards a point (a light), for
// next-event estimation in media (docs/volumes.md): the density of s in [0, len] is
// proportional to 1 / (D^2 + (s - delta)^2), the inverse squared distance to the point, whose
// foot on the ray lies at delta and distance D from it (Kulla & Fajardo 2012). Host+device.
#pragma once

#include "core/math.h"
#include "scene/medium.h"

namespace lantern {

struct Equiangular {
    float delta;   // the foot of the point on the ray (relative to the segment's start)
    float dist;    // D: the point's distance from the ray's line
    float a, b;    // the sampled interval, within the segment [0, len]
    float theta0;  // angle subtended at s = a, in (-pi/2, pi/2)
    float theta1;  // at s = b (pi/2 for an endless interval)
    bool ok;       // false: no sampling (the point on the line, an empty interval)
};

// The set-up for the interval [a, b] (b may be kInf) of a ray from o along unit d, towards x.
// soften > 0: the density of 1 / (D^2 + soften^2 + (s - delta)^2), for a light of that radius
// whose irradiance is I / (d^2 + r^2) (a soft-falloff point or spot): with the bare centre a
// ray passing through the light (D -> 0) drew weights growing as 1 / D (fireflies).
LANTERN_HD inline Equiangular equiangular_setup(Vec3 o, Vec3 d, float a, float b, Vec3 x,
                                                float soften = 0.0f) {
    Equiangular e{};
    const Vec3 ox = x - o;
    e.delta = dot(ox, d);
    e.dist = length(ox - d * e.delta);
    if (soften > 0.0f) e.dist = sqrtf(e.dist * e.dist + soften * soften);
    e.a = a;
    e.b = b;
    e.theta0 = atan2f(a - e.delta, e.dist);
    e.theta1 = b < kInf ? atan2f(b - e.delta, e.dist) : 0.5f * kPi;
    // on the line (or next to it in float) the density degenerates to a delta at the point
    e.ok = e.dist > 1e-6f * fmaxf(fabsf(e.delta), 1.0f) && e.theta1 - e.theta0 > 1e-6f &&
           b > a && a >= 0.0f && is_finite(Vec3{e.delta, e.dist, e.theta0});
    return e;
}
// ... over the whole segment [0, len]
LANTERN_HD inline Equiangular equiangular_setup(Vec3 o, Vec3 d, float len, Vec3 x,
                                                float soften = 0.0f) {
    return equiangular_setup(o, d, 0.0f, len, x, soften);
}

// The density of s (0 outside [a, b]).
LANTERN_HD inline float equiangular_pdf(const Equiangular& e, float s) {
    if (!e.ok || !(s >= e.a && s <= e.b)) return 0.0f;
    const float h = s - e.delta;
    return e.dist / ((e.theta1 - e.theta0) * (e.dist * e.dist + h * h));
}

// A distance from u in [0, 1), clamped into [a, b] against rounding.
LANTERN_HD inline float equiangular_sample(const Equiangular& e, float u) {
    const float th = e.theta0 + u * (e.theta1 - e.theta0);
    const float s = e.delta + e.dist * tanf(th);
    return fminf(fmaxf(s, e.a), e.b);
}

// The part [*t0, *t1] of the segment [0, len] (len may be kInf) of a ray from o along unit d
// inside a spot light's cone (apex, unit axis, cosine of the half angle, < 90 degrees: a convex
// cone, so one interval); false when the ray misses it. Outside it the spot sends nothing
// (spot_attenuation), so equiangular sampling need not spend samples there.
LANTERN_HD inline bool spot_cone_interval(Vec3 apex, Vec3 axis, float cos_half, Vec3 o, Vec3 d,
                                          float len, float* t0, float* t1) {
    if (!(cos_half > 0.0f)) {  // a cone of 90 degrees or more: keep the whole segment
        *t0 = 0.0f;
        *t1 = len;
        return len > 0.0f;
    }
    const Vec3 v = o - apex;
    const float c2 = cos_half * cos_half;
    const float da = dot(d, axis), va = dot(v, axis);
    const float A = da * da - c2, B = 2.0f * (va * da - c2 * dot(v, d)),
                C = va * va - c2 * length_sq(v);
    // the breakpoints: the segment's ends and the quadric's roots within it
    float ts[4] = {0.0f, len, len, len};
    int n = 1;
    if (fabsf(A) > 1e-12f) {
        const float disc = B * B - 4.0f * A * C;
        if (disc >= 0.0f) {
            const float q = -0.5f * (B + copysignf(sqrtf(disc), B));
            float r0 = q / A, r1 = q != 0.0f ? C / q : r0;
            if (r0 > r1) { const float t = r0; r0 = r1; r1 = t; }
            if (r0 > 0.0f && r0 < len) ts[n++] = r0;
            if (r1 > 0.0f && r1 < len && r1 > ts[n - 1]) ts[n++] = r1;
        }
    } else if (fabsf(B) > 1e-12f) {
        const float r = -C / B;
        if (r > 0.0f && r < len) ts[n++] = r;
    }
    ts[n++] = len;
    float lo = kInf, hi = -kInf;
    for (int k = 0; k + 1 < n; ++k) {
        const float s0 = ts[k], s1 = ts[k + 1];
        if (!(s1 > s0)) continue;
        const float mid = s1 < kInf ? 0.5f * (s0 + s1) : 2.0f * s0 + 1.0f;
        const Vec3 w = v + d * mid;
        const float wa = dot(w, axis);
        if (wa > 0.0f && wa * wa >= c2 * length_sq(w)) {
            lo = fminf(lo, s0);
            hi = fmaxf(hi, s1);
        }
    }
    *t0 = lo;
    *t1 = hi;
    return hi > lo;
}

// The density of the free-flight distance s under medium_sample_distance (one-sample MIS over
// the channels with probabilities pmf): the distance strategy's pdf in the MIS weights.
LANTERN_HD inline float medium_distance_pdf(const Medium& m, Vec3 pmf, float s) {
    const Vec3 tr = medium_transmittance(m, s);
    return pmf.x * m.sigma_t.x * tr.x + pmf.y * m.sigma_t.y * tr.y + pmf.z * m.sigma_t.z * tr.z;
}

}  // namespace lantern
