// pt's stages in homogeneous media (docs/volumes.md): per traced segment, the medium's emission
// (integrated exactly), a free-flight distance (one-sample MIS over the RGB channels) and,
// where it falls inside the segment, a medium vertex: next-event estimation with the
// Henyey-Greenstein phase function (power heuristic against phase sampling) and a phase-sampled
// continuation. Volume boundaries (materials with no surface) are passed through; shadow rays
// carry the transmittance of every medium they cross. Run only where SceneView::num_media > 0.
// Included by pt.h after pt_emission_weight, which it uses.
#pragma once

#include "accel/boundary_hits.h"
#include "integrator/pt_light_linking.h"  // pt_medium_receiver
#include "integrator/motion_stage.h"  // a moving volume's boundary at the path's time
#include "scene/medium.h"
#include "scene/medium_equiangular.h"

namespace lantern {

// The medium on the far side of triangle tri for a ray crossing it (front: entering it from the
// side its normal faces): a material with a medium is entered and left for the medium around
// its mesh (Medium::outside: an enclosing mesh medium's, or the world's); one without keeps the
// medium the ray is in (Cycles' stack ignores objects without a volume).
LANTERN_HD inline int32_t medium_across(const SceneView& s, int tri, bool front, int32_t now) {
    const int32_t inside = s.material_medium[s.tri_material[tri]];
    if (inside < 0) return now;
    return front ? inside : s.media[inside].outside;
}

// ---- Lights along the segment, each seen through the medium up to where it lies ----
LANTERN_HD inline void pt_collect_lights_medium(const SceneView& s, const PathState& ps, int i,
                                                Vec3 o, Vec3 d, float tmin, float tmax,
                                                const Medium& m, Vec3 pmf) {
    const bool camera = ps.depth[i] <= 1;
    for (int k = 0; k < s.num_hittable_lights; ++k) {
        const Light& l = s.lights[s.hittable_lights[k]];
        if (camera && !l.visible_camera) continue;
        if (pt_lamp_unseen(s, ps, i, s.hittable_lights[k])) continue;  // its ray visibility
        const LightHit h = intersect_light(l, o, d, tmin, tmax);
        if (!h.hit || is_black(h.le)) continue;
        const float pdf = pt_light_pdf_w(s, ps, i, l, o, d, h.t, h.n);
        const Vec3 tr = medium_pass_weight(m, pmf, h.t - tmin);
        add_radiance(ps, i, ps.throughput[i] * tr * h.le *
                                pt_emission_weight(s, ps, i, s.hittable_lights[k], pdf));
    }
}

// ---- Next-event estimation from a medium point p reached along d: a light from the light tree
// (an omnidirectional receiver, n = 0), weighted by the power heuristic against the phase
// sample, the contribution scaled by `factor` (the path's throughput to p and, for a distance
// chosen by two strategies, its MIS weight); into the slot's shadow ray, or into its medium
// shadow ray (second: the equiangular estimate, PathState::vshadow_*) ----
LANTERN_HD inline void pt_medium_nee(const SceneView& s, const PathState& ps, int i, Vec3 p,
                                     Vec3 d, const Medium& m, Vec3 factor, bool second,
                                     Rng& rng) {
    const Vec2 u_pick = rng.uniform2();
    const Vec2 u_light = rng.uniform2();
    const LightPick pick = light_pick(s, p, vec3(0.0f), u_pick.x);
    if (!(pick.pmf > 0.0f) || is_black(factor)) return;
    const LightSample ls = sample_light(s, s.lights[pick.light], p, u_light,  // (path's time)
                                        s.motion.num_objects > 0 ? motion_time(rng) : 0.0f);
    const float pdf_light = pick.pmf * ls.pdf_w;
    if (!ls.valid || is_black(ls.le) || !(pdf_light > 0.0f)) return;
    if (pt_light_hidden(s, pick.light, kRayKindVolume)) return;  // ray visibility
    if (!(s.world_rays & kWorldVolume) &&  // the world hidden from Volume Scatter (Cycles:
        (pick.light == s.world_light || s.lights[pick.light].of_world))  // SHADER_EXCLUDE_SCATTER)
        return;
    // light linking: a medium point receives as its medium's set (pt_medium_receiver)
    if (s.light_receivers && ps.recv_set &&
        !pt_light_links(s, pick.light, pt_medium_receiver(s, ps, i)))
        return;
    const float phase = hg_phase(m.g, dot(d, ls.wi));
    // shadow linking: next-event estimation alone (its shadow ray passes what casts it none)
    const float w = ls.delta || pt_shadow_linked(s, pick.light) ? 1.0f
                                                                : power_heuristic(pdf_light, phase);
    Vec3 sd = ls.wi;
    float tmax = kInf;
    if (ls.dist < kInf) {  // aimed at the offset point on the light, shortened there
        Vec3 target = ls.p_light;
        if (!is_black(ls.n_light))
            target = offset_ray_origin(target, ls.n_light, -ls.wi, s.offset_scale);
        const Vec3 seg = target - p;
        const float len = length(seg);
        if (len > 0.0f) sd = seg / len;
        tmax = len * (1.0f - 1e-4f);
    }
    const Vec3 c = factor * ls.le * (phase * w / pdf_light);
    if (pt_lamp_unshadowed(s, pick.light)) {  // Cast Shadow off: no shadow ray, no medium on it
        add_radiance(ps, i, c);
        return;
    }
    if (s.light_blockers && ps.shadow_light)  // shadow linking: the light, for its blocker sets
        (second ? ps.vshadow_light : ps.shadow_light)[i] = pick.light;
    if (second) {
        ps.vshadow_o[i] = p;
        ps.vshadow_d[i] = sd;
        ps.vshadow_tmax[i] = tmax;
        ps.vshadow_contrib[i] = c;
        ps.vshadow_medium[i] = ps.medium[i];
        ps.vshadow_valid[i] = 1;
    } else {
        ps.shadow_o[i] = p;
        ps.shadow_d[i] = sd;
        ps.shadow_tmax[i] = tmax;
        ps.shadow_contrib[i] = c;
        ps.shadow_medium[i] = ps.medium[i];
        ps.shadow_valid[i] = 1;
    }
}

// Moves rng past pt_medium_nee's numbers (its two pairs), as a call that returns early does,
// so that the path's later numbers keep their dimensions.
LANTERN_HD inline void pt_medium_nee_skip(Rng& rng) {
#ifndef LANTERN_RNG_PCG
    rng.dim += (rng.dim & 1u) + 4u;
#else
    rng.uniform2();
    rng.uniform2();
#endif
}

// ---- A medium vertex at p, reached along d: next-event estimation (its contribution times
// nee_weight, the distance strategy's MIS weight against equiangular sampling), then the phase
// sample ----
LANTERN_HD inline void pt_medium_vertex(const SceneView& s, const PathState& ps,
                                        const PtSettings& st, int i, Vec3 p, Vec3 d,
                                        const Medium& m, float nee_weight, Rng& rng) {
    const int depth = ps.depth[i];
    if (depth >= st.max_depth) return;
    // a medium vertex: next-event estimation alone for a shadow-linked light, its phase
    // sample's ray weighs 0 (pt_linked_bounce)
    if (ps.shadow_mis) ps.shadow_mis[i] = -1.0f;
    const Vec3 beta = ps.throughput[i];
    const Vec3 n_pick = vec3(0.0f);  // a medium point receives from every direction
    if (nee_weight > 0.0f)
        pt_medium_nee(s, ps, i, p, d, m, beta * nee_weight, false, rng);
    else  // equiangular sampling's alone (pt_equiangular_setup): its numbers skipped
        pt_medium_nee_skip(rng);
    // the phase function's own sample: its weight phase / pdf is 1
    float pdf_w = 0.0f;
    const Vec3 wi = hg_sample(m.g, d, rng.uniform2(), &pdf_w);
    Vec3 b = beta;
    if (!(pdf_w > 0.0f) || !russian_roulette(b, depth, st.rr_depth, rng) ||
        !(max_component(b) > 0.0f) || !is_finite(b))
        return;
    ps.throughput[i] = b;
    ps.depth[i] = depth + 1;
    // light linking: emission the phase sample's ray finds counts as the medium's set receives
    if (s.light_receivers && ps.recv_set) ps.recv_set[i] = uint8_t(pt_medium_receiver(s, ps, i));
    ps.ray_o[i] = p;
    ps.ray_d[i] = wi;
    ps.ray_tmin[i] = 0.0f;
    ps.ray_tmax[i] = kInf;
    ps.prev_pdf_w[i] = pdf_w;
    ps.alive[i] = 1;
    if (ps.world_hidden)  // the world seen from a medium vertex: World > Ray Visibility > Volume
        ps.world_hidden[i] = (s.world_rays & kWorldVolume) ? 0 : 1;
    pt_set_ray_kind(s, ps, i, kRayKindVolume);
    if (s.light_tree_on || s.num_media > 0) {  // (media: pt_light_pdf_w)
        ps.prev_p[i] = p;
        ps.prev_n[i] = n_pick;
    }
}

}  // namespace lantern

#include "integrator/pt_volume_hetero.h"  // heterogeneous media: uses pt_medium_vertex

namespace lantern {

// Optical depth (extinction x length) under which equiangular sampling towards a point light
// takes a segment's next-event estimation alone (pt_equiangular_setup's *alone).
constexpr float kEquiangularAloneDepth = 1.0f;

// ---- Equiangular sampling's set-up for a segment from o along d over [0, len]: a light
// picked (light tree at o, n = 0) and a point on it drawn for the whole segment, independent
// of the distances then sampled; none (ok false) for distant lights or no light.
// *alone: the segment's next-event estimation is equiangular sampling's alone, without the
// free flight's at the point where it scatters (that one is skipped), when the light picked is a
// point light (its radiance falls as the inverse square that equiangular sampling follows, over
// the whole segment) and the segment is optically thin (extinction x len under
// kEquiangularAloneDepth in every channel of medium m: its transmittance, the one factor that
// the free flight follows and equiangular sampling does not, then varies by less than e along
// it). There the free flight's estimate added no measurable variance reduction (bench/results/
// 2026-12-06-ptfog: 1.000x on the lamp in a shade in fog) for a shadow ray per scattering;
// elsewhere (a spot's cone, area lights, thick media) the two stay, weighted by the power
// heuristic. ----
LANTERN_HD inline Equiangular pt_equiangular_setup(const SceneView& s, Vec3 o, Vec3 d, float len,
                                                   const Medium& m, bool* alone, Rng& rng) {
    const Vec2 u_pick = rng.uniform2();
    const Vec2 u_light = rng.uniform2();
    Equiangular none{};
    none.ok = false;
    const LightPick pick = light_pick(s, o, vec3(0.0f), u_pick.x);
    if (pick.light < 0) return none;
    const Light& l = s.lights[pick.light];
    Vec3 x;
    if (l.type == kLightSpot) {  // its centre, over the part of the segment in its cone
        float a, b;
        if (!spot_cone_interval(l.position, -l.frame.axis(2), l.cos_half_spot, o, d, len, &a, &b))
            return none;
        return equiangular_setup(o, d, a, b, l.position, l.radius);
    } else if (l.type == kLightPoint) {  // its centre, softened by its radius
        *alone = max_component(m.sigma_t) * len < kEquiangularAloneDepth;
        return equiangular_setup(o, d, len, l.position, l.radius);
    } else if (l.type == kLightSun || l.type == kLightWorld) {
        return none;
    } else {
        const LightSample ls = sample_light(s, l, o, u_light,  // (the path's time)
                                            s.motion.num_objects > 0 ? motion_time(rng) : 0.0f);
        if (!ls.valid || !(ls.dist < kInf)) return none;
        x = ls.p_light;
    }
    return equiangular_setup(o, d, len, x);
}

// ---- The traced segment in the slot's medium; true when the path scattered inside it (then
// this stage shaded the medium vertex and the hit is not shaded). Otherwise the throughput
// carries the segment's transmittance and the caller shades the hit or the miss; the lights
// the segment crosses are collected here either way. ----
// Out of line on both: the host's pt_shade stays as small as without media, and the device's
// is compiled by ptxas without it (LANTERN_DEVICE_NOINLINE).
#ifndef __CUDA_ARCH__
__attribute__((noinline))
#endif
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline bool pt_medium_segment(const SceneView& s, const PathState& ps,
                                         const PtSettings& st, int i, bool catcher_camera) {
    const Medium& m = s.media[ps.medium[i]];
    if (m.hetero) return pt_hetero_segment(s, ps, st, i, catcher_camera);
    const Vec3 o = ps.ray_o[i], d = ps.ray_d[i];
    const float tmin = ps.ray_tmin[i];
    // a miss goes on to infinity in the medium, also for a camera ray cut at the clip end
    // (Cycles' shade_volume: the segment of a miss is FLT_MAX): light through world fog beyond
    // the clip end carries nothing (D46: docs/difftest.md)
    const float t_end = ps.hit_prim[i] >= 0 ? ps.hit_t[i] : kInf;
    const float len = t_end - tmin;
    const Vec3 beta = ps.throughput[i];
    ps.vshadow_valid[i] = 0;
    if (m.emits && !catcher_camera) add_radiance(ps, i, beta * medium_emission_integral(m, len));
    Rng rng = ps.rng[i];
    const Vec3 pmf = medium_channel_pmf(beta);
    float u_channel = 0.0f, u_dist = 0.0f;
    if (m.scatters) {
        u_channel = rng.uniform();
        u_dist = rng.uniform();
    }
    const MediumStep step = medium_sample_distance(m, len, pmf, u_channel, u_dist);
    if (!catcher_camera)
        pt_collect_lights_medium(  // the lights the ray meets: within its clip end
            s, ps, i, o, d, tmin, fminf(step.scattered ? tmin + step.t : t_end, ps.ray_tmax[i]),
            m, pmf);
    // next-event estimation along the segment by two strategies for the distance, combined by
    // the power heuristic: the free flight's scattering (below) and equiangular sampling
    // towards a light point chosen for the segment (its own shadow ray, PathState::vshadow_*)
    float nee_weight = 1.0f;
    if (m.scatters && ps.depth[i] < st.max_depth) {
        bool alone = false;
        const Equiangular e = pt_equiangular_setup(s, o + d * tmin, d, len, m, &alone, rng);
        if (e.ok) {
            const float se = equiangular_sample(e, rng.uniform());
            const float pe = equiangular_pdf(e, se);
            if (pe > 0.0f) {
                const Vec3 tr = medium_transmittance(m, se);
                const float pd = pmf.x * m.sigma_t.x * tr.x + pmf.y * m.sigma_t.y * tr.y +
                                 pmf.z * m.sigma_t.z * tr.z;  // medium_distance_pdf(m, pmf, se)
                const Vec3 f =
                    beta * m.sigma_s * tr * ((alone ? 1.0f : power_heuristic(pe, pd)) / pe);
                pt_medium_nee(s, ps, i, o + d * (tmin + se), d, m, f, true, rng);
            }
            if (step.scattered)
                nee_weight = alone ? 0.0f
                                   : power_heuristic(medium_distance_pdf(m, pmf, step.t),
                                                     equiangular_pdf(e, step.t));
        }
    }
    ps.throughput[i] = beta * step.weight;
    if (step.scattered)
        pt_medium_vertex(s, ps, st, i, o + d * (tmin + step.t), d, m, nee_weight, rng);
    ps.rng[i] = rng;
    return step.scattered;
}

// ---- A volume boundary (no surface) at hit tri: the ray goes on beyond it in the medium on the
// other side; not a bounce (depth and the last vertex's MIS data stay) ----
#ifndef __CUDA_ARCH__
__attribute__((noinline))  // out of line on the host: pt_shade stays as small as without media
#endif
LANTERN_HD inline void pt_cross_boundary(const SceneView& s, const PathState& ps, int i,
                                         int tri) {
    const Vec3 d = ps.ray_d[i];
    const Vec2 uv = ps.hit_uv[i];
    Vec3 p, ng;
    bool front;
    if (s.motion.num_objects > 0 && object_motion_of(s.motion, tri)) {
        // a moving volume (pt only: the other integrators hand motion with media to pt): its
        // boundary where it is at the path's time
        const SurfaceHit h = surface_moved_at(s, tri, uv, d, motion_time(ps.rng[i]));
        p = h.p;
        ng = h.ng;
        front = h.front;
    } else {
        const Vec3 a = triangle_vertex(s, tri, 0), b = triangle_vertex(s, tri, 1),
                   c = triangle_vertex(s, tri, 2);
        const Vec3 n = cross(b - a, c - a);
        front = dot(n, d) <= 0.0f;
        ng = normalize(n);
        p = a * (1.0f - uv.x - uv.y) + b * uv.x + c * uv.y;
    }
    ps.medium[i] = medium_across(s, tri, front, ps.medium[i]);
    ps.ray_o[i] = offset_ray_origin(p, ng, d, s.offset_scale);
    ps.ray_tmin[i] = 0.0f;
    const float tmax = ps.ray_tmax[i];
    ps.ray_tmax[i] = tmax < kInf ? fmaxf(tmax - ps.hit_t[i], 0.0f) : kInf;
    ps.alive[i] = 1;
}

// ---- Shadow ray through media: the transmittance of every medium it crosses (zero when it is
// blocked by any surface but a volume boundary), from o along d up to tmax, starting in medium
// med. Rays is the executor's ray query (closest(r, kind), occluded_collect), kind its shadow
// rays' RayKind.
// A heterogeneous medium's transmittance is estimated by ratio tracking, with numbers from
// path_rng's tracking block `slot` (medium_tracking_rng; a fixed stream without path_rng).
// time: the path's shutter time (motion blur: what moves is where it is then, a moving
// homogeneous volume's boundary too). ----

// The medium a shadow ray (kShadow) is in where its path's medium is med: a volume whose mesh
// casts no shadow is skipped, from inside as well as crossing it (Cycles 97dbe6f,
// volume_shader_eval_entry: such a volume stays in the shadow ray's volume stack but is not
// evaluated; the shadow query does not see its boundary). Medium::shadow_as: the enclosing one.
LANTERN_HD inline int32_t shadow_medium(const SceneView& s, int32_t med) {
    return med >= 0 && s.no_shadow_objects ? s.media[med].shadow_as : med;
}

// The transmittance of medium med (-1: none) over [0, t] of the ray from o along d.
LANTERN_HD inline Vec3 pt_shadow_segment(const SceneView& s, int32_t med, Vec3 o, Vec3 d, float t,
                                         float time, Rng& track) {
    if (med < 0) return vec3(1.0f);
    const Medium& m = s.media[med];
    if (!m.hetero) return medium_transmittance(m, t);
    Vec3 fo = o, fd = d;  // (a moving volume's density in its exported frame: motion.h)
#ifndef __CUDA_ARCH__  // (motion blur renders on the CPU only, session.cpp)
    if (s.motion.medium_objects) medium_ray_exported(s.motion, med, time, &fo, &fd);
#endif
    return medium_ratio_tracking(s, m, med, fo, fd, t, track);
}

// Boundary triangle prim hit at uv by a ray along d: its geometric normal and whether the ray
// meets its front.
LANTERN_HD inline void pt_boundary_side(const SceneView& s, int32_t prim, Vec2 uv, Vec3 d,
                                        float time, Vec3* ng, bool* front) {
    if (s.motion.num_objects > 0 && object_motion_of(s.motion, int(prim))) {
        const SurfaceHit x = surface_moved_at(s, int(prim), uv, d, time);  // (moving)
        *ng = x.ng;
        *front = x.front;
    } else {
        const Vec3 n = triangle_cross(s, prim);
        *front = dot(n, d) <= 0.0f;
        *ng = normalize(n);
    }
}

// Closest hits among the shadow casters, re-traced from past each volume boundary: what every
// shadow ray through media took before occluded_collect, and still takes where that gives no
// answer (more crossings than it holds, two-level structures, boundaries closer together than
// pt_shadow_crossings trusts) and for lt's camera connections (kind kCamera).
// blockers: a shadow-linked light's blocker sets (pt_light_linking.h): a surface or boundary of
// a set outside it is passed as if it were not there, the medium unchanged (Cycles skips such
// an object in its shadow rays' queries, so its volume stack never sees it either).
template <class Rays, class Kind>
LANTERN_HD inline Vec3 pt_shadow_loop(const SceneView& s, const Rays& rays, Kind kind, Vec3 o,
                                      Vec3 d, float tmax, int32_t med, Rng track, float time,
                                      uint64_t blockers = kAllReceivers,
                                      bool* passed_surface = nullptr) {
    Vec3 tr = vec3(1.0f);
    float t0 = 0.0f;  // past a passed strand: the query goes on from o beyond its entry
    for (int k = 0; k < 256; ++k) {  // boundaries crossed (a bound: never an endless loop)
        const auto h = rays.closest(Ray{o, d, t0, tmax, time}, kind);
        const bool hit = h.prim >= 0 && h.t < tmax;
        const int32_t sm = kind == Kind::kShadow ? shadow_medium(s, med) : med;
        tr = tr * (t0 > 0.0f ? pt_shadow_segment(s, sm, o + d * t0, d, (hit ? h.t : tmax) - t0,
                                                 time, track)
                             : pt_shadow_segment(s, sm, o, d, hit ? h.t : tmax, time, track));
        if (!hit) return tr;
        const bool passed = !pt_casts_shadow(s, blockers, h.prim);  // (pt_light_linking.h)
        const bool boundary = (s.tri_flags[h.prim] & kVolumeBoundary) != 0;
        if ((!passed && !boundary) || is_black(tr)) return vec3(0.0f);
        if (passed_surface && !boundary) *passed_surface = true;  // (pt_linked_mis_fog)
        if (h.prim >= s.num_triangles) {  // a strand passed (pt_shadow_linked_query's rule)
            t0 = h.t + 1e-5f * fmaxf(h.t, s.offset_scale);
            continue;
        }
        t0 = 0.0f;
        Vec3 ng;
        bool front;
        pt_boundary_side(s, h.prim, h.uv, d, time, &ng, &front);
        if (!passed) med = medium_across(s, h.prim, front, med);
        const Vec3 p = o + d * h.t;
        const Vec3 next = offset_ray_origin(p, ng, d, s.offset_scale);
        if (tmax < kInf) tmax = fmaxf(tmax - dot(next - o, d), 0.0f);
        o = next;
    }
    return vec3(0.0f);
}

// The transmittance of an unblocked shadow ray from the boundary crossings one query gathered
// (x, unordered): sorted by distance, the media between them as pt_shadow_loop takes them
// (its segments from the crossings themselves instead of re-offset origins: the same up to the
// offset's few ulps). False (nothing computed): two crossings closer together than a few
// hundred times the origin offset (coplanar or touching boundaries, a ray through a shared
// edge), where the loop's re-offset origin steps over the second: the caller takes the loop.
LANTERN_HD inline bool pt_shadow_crossings(const SceneView& s, BoundaryHits& x, Vec3 o, Vec3 d,
                                           float tmax, int32_t med, Rng track, float time,
                                           Vec3* out) {
    int n = 0;
    for (int k = 0; k < x.n; ++k) {  // insertion sort by t, crossings at or past tmax dropped
        if (!(x.t[k] < tmax)) continue;
        const float t = x.t[k];
        const int32_t prim = x.prim[k];
        const Vec2 uv = x.uv[k];
        int j = n++;
        for (; j > 0 && x.t[j - 1] > t; --j) {
            x.t[j] = x.t[j - 1];
            x.prim[j] = x.prim[j - 1];
            x.uv[j] = x.uv[j - 1];
        }
        x.t[j] = t;
        x.prim[j] = prim;
        x.uv[j] = uv;
    }
    for (int k = 1; k < n; ++k) {
        const Vec3 p = o + d * x.t[k];
        const float near = fmaxf(fmaxf(fabsf(p.x), fmaxf(fabsf(p.y), fabsf(p.z))),
                                 s.offset_scale * (1.0f / 32.0f));
        if (!(x.t[k] - x.t[k - 1] > 2e-3f * near)) return false;
    }
    Vec3 tr = vec3(1.0f);
    float t0 = 0.0f;
    for (int k = 0; k < n; ++k) {
        tr = tr * pt_shadow_segment(s, shadow_medium(s, med), o + d * t0, d, x.t[k] - t0, time,
                                    track);
        if (is_black(tr)) {
            *out = vec3(0.0f);
            return true;
        }
        Vec3 ng;
        bool front;
        pt_boundary_side(s, x.prim[k], x.uv[k], d, time, &ng, &front);
        med = medium_across(s, x.prim[k], front, med);
        t0 = x.t[k];
    }
    *out = tr * pt_shadow_segment(s, shadow_medium(s, med), o + d * t0, d,
                                  tmax < kInf ? tmax - t0 : kInf, time, track);
    return true;
}

// A shadow ray (kShadow): one query that stops at the first caster but a volume boundary and
// gathers the boundaries before it (occluded_collect, accel/boundary_hits.h), where the loop
// took a closest-hit trace per boundary crossed and one to the end or to the blocker.
template <class Rays, class Kind>
LANTERN_HD inline Vec3 pt_shadow_transmittance(const SceneView& s, const Rays& rays, Kind kind,
                                               Vec3 o, Vec3 d, float tmax, int32_t med,
                                               const Rng* path_rng = nullptr,
                                               uint32_t slot = 1, float time = 0.0f,
                                               uint64_t blockers = kAllReceivers,
                                               bool* passed_surface = nullptr) {
    const Rng track = medium_tracking_rng(path_rng ? *path_rng : Rng{}, slot);
    // (a shadow-linked light's blockers: the loop alone passes the surfaces outside them)
    if (kind == Kind::kShadow && blockers == kAllReceivers) {  // (Kind: backend/cpu/embree_accel.h)
        BoundaryHits x;
        const bool blocked = rays.occluded_collect(Ray{o, d, 0.0f, tmax, time}, &x);
        if (x.n >= 0) {
            if (blocked) return vec3(0.0f);
            Vec3 tr;
            if (pt_shadow_crossings(s, x, o, d, tmax, med, track, time, &tr)) return tr;
        }
    }
    return pt_shadow_loop(s, rays, kind, o, d, tmax, med, track, time, blockers, passed_surface);
}

// A shadow ray towards light li (-1: not recorded) through media: pt_shadow_transmittance, for a
// shadow-linked light with its blocker mask (one inlined loop: pt's chunk is near its stack cap,
// and an out-of-line copy's frame added ~560 B to it).
template <class Rays, class Kind>
LANTERN_HD inline Vec3 pt_shadow_medium_ray(const SceneView& s, const Rays& rays, Kind kind,
                                            Vec3 o, Vec3 d, float tmax, int32_t med,
                                            const Rng* path_rng, uint32_t slot, float time,
                                            int li, bool* passed_surface = nullptr) {
    const uint64_t blockers = pt_shadow_linked(s, li) ? s.light_blockers[li] : kAllReceivers;
    return pt_shadow_transmittance(s, rays, kind, o, d, tmax, med, path_rng, slot, time,
                                   blockers, passed_surface);
}

// The slot's shadow rays in a scene with media: the surface's or medium vertex's, and the
// equiangular one (cleared here once tested).
template <class Rays, class Kind>
LANTERN_HD inline void pt_shadow_medium(const SceneView& s, const Rays& rays, Kind kind,
                                        const PathState& ps, int i) {
    const float time = s.motion.rays_timed() ? motion_time(ps.rng[i]) : 0.0f;  // (the path's)
    const bool linked = s.light_blockers && ps.shadow_light;  // (vshadow_light with it)
    if (ps.shadow_valid[i]) {
        bool passed = false;  // a surface outside the light's blockers (pt_linked_mis_fog)
        const Vec3 tr = pt_shadow_medium_ray(s, rays, kind, ps.shadow_o[i], ps.shadow_d[i],
                                             ps.shadow_tmax[i], ps.shadow_medium[i], &ps.rng[i],
                                             1u, time, linked ? ps.shadow_light[i] : -1, &passed);
        // a surface's next event of a shadow-linked light with MIS: its weight kept for a
        // segment free of surfaces (a medium vertex's -1: weight 1, in the contribution)
        const float w = !passed && ps.shadow_mis && ps.shadow_mis[i] >= 0.0f ? ps.shadow_mis[i]
                                                                            : 1.0f;
        if (!is_black(tr)) add_radiance(ps, i, ps.shadow_contrib[i] * (tr * w));
    }
    if (ps.vshadow_valid[i]) {
        const Vec3 tr = pt_shadow_medium_ray(s, rays, kind, ps.vshadow_o[i], ps.vshadow_d[i],
                                             ps.vshadow_tmax[i], ps.vshadow_medium[i],
                                             &ps.rng[i], 2u, time,
                                             linked ? ps.vshadow_light[i] : -1);
        if (!is_black(tr)) add_radiance(ps, i, ps.vshadow_contrib[i] * tr);
        ps.vshadow_valid[i] = 0;
    }
}

}  // namespace lantern
