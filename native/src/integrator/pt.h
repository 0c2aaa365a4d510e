// The path tracer's stages (integrator "pt"): unidirectional paths with next-event estimation,
// combined by the power heuristic. Each stage is one host+device function over one path slot;
// the backend launches them over queues and traces the rays they leave in the slots.
#pragma once

#include "bsdf/material.h"
#include "core/offset.h"
#include "integrator/camera.h"
#include "integrator/nee_resample.h"
#include "integrator/path_state.h"
#include "integrator/pt_features.h"
#include "integrator/pt_light_linking.h"
#include "integrator/pt_ray_visibility.h"
#include "integrator/terminator.h"
#include "scene/light_tree.h"
#include "scene/lights.h"

namespace lantern {

// A moving camera (motion blur, scene/motion.h): the still camera's ray r carried rigidly to
// where the camera is at the path's time (the same draws, the same clip distances); out of
// line on the host, so that pt_generate's still path stays as it was.
#ifndef __CUDA_ARCH__
__attribute__((noinline))
#endif
LANTERN_HD inline void pt_camera_ray_moved(const SceneView& s, const Rng& rng, Ray& r) {
    Transform still_inv;
    if (!transform_inverse(s.camera.to_world, &still_inv)) return;
    const Transform m = transform_mul(
        motion_at(s.motion.steps, s.motion.camera_first, s.motion.camera_steps,
                  motion_time(rng)),
        still_inv);
    r.o = m.point(r.o);
    r.d = normalize(m.vector(r.d));
}

// ---- Generate: slot i starts path `path` of the iteration, in pixel path / spp_per_iteration ----
// (F: the features the scene may use, pt_features.h; so for every stage below)
template <uint32_t F = kPtAll>
LANTERN_HD inline void pt_generate(const SceneView& s, const PathState& ps, const PtSettings& st,
                                   int i, int64_t path) {
    Rng rng = Rng::for_camera(st.seed, st.iteration, st.spp_per_iteration, path);
    Ray r = generate_camera_ray(s.camera, int(path / st.spp_per_iteration), rng);
    if ((F & kPtMotion) && s.motion.camera_steps > 1) pt_camera_ray_moved(s, rng, r);  // blur
    ps.ray_o[i] = r.o;
    ps.ray_d[i] = r.d;
    ps.ray_tmin[i] = r.tmin;
    ps.ray_tmax[i] = r.tmax;
    ps.throughput[i] = vec3(1.0f);
    ps.radiance[i] = vec3(0.0f);
    ps.rng[i] = rng;
    ps.depth[i] = 1;
    ps.prev_pdf_w[i] = 0.0f;
    ps.alive[i] = 1;
    ps.dropped[i] = 0;
    ps.shadow_valid[i] = 0;
    if (ps.world_hidden) ps.world_hidden[i] = 0;
    if (ps.recv_set) ps.recv_set[i] = 0;  // light linking: no value of the slot's last path
    if (s.num_media > 0) {
        ps.medium[i] = s.camera_medium;
        if (ps.vshadow_valid) ps.vshadow_valid[i] = 0;
    }
}

// Whether a ray scattered by material m towards wi (ng: the geometric normal facing the
// arriving ray) sees the world (SceneView::world_rays), as Cycles decides: through the surface
// a transmission; a reflection off the diffuse materials (Diffuse BSDF: Lambert, Oren-Nayar)
// diffuse, off conductors and glass glossy; off Principled and mixes (lobes of both kinds)
// visible when either kind is (addon/export/world.py names that case).
LANTERN_HD inline bool pt_world_sees(const SceneView& s, const Material& m, Vec3 wi, Vec3 ng) {
    const uint32_t r = s.world_rays;
    if (dot(wi, ng) < 0.0f) return (r & kWorldTransmission) != 0;
    switch (m.type) {
    case kMaterialConductor:
    case kMaterialHair:  // Cycles labels hair reflection glossy
    case kMaterialDielectric: return (r & kWorldGlossy) != 0;
    case kMaterialPrincipled:
    case kMaterialMix: return (r & (kWorldDiffuse | kWorldGlossy)) != 0;
    default: return (r & kWorldDiffuse) != 0;
    }
}

// MIS weight of emission from light li found by a BSDF-sampled ray (depth > 1), light_pdf_w the
// light's own solid-angle pdf; next-event estimation picked it at the previous vertex with
// light_pick_pmf. Camera rays and rays from a delta lobe (prev_pdf_w 0: next-event estimation
// cannot find that light) take it all.
template <uint32_t F = kPtAll>
LANTERN_HD inline float pt_emission_weight(const SceneView& s, const PathState& ps, int i, int li,
                                           float light_pdf_w) {
    // light linking: no light from a light that does not light the vertex the ray left
    if ((F & kPtLinks) && s.light_receivers && !pt_emission_linked(s, ps, i, li)) return 0.0f;
    if (ps.depth[i] <= 1 || !(ps.prev_pdf_w[i] > 0.0f)) return 1.0f;
    if ((F & kPtLinks) && s.light_blockers && pt_shadow_linked(s, li) &&
        !pt_linked_bounce(s, ps, i))
        return 0.0f;  // shadow linking without MIS: next-event only (pt_light_linking.h)
    const float pick = s.light_tree_on ? light_pick_pmf(s, li, ps.prev_p[i], ps.prev_n[i])
                                       : s.lights[li].nee_pdf;
    return power_heuristic(ps.prev_pdf_w[i], pick * light_pdf_w);
}

// The solid-angle pdf next-event estimation has for the light point at distance t along d from
// o, as pt_emission_weight needs it. In a scene with media a ray that crossed volume boundaries
// since its last vertex starts beyond them: the pdf is the last vertex's (PathState::prev_p,
// kept in scenes with media), at its own distance. (Soft-falloff disks: by solid
// angle, as every integrator's next-event estimation samples them.) time: a moving emitter's
// shutter time where the caller has its own (bdpt's path time); negative: pt's, from the rng.
LANTERN_HD inline float pt_light_pdf_w(const SceneView& s, const PathState& ps, int i,
                                       const Light& l, Vec3 o, Vec3 d, float t, Vec3 n,
                                       float time = -1.0f) {
    if ((s.num_media > 0 || s.tri_rays) && ps.depth[i] > 1) {  // (tri_rays: pt_pass_hidden)
        const Vec3 q = ps.prev_p[i];
        t = length(o + d * t - q);
        o = q;
    }
    if (l.type == kLightTriangle && s.motion.num_objects > 0)  // a moving emitter: at the path's
        return light_pdf_w_at(s, l, o, d, t, n,  // time (its area then)
                              time < 0.0f ? motion_time(ps.rng[i]) : time);
    return light_pdf_w(l, o, d, t, n);
}

// ---- Lights along the segment: lights are not opaque; a ray collects every light it crosses ----
template <uint32_t F = kPtAll>
LANTERN_HD inline void pt_collect_lights(const SceneView& s, const PathState& ps, int i, Vec3 o,
                                         Vec3 d, float tmin, float tmax) {
    bool camera = ps.depth[i] <= 1;
    for (int k = 0; k < s.num_hittable_lights; ++k) {
        const Light& l = s.lights[s.hittable_lights[k]];
        if (camera && !l.visible_camera) continue;
        if ((F & kPtLinks) && pt_lamp_unseen(s, ps, i, s.hittable_lights[k]))
            continue;  // its ray visibility
        LightHit h = intersect_light(l, o, d, tmin, tmax);
        if (!h.hit || is_black(h.le)) continue;
        float pdf = pt_light_pdf_w(s, ps, i, l, o, d, h.t, h.n);
        add_radiance(ps, i, ps.throughput[i] * h.le *
                                pt_emission_weight<F>(s, ps, i, s.hittable_lights[k], pdf));
    }
}

}  // namespace lantern

#include "integrator/pt_volume.h"  // media: uses pt_emission_weight

namespace lantern {

// ---- Miss: world background and the sun's disk ----
template <uint32_t F = kPtAll>
LANTERN_HD inline void pt_shade_miss(const SceneView& s, const PathState& ps, int i, Vec3 d) {
    bool camera = ps.depth[i] <= 1;
    for (int k = 0; k < s.num_miss_lights; ++k) {
        const Light& l = s.lights[s.miss_lights[k]];
        if (l.type == kLightWorld) {
            if (camera && !l.visible_camera) continue;
            if (!camera && ps.world_hidden && ps.world_hidden[i]) continue;  // world_rays
            float pdf = world_pdf_w(s, d);
            add_radiance(ps, i, ps.throughput[i] * world_radiance(s, l, d) *
                                    pt_emission_weight<F>(s, ps, i, s.miss_lights[k], pdf));
        } else if (l.type == kLightSun && l.cos_sun < 1.0f) {
            // a sun lamp is hidden from the camera (as in Cycles); the world's disc is not
            if (camera ? !l.visible_camera
                       : (l.of_world && ps.world_hidden && ps.world_hidden[i]))
                continue;
            if ((F & kPtLinks) && pt_lamp_unseen(s, ps, i, s.miss_lights[k]))
                continue;  // its ray visibility
            if (dot(d, -l.direction) < l.cos_sun) continue;
            float pdf = light_pdf_w(l, vec3(0.0f), d, kInf, vec3(0.0f));
            add_radiance(ps, i, ps.throughput[i] * l.radiance *
                                    pt_emission_weight<F>(s, ps, i, s.miss_lights[k], pdf));
        }
    }
}

}  // namespace lantern

#include "integrator/pt_surface.h"
#include "integrator/pt_curve.h"  // strands: pt_surface_at

namespace lantern {

// ---- Shadow catchers (SceneView::catcher_mode; lantern/film.py combines the three renders) ----
// True when the path ends or passes through at hit tri: a camera ray reaching a catcher in the
// matte, or anything else in the other two modes; in kCatcherPass later rays go through every
// surface that is not a catcher (the ray continues from the hit, a segment more).
LANTERN_HD inline bool pt_catcher_skips(const SceneView& s, const PathState& ps, int i, int tri) {
    const bool catcher = (s.tri_flags[tri] & kShadowCatcher) != 0;
    if (ps.depth[i] <= 1) return s.catcher_mode == kCatcherMatte ? catcher : !catcher;
    if (s.catcher_mode != kCatcherPass || catcher) return false;
    const Vec3 d = ps.ray_d[i];
    const SurfaceHit h = pt_surface_at(s, ps, i, tri, d);
    ps.ray_o[i] = offset_ray_origin(h.p, h.ng, d, s.offset_scale);
    ps.ray_tmin[i] = 0.0f;
    ps.ray_tmax[i] = kInf;
    ps.depth[i] += 1;  // prev_pdf_w, prev_p and prev_n stay those of the last real vertex
    ps.alive[i] = 1;
    return true;
}

// A bounce ray passing a surface hidden from its kind (pt_ray_visibility.h) goes on from the
// hit; out of line on the host, so that pt_shade's usual path stays as it was.
#ifndef __CUDA_ARCH__
__attribute__((noinline))
#endif
LANTERN_HD inline void pt_pass_hidden_at(const SceneView& s, const PathState& ps, int i, int tri) {
    if (tri >= s.num_triangles) return pt_pass_hidden_strand(s, ps, i);  // (a strand)
    const Vec3 d = ps.ray_d[i];
    const SurfaceHit h = pt_surface_at(s, ps, i, tri, d);
    pt_pass_hidden(s, ps, i, h.p, h.ng);
}

// pt_shade's ray visibility and light linking, out of line on the host (the usual path tests
// one flag): which leaves of material m next-event estimation of light li towards wi may light
// on surface tri (pt_nee_leaves: 0 none, kNeeAllLit all), and the kind and receiver set of the
// bounce ray leaving it towards wi (the kind of the sampled leaf: pt_sampled_leaf).
#ifndef __CUDA_ARCH__
__attribute__((noinline))
#endif
LANTERN_HD inline uint32_t pt_nee_allowed(const SceneView& s, const Material& m, int tri,
                                          Vec3 ng, int li, Vec3 wi) {
    if (!pt_light_links(s, li, pt_receiver_set(s, tri))) return 0u;
    return (s.tri_rays || s.light_rays) ? pt_nee_leaves(s, li, m, wi, ng) : kNeeAllLit;
}
#ifndef __CUDA_ARCH__
__attribute__((noinline))
#endif
LANTERN_HD inline void pt_mark_next_ray(const SceneView& s, const PathState& ps, int i,
                                        const Material& m, Vec3 wi, Vec3 ng, int tri) {
    pt_set_ray_kind(s, ps, i, pt_path_kind(m, wi, ng));
    pt_set_receiver(s, ps, i, tri);
}


// material_eval and material_sample for pt_shade, out of line on the device: inlined there
// (nee_resample's target is), the lobes' local arrays joined the shade kernel's own local
// memory, which every call below it adds to. The host calls them as before.
#ifdef __CUDA_ARCH__
__noinline__
#endif
// ng_l: the geometric normal in the shading frame (view-corrected glossy materials read it)
LANTERN_HD inline BsdfEval pt_eval(const Material& m, bool front, Vec3 wo, Vec3 wi, Vec3 coat_n,
                                   Vec3 ng_l) {
    return material_eval(m, front, wo, wi, Transport::Radiance, coat_n, ng_l);
}
#ifdef __CUDA_ARCH__
__noinline__
#endif
LANTERN_HD inline BsdfSample pt_sample(const Material& m, bool front, Vec3 wo, Vec3 u,
                                       Vec3 coat_n, Vec3 ng_l) {
    return material_sample(m, front, wo, u, Transport::Radiance, coat_n, ng_l);
}

}  // namespace lantern

#include "integrator/pt_sss.h"  // subsurface: uses pt_surface, shade_point

namespace lantern {

// ---- Shade: emission, next-event estimation (a shadow ray), BSDF sampling, roulette ----
template <uint32_t F = kPtAll>
LANTERN_HD inline void pt_shade(const SceneView& s, const PathState& ps, const PtSettings& st,
                                int i) {
    Vec3 o = ps.ray_o[i], d = ps.ray_d[i];
    float t_hit = ps.hit_t[i];
    int tri = ps.hit_prim[i];
    ps.shadow_valid[i] = 0;
    ps.alive[i] = 0;
    // ray visibility, light or shadow linking in the scene (pt_ray_visibility.h,
    // pt_light_linking.h): read once, so that a scene without them tests one register
    const bool extras =
        (F & kPtLinks) && (s.tri_rays || s.light_rays || s.light_receivers || s.light_blockers);
    // the catcher renders (kCatcherObject, kCatcherPass) keep only camera rays reaching one
    const bool catcher_camera = s.catcher_mode != kCatcherMatte && ps.depth[i] <= 1;
    // in a medium: its segment (emission, lights crossed, a scattering inside: pt_volume.h)
    const bool in_medium = s.num_media > 0 && ps.medium[i] >= 0;
    if (in_medium && pt_medium_segment(s, ps, st, i, catcher_camera)) return;
    if (!catcher_camera && !in_medium)
        pt_collect_lights<F>(s, ps, i, o, d, ps.ray_tmin[i], tri >= 0 ? t_hit : ps.ray_tmax[i]);
    if (tri < 0) {  // past the far clip plane too: the background shows, as in Cycles
        if (!catcher_camera) pt_shade_miss<F>(s, ps, i, d);
        return;
    }
    if (s.num_media > 0 && (s.tri_flags[tri] & kVolumeBoundary)) {  // no surface: go on
        pt_cross_boundary(s, ps, i, tri);
        return;
    }
    if (extras && pt_hidden_from_ray(s, ps, i, tri)) {  // ray visibility: go on
        pt_pass_hidden_at(s, ps, i, tri);
        return;
    }
    // a holdout seen by the camera: no colour (its alpha 0 is lantern/film.py's coverage)
    if (ps.depth[i] <= 1 && (s.tri_flags[tri] & kHoldout)) return;
    if ((s.catcher_mode != kCatcherMatte || (s.tri_flags[tri] & kShadowCatcher)) &&
        pt_catcher_skips(s, ps, i, tri))
        return;
    SurfaceHit h = pt_surface_at<F>(s, ps, i, tri, d);  // a triangle's or a strand's (pt_curve.h)
    MaterialScratch scratch;
    const Material& m = material_at_point(
        s, s.tri_material[tri],
        // by value: what it captures by reference the device keeps in local memory throughout
        // (a strand's point has no triangle: tri -1 for the programs)
        [h, tri = tri < s.num_triangles ? tri : -1, uv = ps.hit_uv[i], wo = -d] {
            return shade_point(h, tri, uv, wo);
        },
        scratch);
    if (!is_black(m.emission)) {
        float w = 1.0f;
        int li = s.tri_light ? s.tri_light[tri] : -1;
        if (li >= 0) {
            const Light& l = s.lights[li];
            w = pt_emission_weight<F>(s, ps, i, li,
                                      pt_light_pdf_w(s, ps, i, l, o, d, t_hit, h.ng));
        }
        // the camera's direct view of a Principled emitter: under its coat and sheen
        // (principled_emission_through; light it casts stays undimmed)
        const Vec3 le = ps.depth[i] <= 1 ? m.emission * principled_emission_through(m, dot(d, h.ng))
                                         : m.emission;
        add_radiance(ps, i, ps.throughput[i] * le * w);
    }
    // a surface vertex: its bounce ray may take the MIS weight of a shadow-linked light in
    // fog (pt_linked_bounce; a medium vertex writes -1)
    if (extras && ps.shadow_mis) ps.shadow_mis[i] = 1.0f;
    int depth = ps.depth[i];
    if (depth >= st.max_depth) return;

    Frame frame = h.frame();
    Vec3 wo = frame.to_local(-d);
    const Vec3 ng_l = frame.to_local(h.ng);
    Rng rng = ps.rng[i];
    // under the surface: the walk stage takes the path (integrator/pt_sss.h)
    if ((F & kPtSubsurface) && s.has_subsurface && m.subsurface > 0.0f && tri < s.num_triangles &&
        pt_sss_choose(ps, i, m, wo, ng_l, rng)) {
        ps.rng[i] = rng;
        return;
    }

    // next-event estimation
    const bool delta_material = material_is_delta(m);
    Vec2 u_pick = rng.uniform2();
    Vec2 u_light = rng.uniform2();
    // a smooth mesh's terminator takes light from under its face too, and so does a lamp
    // without shadows (below; s.light_rays: a scene with such lamps may have one): no side to
    // cull by
    const Vec3 n_pick = (terminator_cutoff(s, tri) > 0.0f || (extras && s.light_rays)) &&
                                dot(h.ns, h.ng) < 0.99999f
                            ? vec3(0.0f)
                            : light_pick_normal(s, tri, h.ng);
    LightPick pick{-1, 0.0f};
    LightSample ls{};
    // the path's shutter time: a moving emitter is sampled where it is then
    const float time = s.motion.num_objects > 0 ? motion_time(rng) : 0.0f;
    float ris = 1.0f;  // resampled (light_candidates M > 1): W p_src(y), nee_resample.h
    if (st.light_candidates > 1) {
        const int mc = min_int(st.light_candidates, kMaxLightCandidates);
        const Rng rest = rng;  // candidates 2..M's numbers, drawn inside nee_resample
        nee_resample_skip(rng, nee_resample_extra_draws(mc));
        // luminance of the unshadowed contribution
        auto target = [&](const LightSample& c) LANTERN_DEVICE_INLINE {
            if (!(light_side_agrees(m, c.wi, h.ng, h.ns) ||
                  terminator_passes(s, tri, c.wi, h.ng, h.ns) ||
                  (extras && s.light_rays && !sides_agree(c.wi, h.ng, h.ns))) ||
                is_black(c.le))
                return 0.0f;
            BsdfEval e = pt_eval(m, h.front, wo, frame.to_local(c.wi), h.coat_n, ng_l);
            return luminance(e.f * c.le) * fabsf(dot(c.wi, h.ns));
        };
        if (!delta_material)
            ris = nee_resample(s, h.p, n_pick, mc, Vec3{u_pick.x, u_light.x, u_light.y},
                               rest, u_pick.y, target, &pick, &ls, time);
    } else if (!delta_material) {
        pick = light_pick(s, h.p, n_pick, u_pick.x);
        if (pick.pmf > 0.0f) ls = sample_light(s, s.lights[pick.light], h.p, u_light, time);
    }
    if (pick.pmf > 0.0f && (pick.light == s.world_light || s.lights[pick.light].of_world) &&
        s.world_rays != kWorldRaysAll && !pt_world_sees(s, m, ls.wi, h.ng))
        ls.valid = false;  // the world hidden from this kind of scattering lights nothing here
    uint32_t lit = kNeeAllLit;  // ray visibility: the leaves lit (pt_nee_leaves)
    if (extras && pick.pmf > 0.0f && ls.valid) {  // ray visibility, light linking
        lit = pt_nee_allowed(s, m, tri, h.ng, pick.light, ls.wi);
        ls.valid = lit != 0u;
    }
    if (pick.pmf > 0.0f) {
        // geo_side false: a smooth mesh's light from under its face (integrator/terminator.h),
        // which BSDF sampling never takes: next-event estimation's alone. A lamp without
        // shadows lights it at any offset (D47): Cycles' BSDFs read the shading normal alone
        // and no shadow ray meets the mesh; its BSDF sampling drops those directions too
        // (bsdf_diffuse_sample: below Ng) but its next-event estimation keeps the usual MIS
        // weight there, and so does this one (its sum is Cycles' image, pt_lamp_unshadowed)
        const bool unshadowed = extras && pt_lamp_unshadowed(s, pick.light);
        const bool geo_side = light_side_agrees(m, ls.wi, h.ng, h.ns);
        if (ls.valid && !delta_material &&
            (geo_side || terminator_passes(s, tri, ls.wi, h.ng, h.ns) ||
             (unshadowed && !sides_agree(ls.wi, h.ng, h.ns))) &&
            !is_black(ls.le)) {
            BsdfEval e = pt_eval(m, h.front, wo, frame.to_local(ls.wi), h.coat_n, ng_l);
            if (lit != kNeeAllLit)  // the whole mixture's pdf, the lit leaves' value
                e.f = pt_eval_lit(m, h.front, wo, frame.to_local(ls.wi), h.coat_n, lit);
            float pdf_light = pick.pmf * ls.pdf_w;
            if (e.pdf_fwd_w > 0.0f && pdf_light > 0.0f) {
                // shadow linking (pt_light_linking.h): weight 1 here, the MIS weight kept for
                // the shadow ray's answer (pt_linked_mis), or next-event estimation alone
                const bool linked = extras && pt_shadow_linked(s, pick.light);
                float w = ls.delta || (!geo_side && !unshadowed) || linked
                              ? 1.0f
                              : power_heuristic(pdf_light, e.pdf_fwd_w);
                float cos_i = fabsf(dot(ls.wi, h.ns));
                Vec3 c = ps.throughput[i] * e.f * ls.le * (cos_i * w * ris / pdf_light);
                // Shortened at both ends: from the offset origin to the offset point on the
                // light, aimed between the two offset points (aiming along wi from the un-offset
                // point ends behind a light seen at a grazing angle, and the ray hits the light).
                Vec3 so = offset_ray_origin(terminator_origin(s, tri, h.p, h.ng, h.ns, ls.wi, time),
                                            h.ng, ls.wi, s.offset_scale);
                Vec3 sd = ls.wi;
                float tmax = kInf;
                if (ls.dist < kInf) {
                    Vec3 target = ls.p_light;
                    if (!is_black(ls.n_light)) target = offset_ray_origin(target, ls.n_light, -ls.wi, s.offset_scale);
                    Vec3 seg = target - so;
                    float len = length(seg);
                    if (len > 0.0f) sd = seg / len;
                    tmax = len * (1.0f - 1e-4f);
                }
                ps.shadow_o[i] = so;
                ps.shadow_d[i] = sd;
                ps.shadow_tmax[i] = tmax;
                ps.shadow_contrib[i] = c;
                ps.shadow_valid[i] = 1;
                if (extras && s.light_blockers && ps.shadow_light) {
                    ps.shadow_light[i] = pick.light;
                    pt_keep_shadow_mis(ps, i,
                                       linked && !ls.delta && geo_side && pt_linked_mis_pt(s)
                                           ? power_heuristic(pdf_light, e.pdf_fwd_w)
                                           : 1.0f);
                }
                if (s.num_media > 0)  // through the surface: the medium beyond it
                    ps.shadow_medium[i] = dot(ls.wi, geo_side ? h.ng : h.ns) < 0.0f
                                              ? medium_across(s, tri, h.front, ps.medium[i])
                                              : ps.medium[i];
                if (unshadowed) {  // Cast Shadow off: no ray
                    add_radiance(ps, i, c);
                    ps.shadow_valid[i] = 0;
                }
            }
        }
    }

    // continue the path
    Vec2 u_dir = rng.uniform2();
    BsdfSample bs = pt_sample(m, h.front, wo, Vec3{u_dir.x, u_dir.y, rng.uniform()}, h.coat_n,
                              ng_l);
    Vec3 wi = frame.to_world(bs.wi);
    if (bs.valid && light_side_agrees(m, wi, h.ng, h.ns)) {
        Vec3 beta = ps.throughput[i] * bs.weight;
        if (russian_roulette(beta, depth, st.rr_depth, rng) && max_component(beta) > 0.0f &&
            is_finite(beta)) {
            ps.throughput[i] = beta;
            ps.depth[i] = depth + 1;
            if (s.world_rays != kWorldRaysAll && ps.world_hidden)
                ps.world_hidden[i] = pt_world_sees(s, m, wi, h.ng) ? 0 : 1;
            if (extras) pt_mark_next_ray(s, ps, i, pt_sampled_leaf(m, bs.lobe), wi, h.ng, tri);
            set_next_ray(ps, i, h.p, h.ng, wi, bs.delta ? 0.0f : bs.pdf_fwd_w,
                         s.offset_scale);
            if (s.num_media > 0 && dot(wi, h.ng) < 0.0f)  // through the surface
                ps.medium[i] = medium_across(s, tri, h.front, ps.medium[i]);
            if (s.light_tree_on || s.num_media > 0 || s.tri_rays) {  // (pt_light_pdf_w)
                ps.prev_p[i] = h.p;
                ps.prev_n[i] = n_pick;
            }
        }
    }
    ps.rng[i] = rng;
}

// ---- Shadow result: the backend reports whether the segment was free ----
LANTERN_HD inline void pt_shadow_result(const PathState& ps, int i, bool occluded) {
    if (!occluded) add_radiance(ps, i, ps.shadow_contrib[i]);
}

}  // namespace lantern
