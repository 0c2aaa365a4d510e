// The shading normal a glossy lobe uses for a given view, as Cycles' "Bump Map Correction"
// (on by default) defines it: where the view's mirror direction about the shading normal n
// falls under the geometric surface, n is tilted towards the geometric normal ng, in the plane
// of the two, just far enough that the mirror direction rises a small threshold above the
// surface. Everything is in the local shading frame (n = +Z); the result is n itself wherever
// the mirror direction is already valid, so the correction is continuous.
#pragma once

#include "core/math.h"

namespace lantern {

// v: unit view direction on ng's side (v.ng >= 0); ng: unit geometric normal in this frame.
// The mirror of v about n is valid when its height above the surface is at least
// t = min(0.9 v.ng, 0.01). Otherwise, with x the unit tangent of n away from ng and the
// normal written n(theta) = sin(theta) x + cos(theta) ng, the mirror's height is
// a cos(2 theta - psi) with a = |(v.x, v.ng)| and psi = atan2(v.x, v.ng); the valid normals
// form the interval |2 theta - psi| <= acos(t / a), which holds ng (theta = 0), and the one
// closest to n is its upper end.
LANTERN_HD inline Vec3 valid_reflection_normal(Vec3 ng, Vec3 v) {
    const Vec3 n{0.0f, 0.0f, 1.0f};
    const float v_ng = dot(v, ng);
    const float t = fminf(0.9f * fmaxf(v_ng, 0.0f), 0.01f);
    const float r_ng = 2.0f * v.z * ng.z - v_ng;  // (2 (v.n) n - v) . ng
    if (r_ng >= t) return n;
    Vec3 x = n - ng * ng.z;  // n's tangent part about ng
    const float x_len2 = length_sq(x);
    if (!(x_len2 > 1e-12f)) return n;
    x = x * (1.0f / sqrtf(x_len2));
    const float vx = dot(v, x);
    const float a = sqrtf(vx * vx + v_ng * v_ng);
    if (!(a > 0.0f)) return n;
    const float theta = 0.5f * (atan2f(vx, v_ng) + acosf(fminf(t / a, 1.0f)));
    const Vec3 c = x * sinf(theta) + ng * cosf(theta);
    return is_finite(c) && c.z > 0.0f ? normalize(c) : n;
}

// The local frame about n' (from valid_reflection_normal) with its first axis the old frame's
// first axis made orthogonal to n' (the smallest turn: anisotropic lobes keep their tangent).
LANTERN_HD inline Frame valid_reflection_frame(Vec3 n2) {
    Frame f;
    f.n = n2;
    Vec3 s = Vec3{1.0f, 0.0f, 0.0f} - n2 * n2.x;
    if (!(length_sq(s) > 1e-12f)) s = Vec3{0.0f, 1.0f, 0.0f} - n2 * n2.y;
    f.s = normalize(s);
    f.t = cross(n2, f.s);
    return f;
}

}  // namespace lantern
