// lt through a strand (docs/curves.md "lt through a strand"): pt reaches a tube vertex p from
// outside and may leave it through its own fiber (a ray from inside the round segment does not
// see it: only entries are reported), so pt's path space holds segments p -> y whose light side
// is inside p's fiber. A light path from y along the same line meets the fiber's near side p'
// first; the line goes on through the fiber and leaves it at p. So at a tube vertex whose BSDF
// transmits, lt takes with probability 1/2 the usual vertex p' (the light outside), with 1/2
// the point p where its ray leaves the strand (the light inside: the splat to the camera and
// the continuation leave p outwards, the one-sided rules of tube vertices). p lies on the
// light's ray, so its density from y is the same direction density at y converted at p: the
// throughput needs nothing but the 1 / (1/2). The two are different vertices of pt's path
// space (light outside at p', inside at p), so neither is counted twice.
// CPU only (strands render on the CPU: session.cpp); host code of lt_shade.
#pragma once

#include "integrator/bdpt_curve.h"
#include "integrator/pt_curve.h"

namespace lantern {

// The far root t > tmin of o + t w (w unit) leaving segment g's round shape (accel/
// curve_hit.h: the hull of its end spheres, a joined end without its sphere): true with *t.
// Where the line leaves through a joined end, *end is +1 (p1's side) or -1 (p0's) and false is
// returned: the line goes on in the neighbouring segment.
LANTERN_HD inline bool curve_exit_segment(Vec3 o, Vec3 w, const CurveSeg& g, float tmin,
                                          float* t, int* end) {
    *end = 0;
    const float shift = dot((g.p0 + g.p1) * 0.5f - o, w);  // (precision: curve_hit_segment)
    o = o + w * shift;
    tmin -= shift;
    float best = -kInf;
    auto sphere_far = [&](Vec3 c, float r) {
        const Vec3 q = o - c;
        const float b = dot(q, w);
        const Vec3 f = q - w * b;
        const float disc = r * r - dot(f, f);
        if (disc >= 0.0f) {
            const float tt = -b + sqrtf(disc);
            if (tt > tmin && tt > best) best = tt;
        }
    };
    if (g.r0 > 0.0f && !(g.flags & kCurveJoinStart)) sphere_far(g.p0, g.r0);
    if (g.r1 > 0.0f && !(g.flags & kCurveJoinEnd)) sphere_far(g.p1, g.r1);
    const Vec3 axis = g.p1 - g.p0;
    const float len = length(axis);
    const float sin_b = len > 0.0f ? (g.r0 - g.r1) / len : 1.0f;
    if (fabsf(sin_b) < 1.0f) {
        const Vec3 d = axis / len, q = o - g.p0;
        const float cos2 = 1.0f - sin_b * sin_b;
        const float s0 = dot(q, d), ws = dot(w, d), e0 = g.r0 - s0 * sin_b;
        const float a = cos2 - ws * ws;
        const float hb = cos2 * (dot(q, w) - s0 * ws) + ws * sin_b * e0;
        const float c = cos2 * (dot(q, q) - s0 * s0) - e0 * e0;
        const float disc = hb * hb - a * c;
        if (disc >= 0.0f && fabsf(a) > 0.0f) {
            const float sq = sqrtf(disc);
            const float roots[2] = {(-hb - sq) / a, (-hb + sq) / a};
            for (float tc : roots) {
                if (!(tc > tmin && tc > best)) continue;
                const float s = s0 + tc * ws;
                if (s < g.r0 * sin_b || s > len + g.r1 * sin_b || g.r0 - s * sin_b < 0.0f)
                    continue;
                const Vec3 radial = q + w * tc - d * s;
                const float rho = length(radial);
                if (!(rho > 0.0f)) continue;
                const Vec3 n = radial * (sqrtf(cos2) / rho) + d * sin_b;
                if (dot(n, w) > 0.0f) best = tc;  // an exit: the normal along the ray
            }
        }
        if (!(best > tmin)) {  // none: through a joined end (the line runs along the axis)
            if (ws > 0.0f && (g.flags & kCurveJoinEnd)) *end = 1;
            if (ws < 0.0f && (g.flags & kCurveJoinStart)) *end = -1;
        }
    }
    if (!(best > tmin)) return false;
    *t = best + shift;
    return true;
}

// Where the light path's ray (o + t d, unit d) that entered strand segment *prim at t_in leaves
// the strand: *prim the segment left (a neighbour where the line runs on through a joint), *h
// its surface there with the outward normal (facing along d). False where no exit is found.
inline bool lt_strand_exit(const SceneView& s, Vec3 o, Vec3 d, float t_in, float time,
                           int* prim, SurfaceHit* h) {
    int seg = *prim - s.num_triangles;
    // a set moving with its object: the segment in its exported frame (pt_curve.h)
    Vec3 oc = o, dc = d;
    float scale = 1.0f;  // (t there along the unit direction = scale x t in the world)
    const CurveSetMotion* cs = s.curves.num_sets > 0 ? curve_set_of(s.curves, seg) : nullptr;
    if (cs) {
        Transform inv;
        if (!transform_inverse(object_motion_to_world(s.motion, cs->o, time), &inv)) return false;
        oc = inv.point(o);
        dc = inv.vector(d);
        scale = length(dc);
        if (!(scale > 0.0f)) return false;
        dc = dc / scale;
    }
    const float tmin = t_in * scale;
    float t = 0.0f;
    bool found = false;
    for (int hop = 0; hop < 8 && !found; ++hop) {  // through at most a few joints
        int end = 0;
        found = curve_exit_segment(oc, dc, curve_seg_of(s.curves, seg, time), tmin, &t, &end);
        if (found) break;
        if (end == 0) return false;
        seg += end;
        if (seg < 0 || seg >= s.curves.num_segs) return false;
    }
    if (!found) return false;
    *prim = s.num_triangles + seg;
    // the point's place along the segment (its texture coordinate u: pt_surface_curve)
    const CurveSeg g = curve_seg_of(s.curves, seg, time);
    const Vec3 axis = g.p1 - g.p0;
    const float len2 = length_sq(axis);
    const float u = len2 > 0.0f ? clampf(dot(oc + dc * t - g.p0, axis) / len2, 0.0f, 1.0f)
                                : 0.0f;
    // the surface there, seen from beyond it (pt_surface_curve turns the normal towards the
    // ray: from the far side that is the outward normal, along d)
    const Vec3 p = o + d * (t / scale);
    *h = pt_surface_curve(s, *prim, Vec2{u, 0.0f}, p + d, -d, 1.0f, time);
    h->p = p;
    return dot(h->ng, d) > 0.0f;
}

// The continuation from the point p where the light left the strand (its direction wo inside
// the fiber, local to p's frame, Z outward). The BSDF's Importance sampler draws the hair lobe
// at the offset h(wo) of that inside direction, while the lobe's value is pt's at the offset
// h(wi) of the camera side's direction: the two offsets are unrelated at a tube vertex, and where
// f_{h(wi)} has its TT or TRT peak the sampler at h(wo) can have a density 10^-3 of it (the mix
// fur's firefly: weight 1,756, pdf 5.5e-4; docs/curves.md "lt through a strand"). So: the
// one-sample mixture of the BSDF's sampler and a cosine about Z, 1/2 each (u_pick), weighted by
// the mixture's density (the balance heuristic), which bounds the weight by 2 pi f |wi.z| /
// |wi.z|. A direction into the fiber (wi.z <= 0) cannot continue a tube vertex: invalid.
inline BsdfSample lt_strand_inside_sample(const Material& m, bool front, Vec3 wo, Vec3 u,
                                          float u_pick, Vec3 coat_n, Vec3 ng_l) {
    BsdfSample s{vec3(0.0f), vec3(0.0f), 0.0f, false};
    Vec3 wi;
    if (u_pick < 0.5f) {
        const BsdfSample b = material_sample(m, front, wo, u, Transport::Importance, coat_n, ng_l);
        if (!b.valid) return s;
        if (b.delta) {  // (a delta leaf: only this half proposes it)
            s = b;
            s.weight = b.weight * 2.0f;
            s.pdf_fwd_w = b.pdf_fwd_w * 0.5f;
            return s;
        }
        wi = b.wi;
    } else {
        float pdf_c = 0.0f;
        wi = sample_cosine_hemisphere(Vec2{u.x, u.y}, &pdf_c);
    }
    if (!(wi.z > 0.0f)) return s;
    const BsdfEval e = material_eval(m, front, wo, wi, Transport::Importance, coat_n, ng_l);
    const float pdf = 0.5f * e.pdf_fwd_w + 0.5f * wi.z * kInvPi;
    if (!(pdf > 0.0f)) return s;
    s.wi = wi;
    s.pdf_fwd_w = pdf;
    s.weight = e.f * (wi.z / pdf);
    s.valid = is_finite(s.weight);
    return s;
}

}  // namespace lantern
