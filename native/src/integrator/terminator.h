// The shadow terminator of smooth-shaded meshes, as Cycles renders it (its Object > Shading
// "Shadow Terminator Geometry Offset", default 0.1; docs/materials.md "Shadow terminator").
// A coarse mesh's flat triangles under smooth normals are lit, by the shading normal, from
// directions under their own plane; a shadow ray from the flat point then runs into the mesh and
// the lit side ends in a dark band along the triangles (the terminator). Where a triangle's
// mesh has an offset (SceneView::tri_terminator > 0), next-event estimation from the camera
// side takes light on either side of the geometric normal where the BSDF has it (the shading
// normal decides, as Cycles' BSDF evaluation does), and the shadow ray starts from the point
// lifted toward the curved surface the vertex normals describe (Hanika 2021, "Hacking the
// Shadow Terminator": a parabola through the corners, bounded by the corners' tangent planes),
// by an amount that fades in as the light nears the terminator. Forward sampling still keeps
// to the geometric side, so such light is next-event estimation's alone (MIS weight 1). Only
// next-event rays to lights (pt, pt's subsurface exits, the bidirectional camera vertices'):
// connections to light sub-path vertices stay unlifted, as pt's BSDF-sampled indirect light.
#pragma once

#include "core/math.h"
#include "scene/scene_view.h"

namespace lantern {

// The mesh's offset for triangle tri (0 for strands, meshes without normals, or none set).
LANTERN_HD inline float terminator_cutoff(const SceneView& s, int tri) {
    if (!s.tri_terminator || tri < 0 || tri >= s.num_triangles) return 0.0f;
    return s.tri_terminator[tri];
}

// How far (0..1) the shadow ray toward w is lifted: 1 from where the light is at the cutoff
// above the geometric plane (on the shading normal's side of w), fading to 0 above it.
LANTERN_HD inline float terminator_amount(float cutoff, Vec3 ng, Vec3 ns, Vec3 w) {
    float nl = dot(ns, w);
    const Vec3 side = nl < 0.0f ? -ng : ng;
    nl = fabsf(nl);
    const float ngl = dot(side, w);
    const float a = nl < cutoff ? 2.0f - (ngl + nl) / cutoff : 1.0f - ngl / cutoff;
    return a < 0.0f ? 0.0f : (a > 1.0f ? 1.0f : a);
}

// The lift of point p on the triangle of corners v and vertex normals n toward the smooth
// surface, on side `side` (the geometric normal facing the light's side of the shading normal):
// the vertex normals' parabola, at most the corners' tangent planes' envelope and at least half
// the parabola. Zero where degenerate.
LANTERN_HD inline Vec3 terminator_lift_on(const Vec3 v[3], const Vec3 vn[3], Vec3 p, Vec3 side) {
    const Vec3 v0 = v[0], v1 = v[1], v2 = v[2];
    Vec3 n0 = vn[0], n1 = vn[1], n2 = vn[2];
    // barycentrics of p (on the triangle, up to rounding)
    const Vec3 e1 = v1 - v0, e2 = v2 - v0, d = p - v0;
    const float d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2);
    const float den = d11 * d22 - d12 * d12;
    if (!(den > 0.0f)) return vec3(0.0f);
    const float d1 = dot(d, e1), d2 = dot(d, e2);
    float b1 = (d22 * d1 - d12 * d2) / den, b2 = (d11 * d2 - d12 * d1) / den;
    b1 = fminf(fmaxf(b1, 0.0f), 1.0f);
    b2 = fminf(fmaxf(b2, 0.0f), 1.0f - b1);
    const float b0 = 1.0f - b1 - b2;
    Vec3 n = n0 * b0 + n1 * b1 + n2 * b2;  // unnormalised, as Cycles'
    if (dot(n, side) < 0.0f) {  // seen from the vertex normals' back: the same, mirrored
        n = -n;
        n0 = -n0;
        n1 = -n1;
        n2 = -n2;
    }
    const Vec3 q = v0 * b0 + v1 * b1 + v2 * b2;
    // the parabola through the corners with the vertex normals' slopes
    const float a = dot(n2 - n0, v0 - v2), b = dot(n2 - n1, v1 - v2), c = dot(n1 - n0, v1 - v0);
    float h = a * b0 * (b0 - 1.0f) + (a + b + c) * b0 * b1 + b * b1 * (b1 - 1.0f);
    // each corner's tangent plane, raised to pass over the triangle's other corners
    float h0 = fmaxf(fmaxf(dot(v1 - v0, n0), dot(v2 - v0, n0)), 0.0f);
    float h1 = fmaxf(fmaxf(dot(v0 - v1, n1), dot(v2 - v1, n1)), 0.0f);
    float h2 = fmaxf(fmaxf(dot(v0 - v2, n2), dot(v1 - v2, n2)), 0.0f);
    h0 = fmaxf(dot(v0 - q, n0) + h0, 0.0f);
    h1 = fmaxf(dot(v1 - q, n1) + h1, 0.0f);
    h2 = fmaxf(dot(v2 - q, n2) + h2, 0.0f);
    h = fmaxf(fminf(fminf(h0, h1), h2), 0.5f * h);
    const Vec3 lift = n * h;
    return is_finite(lift) ? lift : vec3(0.0f);
}

// The same on triangle tri as exported (its still corners and vertex normals).
LANTERN_HD inline Vec3 terminator_lift(const SceneView& s, int tri, Vec3 p, Vec3 side) {
    const uint32_t* idx = s.indices + 3 * tri;
    const Vec3 v[3] = {s.positions[idx[0]], s.positions[idx[1]], s.positions[idx[2]]};
    const Vec3 n[3] = {s.normals[idx[0]], s.normals[idx[1]], s.normals[idx[2]]};
    return terminator_lift_on(v, n, p, side);
}

// The lift on triangle tri of a moving mesh at `time` (D49: p and side are where the hit is
// then, motion_surface's): the lift taken on the triangle moved to `time`, its corners by the
// object's matrix and its vertex normals as normals (a deforming mesh's corners at the time
// first, its vertex normals turned as the triangle's normal turns, as deform_hit turns the
// hit's). Out of line (the device's stack: one matrix, no inverse): still scenes never call it.
#ifndef __CUDA_ARCH__
__attribute__((noinline))
#endif
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline Vec3 terminator_lift_moved(const SceneView& s, int tri, Vec3 p, Vec3 side,
                                             float time) {
    const ObjectMotion* o = object_motion_of(s.motion, tri);
    if (!o) return terminator_lift(s, tri, p, side);
    const uint32_t* idx = s.indices + 3 * tri;
    Vec3 v[3], n[3];
    for (int j = 0; j < 3; ++j) {
        v[j] = s.positions[idx[j]];
        n[j] = s.normals[idx[j]];
    }
    if (const DeformMesh* dm = deform_of(s.motion, *o)) {
        Vec3 pd[3];
        deform_triangle(s.motion, *dm, tri, time, pd);
        const Vec3 ne = cross(v[1] - v[0], v[2] - v[0]), nd = cross(pd[1] - pd[0], pd[2] - pd[0]);
        const float le = length(ne), ld = length(nd);
        for (int j = 0; j < 3; ++j) {
            v[j] = pd[j];
            if (le > 0.0f && ld > 0.0f)
                n[j] = rotate_between(ne * (1.0f / le), nd * (1.0f / ld), n[j]);
        }
    }
    const Transform m = object_motion_to_world(s.motion, *o, time);
    for (int j = 0; j < 3; ++j) {  // (a mirroring matrix flips all three: the lift mirrors back)
        v[j] = m.point(v[j]);
        n[j] = normalize(motion_normal(m, n[j]));
    }
    return terminator_lift_on(v, n, p, side);
}

// Next-event estimation's shadow origin toward w from hit point p of triangle tri (before the
// self-intersection offset): p lifted where the mesh has a terminator offset; `time`: the
// path's shutter time (read only where meshes move).
LANTERN_HD inline Vec3 terminator_origin(const SceneView& s, int tri, Vec3 p, Vec3 ng, Vec3 ns,
                                         Vec3 w, float time) {
    const float cutoff = terminator_cutoff(s, tri);
    if (!(cutoff > 0.0f)) return p;
    const float amount = terminator_amount(cutoff, ng, ns, w);
    if (!(amount > 0.0f)) return p;
    const Vec3 side = dot(ns, w) < 0.0f ? -ng : ng;
    const Vec3 lift = s.motion.num_objects > 0 ? terminator_lift_moved(s, tri, p, side, time)
                                               : terminator_lift(s, tri, p, side);
    return p + lift * amount;
}

// The light's side test of next-event estimation with the terminator: where the mesh has an
// offset, a direction on which the geometric and the shading normal disagree is the BSDF's to
// weigh (the shadow ray, from the lifted point, decides whether the mesh hides it).
LANTERN_HD inline bool terminator_passes(const SceneView& s, int tri, Vec3 w, Vec3 ng,
                                         Vec3 ns) {
    return dot(w, ng) * dot(w, ns) < 0.0f && terminator_cutoff(s, tri) > 0.0f;
}

}  // namespace lantern
