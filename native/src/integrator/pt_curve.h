// A path's hit on a strand (docs/curves.md; scene/curves.h): prim >= num_triangles. The surface
// is the round segment's at o + t d: the cross-section normal as both geometric and shading
// normal (facing the ray: only entries are reported), the frame turned so that its X is the
// strand's tangent (the hair lobe's frame, bsdf/hair_lobe.h), texture coordinates (u, 0).
#pragma once

#include "integrator/pt_features.h"
#include "integrator/pt_surface.h"

namespace lantern {

#ifndef __CUDA_ARCH__
__attribute__((noinline))  // off pt_shade's usual path
#endif
LANTERN_HD inline SurfaceHit pt_surface_curve(const SceneView& s, int prim, Vec2 uv, Vec3 o,
                                              Vec3 d, float t, float time = 0.0f) {
    // a moving strand (motion blur): the segment as the ray met it, at the path's time
    const int seg = prim - s.num_triangles;
    const CurveSeg g = curve_seg_of(s.curves, seg, time);
    SurfaceHit h;
    h.p = o + d * t;
    Vec3 tangent;
    Vec3 n;
    const CurveSetMotion* cs = s.curves.num_sets > 0 ? curve_set_of(s.curves, seg) : nullptr;
    Transform m, inv;
    if (cs && (m = object_motion_to_world(s.motion, cs->o, time), transform_inverse(m, &inv))) {
        // a set moving with its object: the segment in its exported frame, the hit brought
        // there, the normal and tangent back by the matrix at the path's time (a mirror's
        // cofactors turn the normal inside: the sign of the determinant)
        n = curve_normal_at(g, inv.point(h.p), &tangent);
        const float det = m.m[0][0] * (m.m[1][1] * m.m[2][2] - m.m[1][2] * m.m[2][1]) -
                          m.m[0][1] * (m.m[1][0] * m.m[2][2] - m.m[1][2] * m.m[2][0]) +
                          m.m[0][2] * (m.m[1][0] * m.m[2][1] - m.m[1][1] * m.m[2][0]);
        n = normalize(motion_normal(m, n)) * (det < 0.0f ? -1.0f : 1.0f);
        tangent = normalize(m.vector(tangent));
    } else {
        n = curve_normal_at(g, h.p, &tangent);
    }
    if (dot(n, d) > 0.0f) n = -n;  // a grazing entry rounded to the far side
    h.ng = h.ns = n;
    h.front = true;
    h.st = Vec2{uv.x, 0.0f};
    const Frame f = Frame::from_normal(n);
    const Vec3 tp = tangent - n * dot(tangent, n);
    h.tangent_angle = length_sq(tp) > 1e-12f ? atan2f(dot(tp, f.t), dot(tp, f.s)) : 0.0f;
    return h;
}

// The surface of a hit (prim, uv, t) of the ray o + t d, a triangle's as exported or a strand's
// at the ray's `time` (a moving strand: motion blur): the passes (integrator/aov.cpp), the light
// probe and the light-path stages' strand vertices read it.
LANTERN_HD inline SurfaceHit surface_of_hit(const SceneView& s, int prim, Vec2 uv, Vec3 o, Vec3 d,
                                            float t, float time = 0.0f) {
    return prim >= s.num_triangles ? pt_surface_curve(s, prim, uv, o, d, t, time)
                                   : pt_surface(s, prim, uv, d);
}

// The surface at slot i's hit, a triangle's or a strand's (F: pt_features.h).
template <uint32_t F = kPtAll>
LANTERN_HD inline SurfaceHit pt_surface_at(const SceneView& s, const PathState& ps, int i, int prim,
                                           Vec3 d) {
    if ((F & kPtStrands) && __builtin_expect(prim >= s.num_triangles, 0))  // off the usual path
        return pt_surface_curve(s, prim, ps.hit_uv[i], ps.ray_o[i], d, ps.hit_t[i],
                                (F & kPtMotion) && s.motion.curves ? motion_time(ps.rng[i])
                                                                   : 0.0f);
    return (F & kPtMotion) && s.motion.num_objects
               ? pt_surface_moved(s, prim, ps.hit_uv[i], d, ps.rng[i])
               : pt_surface(s, prim, ps.hit_uv[i], d);
}

}  // namespace lantern
