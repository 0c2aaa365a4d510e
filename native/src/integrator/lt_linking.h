// Shadow linking, Cast Shadow off (a lamp's, an object's) and light linking in media in the light
// tracer (integrator "lt"), as pt renders them (bidir_linking.h, bidir_no_shadow.h,
// bidir_linking_medium.h). A light path y0 (on light l) y1 ... yk is splatted at the camera: in
// pt's terms x0 = y0, x1 = y1, and only the segment x0 x1 is a next-event shadow ray (the camera
// segment is a camera ray, the others BSDF rays: the ordinary query, as lt traces them).
//
// Next-event estimation sees l from x1 past every surface that does not cast l a shadow
// ("transparent": a non-caster, a surface outside a shadow-linked l's blocker set, any surface
// for a lamp without shadows, lt_shadow_passes). pt's image of the paths through x1 is
//     integral of f (V' w_nee + V w_bsdf)
// over the scattering at x1, V the ordinary visibility of x0 x1, V' the shadow query's, w_nee
// and w_bsdf pt's two weights (a shadow-linked light: 1 and 0 after a non-delta lobe; a delta
// lobe at x1: next-event estimation cannot make it, w_bsdf = 1). Light tracing's first segment
// therefore walks on: its first hit h1 (V = V' = 1: weight 1 whatever the lobe) and, past
// transparent surfaces, the hits h2, h3, ... up to the first surface that casts l a shadow
// (V = 0, V' = 1), each a candidate x1 that only next-event estimation makes: its non-delta
// lobes only, weighed by pt's w_nee (lt_nee_weight). One slot follows one path: at a transparent
// hit it stops there (y1 = h_j) or passes on, each with probability 1/2 and weight 2 (passing
// for sure where l does not light the hit's receiver set). PathState::walk_passed counts the
// surfaces passed (shadow_light's slots: lt traces no next-event rays of its own),
// PathState::prev_p / prev_n keep x0 and its normal for w_nee. In media (a shadow-linked light
// alone) the walk goes on through the media and boundaries as lt's paths do, each vertex taking
// pt's shadow ray's transmittance instead of the walked one (lt_medium.h lt_walk_ratio).
// A walk under the surface from a vertex past a transparent surface (lt_sss.h) takes pt's
// next-event weight at a walk's exit (lt_sss_nee_weight).
//
// Light linking in media (bidir_linking_medium.h): the path's receiver set is found from x1
// toward the camera, a surface's own, 0 at the first vertex in the world's medium, else pending
// through a mesh's volume (PathState::recv_set 1 while pending) and 0 at the camera: the light
// pass decides it at its first surface or world-medium vertex and ends the path where l does
// not light it; a pending vertex's splat takes set 0.
// Included by lt.h.
#pragma once

#include "integrator/bidir_linking.h"
#include "integrator/pt_surface.h"
#include "integrator/terminator.h"
#include "scene/light_tree.h"

namespace lantern {

// Whether light li's first segment walks past transparent surfaces (lt_shadow_passes).
LANTERN_HD inline bool lt_walks(const SceneView& s, int li) {
    return li >= 0 && (bidir_light_path_delta_only(s, li) || s.no_shadow_objects != 0);
}

// Whether pt's next-event shadow ray toward light li passes surface (or strand) tri: a lamp
// without shadows traces none, the shadow query skips non-casters (accel/bvh.h), a
// shadow-linked light's query stops at its blockers only (pt_occluded_linked).
LANTERN_HD inline bool lt_shadow_passes(const SceneView& s, int li, int tri) {
    if (pt_lamp_unshadowed(s, li)) return true;
    if (s.no_shadow_objects && !(s.tri_flags[tri] & kCastShadow)) return true;
    if (!bidir_nee_only(s, li)) return false;
    const int set = s.tri_shadow_set ? int(s.tri_shadow_set[tri]) : 0;
    return ((s.light_blockers[li] >> set) & 1u) == 0u;
}

// The receiver decision of slot i's vertex on triangle tri (-1: a medium vertex, `world`: in the
// world's medium): true where the path goes on. Clears the pending set where the vertex
// decides it (a surface, a world-medium vertex); a mesh volume's vertex keeps it pending.
LANTERN_HD inline bool lt_receiver_decides(const SceneView& s, const PathState& ps,
                                           const LightPathState& lp, int i, int tri, bool world) {
    if (!s.light_receivers || !lp.light || !ps.recv_set[i]) return true;
    if (tri < 0 && !world) return true;  // pending on
    ps.recv_set[i] = 0;
    return tri >= 0 ? bidir_links(s, lp.light[i], tri) : pt_light_links(s, lp.light[i], 0);
}

// A splat's factor for the receiver set: a pending path's is the camera's, set 0.
LANTERN_HD inline bool lt_pending_lit(const SceneView& s, const PathState& ps,
                                      const LightPathState& lp, int i) {
    return !s.light_receivers || !lp.light || !ps.recv_set[i] || pt_light_links(s, lp.light[i], 0);
}

// One step of the first segment's walk at slot i's hit on tri (point p): 1 where the hit is
// the path's y1 (the throughput then carries the choice's weight), 0 where the slot passed on
// (its ray continues past the hit) or ended. `linked`: whether light li lights the hit.
LANTERN_HD inline int lt_walk_step(const SceneView& s, const PathState& ps, int i, int li,
                                   int tri, Vec3 p, bool linked) {
    if (!lt_shadow_passes(s, li, tri)) return 1;  // it casts l a shadow: the walk's last hit
    if (ps.walk_passed(i) >= 255) return 0;  // (a bound: never an endless walk)
    if (linked) {
        Rng rng = ps.rng[i];
        const bool stop = rng.uniform() < 0.5f;
        ps.rng[i] = rng;
        ps.throughput[i] = ps.throughput[i] * 2.0f;
        if (stop) return 1;
    }
    if (tri >= s.num_triangles) {  // a strand: on from the same origin past its entry, as
        // pt_shadow_linked_query (re-offset from a grazing entry into an end sphere, the ray
        // found the strand again and again)
        const float t = ps.hit_t[i];
        ps.ray_tmin[i] = t + 1e-5f * fmaxf(t, s.offset_scale);
        ps.alive[i] = 1;
        ps.walk_passed(i) += 1;
        return 0;
    }
    const Vec3 ng = triangle_geometric_normal(s, tri);
    pt_pass_hidden(s, ps, i, p, ng);
    // in media: past a surface around a volume the walk is in it (pt's camera side would be);
    // pt's shadow ray keeps its medium (lt_walk_ratio)
    if (s.num_media > 0)
        ps.medium[i] = medium_across(s, tri, dot(ng, ps.ray_d[i]) <= 0.0f, ps.medium[i]);
    ps.walk_passed(i) += 1;
    return 0;
}

// pt's next-event density of light li from x1 = p (geometric normal ng, shading ns, triangle
// tri) along w_l: pick x light pdf, the light at x0 (PathState::prev_p, normal prev_n); 0 for a
// delta light (next-event estimation alone).
// (the light's solid-angle density alone: lt_light_pdf_w; a medium point's pick, n = 0:
// lt_ray_visibility.h lt_rays_medium_weight)
LANTERN_HD inline float lt_light_pdf_w(const SceneView& s, const PathState& ps, int i, int li,
                                       Vec3 p, Vec3 w_l) {
    if (li == s.world_light) return world_pdf_w(s, w_l);
    const Light& l = s.lights[li];
    const float t = l.type == kLightSun ? kInf : length(ps.prev_p[i] - p);
    return light_pdf_w_at(s, l, p, w_l, t, ps.prev_n[i],
                          s.motion.num_objects > 0 ? motion_time(ps.rng[i]) : 0.0f);
}

LANTERN_HD inline float lt_light_pdf(const SceneView& s, const PathState& ps, int i, int li,
                                     int tri, Vec3 p, Vec3 ng, Vec3 ns, Vec3 w_l) {
    const Light& l = s.lights[li];
    const float pdf_w = lt_light_pdf_w(s, ps, i, li, p, w_l);
    if (!(pdf_w > 0.0f)) return 0.0f;
    // the pick's normal as pt_shade (and pt_sss_exit) take it
    const Vec3 n_pick = (terminator_cutoff(s, tri) > 0.0f || s.light_rays) &&
                                dot(ns, ng) < 0.99999f
                            ? vec3(0.0f)
                            : light_pick_normal(s, tri, ng);
    const float pick = s.light_tree_on ? light_pick_pmf(s, li, p, n_pick) : l.nee_pdf;
    return pick * pdf_w;
}

// Whether light l is found by no bounce ray (a point, a spot of radius 0, a sun of angle 0):
// next-event estimation alone makes its paths.
LANTERN_HD inline bool lt_light_delta(const Light& l) {
    return ((l.type == kLightPoint || l.type == kLightSpot) && l.radius <= 0.0f) ||
           (l.type == kLightSun && l.cos_sun >= 1.0f);
}

// pt's next-event weight at a first-segment vertex past a transparent surface (x1 on triangle
// tri, material m, h's normals facing the light ray): the light at x0 (PathState::prev_p, normal
// prev_n) along w_l, the path going on along w_c, pdf_rev m's density of sampling w_l from w_c
// (pt's BSDF sampling). 0 where pt's next-event estimation does not take that side.
LANTERN_HD inline float lt_nee_weight(const SceneView& s, const PathState& ps, int i, int li,
                                      int tri, const Material& m, const SurfaceHit& h, Vec3 w_l,
                                      Vec3 w_c, float pdf_rev) {
    // pt's shading point faces the camera-side ray
    const bool flip = dot(w_c, h.ng) < 0.0f;
    const Vec3 ng = flip ? -h.ng : h.ng, ns = flip ? -h.ns : h.ns;
    const bool unshadowed = pt_lamp_unshadowed(s, li);
    const bool geo_side = light_side_agrees(m, w_l, ng, ns);
    if (!(geo_side || terminator_passes(s, tri, w_l, ng, ns) ||
          (unshadowed && !sides_agree(w_l, ng, ns))))
        return 0.0f;
    if (bidir_nee_only(s, li) || (!geo_side && !unshadowed)) return 1.0f;
    const float pdf = lt_light_pdf(s, ps, i, li, tri, h.p, ng, ns, w_l);
    // a delta light: next-event estimation alone; a light it never picks (a constant world,
    // scene_lights.cpp) or does not sample along w_l: the bounce ray alone
    if (!(pdf > 0.0f)) return lt_light_delta(s.lights[li]) ? 1.0f : 0.0f;
    return power_heuristic(pdf, pdf_rev);
}

// pt's next-event weight at a walk's exit x_o = h (pt_sss.h pt_sss_exit: the white Lambert
// exit lobe about the shading normal, h's normals facing the light) past a transparent surface:
// lt's walk from y1 = x_o is pt's exit whose next event found l; 0 where pt's takes no light.
LANTERN_HD inline float lt_sss_nee_weight(const SceneView& s, const PathState& ps, int i,
                                          int li, int tri, const SurfaceHit& h, Vec3 w_l) {
    const float cos_i = dot(w_l, h.ns);
    const bool geo_side = dot(w_l, h.ng) > 0.0f;
    const bool unshadowed = pt_lamp_unshadowed(s, li);
    if (!(cos_i > 0.0f) || !(geo_side || terminator_cutoff(s, tri) > 0.0f || unshadowed))
        return 0.0f;
    if (bidir_nee_only(s, li) || (!geo_side && !unshadowed)) return 1.0f;
    const float pdf = lt_light_pdf(s, ps, i, li, tri, h.p, h.ng, h.ns, w_l);
    if (!(pdf > 0.0f)) return lt_light_delta(s.lights[li]) ? 1.0f : 0.0f;  // (lt_nee_weight)
    return power_heuristic(pdf, cos_i * kInvPi);
}

}  // namespace lantern
