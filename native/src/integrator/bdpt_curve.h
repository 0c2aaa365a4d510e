// Strand vertices in the light-path integrators (bdpt, lvc, cis and lt; docs/curves.md
// "Bidirectional"): the fiber measure. A strand vertex is (s, h), the place along the strand and
// the offset across it of the ray that found it, whichever sub-path that was; its area element
// is r dh ds, so its geometric cosine towards w is cos theta(w), the cosine to the fiber's
// normal plane (the hair lobe's frame: X the tangent), from either side: a light path reaches
// every (s, h) a camera path does and the reverse. The hair lobe's BSDF in that measure is
// bsdf/hair_lobe.h's (Importance: f_cos(wi, wo) / cos theta(wo)).
// A strand shaded by any other BSDF (Principled, Diffuse, a mix, node programs) is not in the
// fiber measure: its vertex is pt's, the point on the tube's surface with the tube's outward
// normal, in the surface measure ("tube" vertices: docs/curves.md "Ordinary BSDFs on strands").
#pragma once

#include "bsdf/hair_lobe.h"
#include "scene/scene_view.h"

namespace lantern {

LANTERN_HD inline bool prim_is_strand(const SceneView& s, int prim) {
    return prim >= s.num_triangles;
}

// The geometric cosine at a vertex towards unit w: |ng.w| on a surface, cos theta on a strand
// (f: the strand hit's frame, X its tangent).
LANTERN_HD inline float vertex_cos(bool strand, const Frame& f, Vec3 ng, Vec3 w) {
    if (!strand) return fabsf(dot(w, ng));
    const float c = dot(w, f.s);
    return sqrtf(fmaxf(1.0f - c * c, 0.0f));
}

// On a strand (prim_is_strand), the fiber measure is the hair lobe's only; any other resolved
// material (programs keep the type) makes a tube vertex, and so does the hair lobe where it is
// also a mix's leaf (kHairTube: its lobe in the surface measure, bsdf/hair_lobe.h; a mix of the
// two measures would be neither: docs/curves.md "Principled Hair in a mix").
LANTERN_HD inline bool strand_fiber(const Material& m) {
    return m.type == kMaterialHair && !(m.tex_flags & kHairTube);
}

// The light sub-path's geometric cosine at a camera sub-path's vertex towards its light side w
// (the light path's area density of the vertex): vertex_cos, but 0 at a tube vertex whose light
// side is inside its fiber. pt reaches a tube point from outside only and lets a ray leave it
// through the fiber (only entries are reported), so a tube vertex faces its camera-side
// neighbour; a light path towards it through the fiber meets the fiber's near side first:
// that light technique has density 0 and the camera's techniques take the whole weight.
LANTERN_HD inline float light_arrival_cos(bool fiber, bool tube, const Frame& f, Vec3 ng,
                                          Vec3 w) {
    if (tube && !(dot(w, ng) > 0.0f)) return 0.0f;
    return vertex_cos(fiber, f, ng, w);
}

// A shadow segment ending at strand vertex y (prim, normal ng) from the far side of its fiber
// (dir: unit, towards y) would enter the fiber before it reaches y: it ends a chord earlier
// (2 r / cos theta at most), so that the fiber does not hide its own vertex.
LANTERN_HD inline float strand_end_shorten(const SceneView& s, int prim, Vec3 ng, Vec3 dir,
                                           const Frame& f) {
    if (!(dot(dir, ng) > 0.0f)) return 0.0f;  // arriving on y's own side
    const CurveSeg& g = s.curves.segs[prim - s.num_triangles];
    float r = fmaxf(g.r0, g.r1);
    if (g.flags & kCurveMoves)  // motion blur: the largest radius over the steps (no time here)
        for (int k = 0; k < s.curves.keys.num_steps; ++k) {
            const CurveSeg& a = s.curves.keys.keys[size_t(k) * size_t(s.curves.keys.num_segs) +
                                                   size_t(g.index)];
            r = fmaxf(r, fmaxf(a.r0, a.r1));
        }
    if (s.curves.num_sets > 0)  // a set moving with its object: the most its steps scale it
        if (const CurveSetMotion* cs = curve_set_of(s.curves, prim - s.num_triangles))
            r *= cs->radius_scale;
    return 2.02f * r / fmaxf(vertex_cos(true, f, ng, dir), 0.05f);
}

}  // namespace lantern
