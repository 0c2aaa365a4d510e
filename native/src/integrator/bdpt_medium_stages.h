// The bidirectional stages in homogeneous media (docs/volumes.md "Medium vertices in the
// bidirectional integrators"; the pieces and the MIS rules: bdpt_medium.h; heterogeneous media:
// bdpt_medium_hetero.h and bdpt_camera_hetero_segment below). Run only where
// SceneView::num_media > 0; the hooks in bdpt_light.h / bdpt_camera.h are one line each.
//
// - Every traced piece (between vertices and volume boundaries) in a medium draws a flight by
//   the throughput-free channel rule; the slot's MediumSegmentPdf (BdptState::seg_*) collects
//   the segment's distance factors; volume boundaries are passed (not vertices).
// - A flight that scatters makes a medium vertex: in the light pass stored in the cache
//   (lv_make_medium) and splatted to the camera; in the camera pass next-event estimation,
//   connections (bdpt, lvc, cis) and the lights crossed before it; both continue with a
//   Henyey-Greenstein sample.
// - Next-event estimation, connections and light tracing splats are queued with the weight
//   their factors 1 would give, and the two parts of its denominator that the segment's end
//   factors multiply (BdptState::shadow_wn / wf, conn_wn / wf); the shadow stage traces the
//   segment (bdpt_medium_shadow) and finishes the weight (bdpt_medium_finish_c) with the
//   transmittance.
#pragma once

#include "integrator/bdpt_curve.h"  // strand vertices (the connection's cosines)
#include "integrator/bdpt_camera_emission.h"  // bidir_rays_nee_ratio (ray kinds)
#include "integrator/bdpt_medium.h"
#include "integrator/bdpt_medium_light.h"  // the light pass
#include "integrator/bdpt_motion.h"        // bdpt_emitter_time
#include "integrator/bidir_linking.h"      // light linking (s = 0)

namespace lantern {

// ---------------------------------------------------------------------------------------------
// Camera pass
// ---------------------------------------------------------------------------------------------

LANTERN_HD inline void bdpt_camera_generate_medium(const PathState& ps, const BdptState& bs,
                                                   int i) {
    ps.prev_p[i] = ps.ray_o[i];
    bdpt_seg_store(bs, i, medium_segment_begin(false));
}

// The weight of light l's emission reached at p_light (normal n; distant lights: kInf) by the
// camera path, seg the segment's factors up to it (bdpt_emission_weight with them).
LANTERN_HD inline float bdpt_emission_weight_medium(const SceneView& s, const PathState& ps,
                                                    const BdptState& bs, const BdptSettings& st,
                                                    int i, const Light& l, Vec3 p_light,
                                                    bool infinite, Vec3 n,
                                                    const MediumSegmentPdf& seg,
                                                    float* nee_ratio = nullptr,
                                                    float soft_emit = -1.0f) {
    if (ps.depth[i] <= 1) return 1.0f;
    if (!(seg.fwd > 0.0f)) return 0.0f;
    const Vec3 d = ps.ray_d[i], prev = ps.prev_p[i];
    float dvcm = bs.dvcm[i], dvc = bs.dvc[i];
    const int li = int(&l - s.lights);
    const float pick = s.light_tree_on ? light_pick_pmf(s, li, prev, ps.prev_n[i]) : l.nee_pdf;
    float pdf_direct;
    if (infinite) {
        pdf_direct = pick * (l.type == kLightWorld ? world_pdf_w(s, d)
                                                   : light_pdf_w(l, prev, d, kInf, n));
        dvcm /= mis(seg.fwd);
        dvc *= mis(seg.rev) / mis(seg.fwd);
    } else {
        const float dist = length(p_light - prev);
        const float cos_l = fabsf(dot(d, n));
        if (!(cos_l > 0.0f) || !(dist > 0.0f)) return 0.0f;
        pdf_direct = pick * light_pdf_w(l, prev, d, dist, n) * cos_l / (dist * dist);
        bdpt_medium_hit_update(dvcm, dvc, dist, cos_l, seg, true);
    }
    const float pdf_emit = soft_emit >= 0.0f
                               ? soft_emit
                               : l.emit_pick_pdf * emission_pdf(s, l, n, -d, 0.0f).pdf_emit;
    if (ps.depth[i] == 2) dvc *= bdpt_direct_lt(st);
    if (nee_ratio) *nee_ratio = mis(pdf_direct) * dvcm;  // next-event estimation's (moments)
    return 1.0f / (1.0f + mis(pdf_direct) * dvcm + mis(st.r * pdf_emit) * dvc);
}

// s = 0 of lamp li (a lamp without shadows) past a non-delta bounce: pt's weight, 1 / (1 +
// (p_nee / p_bsdf)^2), in place of w (bdpt_emission_weight_medium's, nee its next-event
// ratio): that ratio holds the segment's flight factor (dVCM / F_fwd), pt's does not
// (pt_emission_weight: solid angle alone). Otherwise w (bidir_linking.h).
LANTERN_HD inline float bidir_pt_weight_medium(const SceneView& s, const PathState& ps, int i,
                                               int li, const MediumSegmentPdf& seg, float w,
                                               float nee) {
    return w > 0.0f && bidir_pt_weight(s, ps, i, li) ? 1.0f / (1.0f + nee * mis(seg.fwd)) : w;
}

// A camera path from vertex x (the slot's prev_p; a medium vertex where the segment started in
// one, else a surface of normal bs.prev_ng) hits the disk of soft-falloff light l at y0, seg the
// segment's factors up to it: the stand-in for pdf_emit that makes bdpt_emission_weight_medium's
// (which divides by cos_out F_rev / |y0 - x|^2 through dVC) the light path's density of x,
// soft_light_path_pdf_a_medium (bdpt_soft_hit_emit without media).
template <class SR>
LANTERN_HD inline float bdpt_soft_hit_emit_medium(const SceneView& s, const PathState& ps,
                                                  const BdptState& bs, const SR& sr, int i,
                                                  const Light& l, Vec3 y0,
                                                  const MediumSegmentPdf& seg) {
    const Vec3 x = ps.prev_p[i], d = ps.ray_d[i];
    const Vec3 ng = (seg.flags & kSegStartMedium) ? vec3(0.0f) : bs.prev_ng[i];
    const float cos_out = is_black(ng) ? 1.0f : fabsf(dot(d, ng));
    if (!(cos_out > 0.0f) || !(seg.rev > 0.0f)) return 0.0f;
    const float pdf_a = soft_light_path_pdf_a_medium(s, sr, l, x, ng);
    if (!(pdf_a > 0.0f)) return 0.0f;
    const float r = pdf_a * length_sq(y0 - x) / (cos_out * seg.rev);
    return is_finite(r) ? r : 0.0f;
}

// Lights crossed by the piece [tmin, t_stop] in medium m (null: vacuum), each through the
// flight's pass weight up to it; the background on a miss that passed the whole piece.
template <class SR>
LANTERN_HD inline void bdpt_camera_emission_medium(const SceneView& s, const PathState& ps,
                                                   const BdptState& bs, const BdptSettings& st,
                                                   int i, float t_stop, bool miss,
                                                   const Medium* m,
                                                   const MediumSegmentPdf& seg0, Vec3 beta,
                                                   const SR& sr) {
    const Vec3 o = ps.ray_o[i], d = ps.ray_d[i];
    const float tmin = ps.ray_tmin[i];
    const bool camera = ps.depth[i] <= 1;
    for (int k = 0; k < s.num_hittable_lights; ++k) {
        const Light& l = s.lights[s.hittable_lights[k]];
        if (camera && !l.visible_camera) continue;
        if (!bidir_emission_counts(s, ps, i, s.hittable_lights[k])) continue;  // (linking)
        if (pt_lamp_unseen(s, ps, i, s.hittable_lights[k])) continue;  // (ray kinds)
        LightHit h = intersect_light(l, o, d, tmin, t_stop);
        if (!h.hit || is_black(h.le)) continue;
        MediumSegmentPdf seg = seg0;
        medium_segment_piece(seg, m, h.t - tmin, false);
        const Vec3 tr = m ? medium_pass_weight(*m, bdpt_medium_pmf(), h.t - tmin) : vec3(1.0f);
        float nee = 0.0f;
        float soft = -1.0f;  // (a soft-falloff light's stand-in for pdf_emit; r = 0: no ray)
        if (!camera && light_receiver_dependent(l))
            soft = st.r > 0.0f
                       ? bdpt_soft_hit_emit_medium(s, ps, bs, sr, i, l, o + d * h.t, seg)
                       : 0.0f;
        float w = bdpt_emission_weight_medium(s, ps, bs, st, i, l, o + d * h.t, false, h.n, seg,
                                              &nee, soft);
        w = bidir_pt_weight_medium(s, ps, i, s.hittable_lights[k], seg, w, nee);
        if (w > 0.0f && bidir_rays_on(s) && bidir_rays_pt_weight(s, ps, i, s.hittable_lights[k])) {
            w = bidir_rays_emission_weight(s, ps, i, s.hittable_lights[k], o, d, h.t, h.n, 0.0f);
            nee = bidir_rays_nee_ratio(w);  // (ray kinds: pt's weight, bidir_ray_visibility.h)
        }
        Vec3 c = beta * tr * h.le * w;
        if (st.moments) c = bdpt_moment(c, c, bdpt_pt_factor(1.0f / w, 1.0f, nee));
        add_radiance(ps, i, c);
    }
    if (!miss) return;
    MediumSegmentPdf seg = seg0;
    medium_segment_piece(seg, m, kInf, false);
    const Vec3 tr = m ? medium_pass_weight(*m, bdpt_medium_pmf(), kInf) : vec3(1.0f);
    if (is_black(tr)) return;
    for (int k = 0; k < s.num_miss_lights; ++k) {
        const Light& l = s.lights[s.miss_lights[k]];
        if (l.type == kLightSun && (l.cos_sun >= 1.0f || (camera && !l.visible_camera) ||
                                    dot(d, -l.direction) < l.cos_sun))
            continue;
        if (l.type == kLightWorld && camera && !l.visible_camera) continue;
        if (!bidir_emission_counts(s, ps, i, s.miss_lights[k])) continue;  // (linking)
        if (pt_lamp_unseen(s, ps, i, s.miss_lights[k])) continue;  // (ray kinds)
        float nee = 0.0f;
        float w = bdpt_emission_weight_medium(s, ps, bs, st, i, l, vec3(0.0f), true,
                                              vec3(0.0f), seg, &nee);
        w = bidir_pt_weight_medium(s, ps, i, s.miss_lights[k], seg, w, nee);
        if (w > 0.0f && bidir_rays_on(s) && bidir_rays_pt_weight(s, ps, i, s.miss_lights[k])) {
            w = bidir_rays_emission_weight(s, ps, i, s.miss_lights[k], o, d, kInf, vec3(0.0f),
                                           0.0f);
            nee = bidir_rays_nee_ratio(w);
        }
        const Vec3 le = l.type == kLightWorld ? world_radiance(s, l, d) : l.radiance;
        Vec3 c = beta * tr * le * w;
        if (st.moments) c = bdpt_moment(c, c, bdpt_pt_factor(1.0f / w, 1.0f, nee));
        add_radiance(ps, i, c);
    }
}

// s = 1 from a medium vertex: a light from the light tree (omnidirectional receiver), the
// phase function in place of the BSDF, no cosine at z. Out of line on the device
// (LANTERN_DEVICE_NOINLINE): its light sample stays out of the events kernel's own frame.
template <class SR>
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline void bdpt_camera_medium_nee(const SceneView& s, const PathState& ps,
                                              const BdptState& bs, const BdptSettings& st,
                                              const CameraVertex& z, int i, Rng& rng,
                                              const SR& sr, int64_t path) {
    const Vec2 u_pick = rng.uniform2();
    const Vec2 u_light = rng.uniform2();
    const LightPick pick = light_pick(s, z.h.p, vec3(0.0f), u_pick.x);
    if (!(pick.pmf > 0.0f)) return;
    if (!camera_medium_links(s, ps, i, pick.light)) return;  // (bidir_linking_medium.h)
    // ray visibility by kind: nothing from a light hidden from Volume Scatter (pt_medium_nee)
    const bool rays = bidir_rays_on(s);
    if (rays && pt_light_hidden(s, pick.light, kRayKindVolume)) return;
    const Light& l = s.lights[pick.light];
    // a moving emitter where it is at the camera path's time (its shadow ray's time too)
    const float time = bdpt_emitter_time(s, st, path);
    const LightSample ls = sample_light(s, l, z.h.p, u_light, time);
    if (!ls.valid || is_black(ls.le)) return;
    const float ph = hg_phase(s.media[z.medium_vertex].g, dot(-z.wo_w, ls.wi));
    const float pdf_light_w = pick.pmf * ls.pdf_w;
    if (!(ph > 0.0f) || !(pdf_light_w > 0.0f)) return;
    const bool infinite = !(ls.dist < kInf);
    const float cos_l = is_black(ls.n_light) ? 1.0f : fabsf(dot(ls.wi, ls.n_light));
    const float pdf_emit =
        l.emit_pick_pdf * emission_pdf(s, l, ls.n_light, -ls.wi, time).pdf_emit;
    float pdf_nee, pdf_lp;
    if (infinite) {
        pdf_nee = pdf_light_w;
        pdf_lp = pdf_emit;
    } else {
        const float d2 = ls.dist * ls.dist;
        pdf_nee = ls.delta ? pick.pmf : pdf_light_w * cos_l / d2;
        pdf_lp = pdf_emit / d2;
    }
    // a soft-falloff light's path makes z from its centre (soft_light_medium.h)
    const bool soft = light_receiver_dependent(l);
    if (soft)
        pdf_lp = st.r > 0.0f ? soft_light_path_pdf_a_medium(s, sr, l, z.h.p, vec3(0.0f)) : 0.0f;
    float w_light = ls.delta ? 0.0f : mis(ph / pdf_light_w);
    const float dvcm_z = z.depth == 1 ? z.dvcm * bdpt_direct_lt(st)
                                      : camera_conn_dvcm(st, z.dvcm, z.depth);
    float w_camera = mis(st.r * pdf_lp / pdf_nee) * (dvcm_z + z.dvc * mis(ph));
    // shadow linking: its shadow ray's light, next-event estimation alone; a lamp without
    // shadows: pt's weight (w_camera 0), no shadow ray and no medium on it, as pt_medium_nee
    // (bidir_linking.h; a phase function is no delta lobe)
    const bool unshadowed = s.light_rays && pt_lamp_unshadowed(s, pick.light);
    bidir_nee_weights(s, ps, i, pick.light, unshadowed, w_light, w_camera);
    // a restricted path, an R light: pt's weight, no flight factor (bidir_ray_visibility.h)
    const bool pt_w = rays && bidir_rays_pt_nee(s, ps, i, pick.light);
    if (pt_w) w_camera = 0.0f;
    const float w = 1.0f / (w_light + 1.0f + w_camera);
    const Vec3 c = z.beta * ls.le * (ph * w / pdf_light_w);
    if (!is_finite(c)) {
        ps.dropped[i] = 1;
        return;
    }
    if (unshadowed) {  // Cast Shadow off: no ray
        add_radiance(ps, i, c);
        return;
    }
    if (!infinite) {
        shadow_segment(z.h.p, vec3(0.0f), ls.p_light, ls.n_light, ls.wi, s.offset_scale,
                       &ps.shadow_o[i], &ps.shadow_d[i], &ps.shadow_tmax[i]);
    } else {
        ps.shadow_o[i] = z.h.p;
        ps.shadow_d[i] = ls.wi;
        ps.shadow_tmax[i] = kInf;
    }
    ps.shadow_contrib[i] = c;
    ps.shadow_valid[i] = 1;
    ps.shadow_medium[i] = z.medium_vertex;
    bs.shadow_wn[i] = w_camera;
    bs.shadow_wf[i] = pt_w ? 0.0f : w_light;
    bs.shadow_kind[i] = kConnNearMedium | (st.moments ? kMomOn | kMomFar | kMomOwnB : 0) |
                        (soft ? kConnNearFixed : 0);  // (F(c -> z) is in pdf_lp)
    if (st.moments) bs.shadow_mom[i] = Vec3{w_light, 1.0f, 1.0f};
}

// s >= 2 in a scene with media: z (surface or medium vertex) to cache vertex y (surface or
// medium vertex); the weight of factors 1, its two parts, the medium the segment starts in.
LANTERN_HD inline Connection bdpt_connect_medium(const SceneView& s, const BdptSettings& st,
                                                 const CameraVertex& z, const LightVertex& y,
                                                 bool* clobbered) {
    Connection r{vec3(0.0f), vec3(0.0f), 0.0f, 0.0f, 0.0f};
    if (z.depth + 1 + y.length > st.max_depth) return r;
    Vec3 dir = y.p - z.h.p;
    const float d2 = length_sq(dir);
    if (!(d2 > 0.0f) || !is_finite(d2)) return r;
    const float dist = sqrtf(d2);
    dir = dir / dist;
    const bool zm = z.medium_vertex >= 0, ym = lv_is_medium(y);
    // the camera vertex's side
    Vec3 fz;
    float pz_fwd, pz_rev, cos_z_ng = 1.0f, cos_z_ns = 1.0f;
    int32_t start = z.medium_vertex;
    if (zm) {
        const float ph = hg_phase(s.media[z.medium_vertex].g, dot(-z.wo_w, dir));
        fz = vec3(ph);
        pz_fwd = pz_rev = ph;
    } else {
        const Vec3 wi_z = z.frame.to_local(dir);
        const float dz_ng = dot(dir, z.h.ng);
        if (!(material_corrects_view(*z.m) ? dz_ng > 0.0f : dz_ng * wi_z.z > 0.0f)) return r;
        const BsdfEval ez = bdpt_eval(*z.m, z.h.front, z.wo, wi_z, Transport::Radiance,
                                      z.h.coat_n, z.frame, z.h.ng);
        fz = ez.f;
        pz_fwd = ez.pdf_fwd_w;
        pz_rev = ez.pdf_rev_w;
        // (a strand: the fiber measure's cosine, 0 where a tube faces away: bdpt_curve.h)
        cos_z_ng = light_arrival_cos(z.strand && !z.tube, z.tube, z.frame, z.h.ng, dir);
        cos_z_ns = fabsf(wi_z.z);
        start = dz_ng < 0.0f ? medium_across(s, z.tri, z.h.front, z.slot_medium)
                             : z.slot_medium;
    }
    if (is_black(fz)) return r;
    // the cache vertex's side
    Vec3 fy;
    float py_fwd, py_rev, cos_y_ng = 1.0f, cos_y = 1.0f;
    bool y_fiber = false;
    Frame fyf;
    if (ym) {
        const float ph = hg_phase(s.media[lv_medium(y)].g, dot(y.wo, dir));
        fy = vec3(ph);
        py_fwd = py_rev = ph;
    } else {
        const float dy_ng = dot(-dir, y.ng), dy_ns = dot(-dir, y.ns);
        const bool y_geometric = material_view_geometric(s.materials[y.material]);
        if (!(y_geometric ? dy_ng > 0.0f : dy_ng * dy_ns > 0.0f)) return r;
        // y on a strand: the hair lobe's fiber measure, or a tube vertex facing z (bdpt_curve.h)
        y_fiber = prim_is_strand(s, y.tri) && strand_fiber(s.materials[y.material]);
        if (prim_is_strand(s, y.tri) && !y_fiber && !(dy_ng > 0.0f)) return r;
#ifdef __CUDA_ARCH__
        MaterialScratch& scratch = *z.scratch;
#else
        MaterialScratch scratch;
#endif
        const Material& my = material_at_point(
            s, y.material, [&] { return shade_point_lv(s, y, -dir); }, scratch);
        *clobbered = &my == &scratch.m;
        fyf = Frame::from_normal_angle(y.ns, y.tangent_angle);
        const Vec3 coat_y = (my.tex_flags & kCoatNormal) || material_keeps_unbent_normal(my)
                                ? oct_decode(y.coat_n)
                                : vec3(0.0f, 0.0f, 1.0f);
        const Vec3 wo_y = fyf.to_local(y.wo);
        const Vec3 wi_y = Vec3{dot(-dir, fyf.s), dot(-dir, fyf.t), dy_ns};
        const BsdfEval ey = bdpt_eval(my, lv_front(y), wo_y, wi_y, Transport::Importance,
                                      coat_y, fyf, y.ng);
        const float cos_yo_ng = fabsf(dot(y.wo, y.ng));
        if (!(cos_yo_ng > 0.0f)) return r;
        fy = ey.f;
        py_fwd = ey.pdf_fwd_w;
        py_rev = ey.pdf_rev_w;
        cos_y_ng = vertex_cos(y_fiber, fyf, y.ng, dir);
        // (the lobe's Importance f is the fiber measure's: y's adjoint factor is 1)
        cos_y = y_fiber ? cos_y_ng : fabsf(wo_y.z) * cos_y_ng / cos_yo_ng;
    }
    if (is_black(fy)) return r;
    const float inv_d2 = 1.0f / d2;
    float y_dvcm, y_dvc;
    light_vertex_mis(st, y, &y_dvcm, &y_dvc);
    const float wf = mis(pz_fwd * cos_y_ng * inv_d2) * (y_dvcm + y_dvc * mis(py_rev));
    const float wn = mis(py_fwd * cos_z_ng * inv_d2) * (z.dvcm + z.dvc * mis(pz_rev));
    const float w = 1.0f / (wf + 1.0f + wn);
    r.c = z.beta * fz * y.beta * fy * (cos_z_ns * cos_y * inv_d2 * w);
    if (!is_finite(r.c)) r.c = vec3(0.0f);
    r.dir = dir;
    r.dist = dist;
    r.bsdf_target = luminance(fz) * luminance(fy);
    r.wn = wn;
    r.wf = wf;
    if (st.moments) {  // pt's techniques (bdpt_connect_in), both far-end: kMomG at the finish
        const float x = mis(pz_fwd * cos_y_ng * inv_d2), rev = mis(py_rev);
        r.pt_factor = bdpt_pt_factor(1.0f, x * y.dpt0 * rev,
                                     x * (y.length == 1 ? y.dvcm : y.dpt1 * rev));
    }
    r.medium = start;
    r.kind = (zm ? kConnNearMedium : 0) | (ym ? kConnFarMedium : 0);
    if (y_fiber) r.y_strand_cut = strand_end_shorten(s, y.tri, y.ng, dir, fyf);
    return r;
}

// A medium camera vertex at p reached along d in medium med: its next event and connections
// queued for the events stage (bdpt_camera_events.h), and its continuation (the camera pass's
// medium vertex). Out of line on the device (LANTERN_DEVICE_NOINLINE): one copy, not one in
// each of the two segment stages above it. z: bdpt_camera_shade's camera vertex, not yet set
// (the call ends here): a GPU thread holds one CameraVertex for the whole shade call.
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline void bdpt_camera_medium_vertex(const SceneView& s, const PathState& ps,
                                                 const BdptState& bs, const BdptSettings& st,
                                                 const LightCache& cache, int i, int64_t path,
                                                 Vec3 p, Vec3 d, int32_t med,
                                                 const MediumSegmentPdf& seg, CameraVertex& z) {
    const Medium& m = s.media[med];
    float dvcm = bs.dvcm[i], dvc = bs.dvc[i];
    const int depth = ps.depth[i];
    const float dist = length(p - ps.prev_p[i]);
    if (!(dist > 0.0f)) return;
    bdpt_medium_hit_update(dvcm, dvc, dist, 1.0f, seg, !(depth == 1 && s.camera.orthographic));
    if (depth >= st.max_depth) return;
    z.h.p = p;
    z.h.ng = vec3(0.0f);
    z.h.ns = vec3(0.0f);
    z.tri = camera_medium_tri(s, ps, i, med);  // (light linking: bidir_linking_medium.h)
    z.wo_w = -d;
    z.m = nullptr;
    z.depth = depth;
    z.beta = ps.throughput[i];
    z.dvcm = dvcm;
    z.dvc = dvc;
    z.n_pick = vec3(0.0f);
    z.medium_vertex = med;
    z.slot_medium = med;
    z.strand = false;
    Rng rng = ps.rng[i];
    // next event (bdpt_camera_medium_nee) and connections: the events stage's
    // (bdpt_camera_events.h); here their draws are skipped
    bdpt_queue_camera_events(bs, i, z, rng);
    bdpt_skip_camera_events(rng);
    float pdf_w = 0.0f;
    const Vec3 wi = hg_sample(m.g, d, rng.uniform2(), &pdf_w);  // weight 1
    Vec3 beta = z.beta;
    if (pdf_w > 0.0f && russian_roulette(beta, depth, st.rr_depth, rng) &&
        max_component(beta) > 0.0f && is_finite(beta)) {
        dvcm = camera_conn_dvcm(st, dvcm, depth);
        bdpt_medium_scatter_update(dvcm, dvc, pdf_w);
        ps.throughput[i] = beta;
        ps.depth[i] = depth + 1;
        bs.dvcm[i] = dvcm;
        bs.dvc[i] = dvc;
        ps.ray_o[i] = p;
        ps.ray_d[i] = wi;
        ps.ray_tmin[i] = 0.0f;
        ps.ray_tmax[i] = kInf;
        ps.prev_pdf_w[i] = pdf_w;
        ps.alive[i] = 1;
        ps.prev_p[i] = p;
        ps.prev_n[i] = vec3(0.0f);
        bdpt_seg_store(bs, i, medium_segment_begin(true));
        bidir_set_ray_kind(s, ps, i, kRayKindVolume);  // (ray kinds: Volume Scatter alone)
    }
    ps.rng[i] = rng;
}

// Lights crossed by the stretch [a, b) of a piece of heterogeneous medium med from o0 along d,
// seen with the tracking's weight there (bw: the throughput times it) and the stand-in's factor
// up to each (fo, fd: the piece as the density sees it, medium_frame_ray).
LANTERN_HD inline void bdpt_camera_lights_hetero(const SceneView& s, const PathState& ps,
                                                 const BdptState& bs, const BdptSettings& st,
                                                 int i, int32_t med, Vec3 o0, Vec3 fo, Vec3 fd,
                                                 float a, float b, const MediumSegmentPdf& seg0,
                                                 Vec3 bw) {
    if (is_black(bw)) return;
    const Vec3 d = ps.ray_d[i];
    const bool camera = ps.depth[i] <= 1;
    for (int k = 0; k < s.num_hittable_lights; ++k) {
        const Light& l = s.lights[s.hittable_lights[k]];
        if (camera && !l.visible_camera) continue;
        if (!bidir_emission_counts(s, ps, i, s.hittable_lights[k])) continue;  // (linking)
        if (pt_lamp_unseen(s, ps, i, s.hittable_lights[k])) continue;  // (ray kinds)
        const LightHit h = intersect_light(l, o0, d, a, b);
        if (!h.hit || is_black(h.le)) continue;
        MediumSegmentPdf seg = seg0;
        medium_segment_piece_hetero(seg, s, med, fo, fd, h.t, false);
        float nee = 0.0f;
        float w = bdpt_emission_weight_medium(s, ps, bs, st, i, l, o0 + d * h.t, false, h.n,
                                              seg, &nee);
        w = bidir_pt_weight_medium(s, ps, i, s.hittable_lights[k], seg, w, nee);
        if (w > 0.0f && bidir_rays_on(s) && bidir_rays_pt_weight(s, ps, i, s.hittable_lights[k]))
            w = bidir_rays_emission_weight(s, ps, i, s.hittable_lights[k], o0, d, h.t, h.n,
                                           0.0f);  // (ray kinds: pt's weight)
        add_radiance(ps, i, bw * h.le * w);
    }
}

// The camera path's traced piece in a heterogeneous medium (bdpt_camera_medium_segment's
// contract): a tracking to the next real scattering event, the emission at its tentative
// collisions (weight 1, as in homogeneous media) and the lights it passes, each with the
// tracking's weight; the piece's factors by the stand-in (bdpt_medium_hetero.h). A ray that
// leaves the medium to infinity (an open mesh) sees no distant light.
template <class SR>
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline bool bdpt_camera_hetero_segment(const SceneView& s, const PathState& ps,
                                                  const BdptState& bs, const BdptSettings& st,
                                                  const LightCache& cache, int i, int64_t path,
                                                  CameraVertex& z, const SR& sr) {
    const int tri = ps.hit_prim[i];
    MediumSegmentPdf seg = bdpt_seg_load(bs, i);
    const Vec3 d = ps.ray_d[i];
    const float tmin = ps.ray_tmin[i];
    const Vec3 o0 = ps.ray_o[i] + d * tmin;
    const float len = (tri >= 0 ? ps.hit_t[i] : ps.ray_tmax[i]) - tmin;
    const int32_t med = ps.medium[i];
    const Medium& m = s.media[med];
    const Vec3 beta = ps.throughput[i];
    Rng rng = ps.rng[i];
    Rng tr = medium_tracking_rng(rng, 0);
    rng.uniform();  // the next segment's tracking starts a block of its own
    ps.rng[i] = rng;
    const bool lights = s.num_hittable_lights > 0;
    Vec3 fo = o0, fd = d;  // (a moving volume's density: its exported frame at the path's time)
    if (s.motion.medium_objects) medium_frame_ray(s, med, bdpt_time(st, path), &fo, &fd);
    const HeteroStep h = medium_track(
        s, m, med, fo, fd, len, beta, tr,
        [&](float t, Vec3 w, float mu) {  // mu: the majorant where the collision fell
            if (m.emits)
                add_radiance(ps, i, beta * w * medium_emission_at(s, m, med, fo + fd * t) / mu);
        },
        [&](float a, float b, Vec3 w) {
            if (lights)
                bdpt_camera_lights_hetero(s, ps, bs, st, i, med, o0, fo, fd, a, b, seg, beta * w);
        });
    ps.throughput[i] = beta * h.weight;
    medium_segment_piece_hetero(seg, s, med, fo, fd, h.t, h.scattered);
    if (h.scattered) {
        bdpt_camera_medium_vertex(s, ps, bs, st, cache, i, path, o0 + d * h.t, d, med, seg, z);
        return true;
    }
    bdpt_seg_store(bs, i, seg);
    if (tri < 0 || is_black(ps.throughput[i])) return true;
    if (s.tri_flags[tri] & kVolumeBoundary) {
        bdpt_cross_boundary(s, st, ps, i, path, tri);  // (motion: at its time)
        return true;
    }
    return false;
}

// The camera path's traced piece: its flight, the lights it crosses, a medium vertex, a
// volume boundary passed; false at a surface (bdpt_camera_shade goes on, its emission done).
// Out of line on the device (LANTERN_DEVICE_NOINLINE: ptxas compiles camera shade in pieces).
template <class SR>
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline bool bdpt_camera_medium_segment(const SceneView& s, const PathState& ps,
                                                  const BdptState& bs, const BdptSettings& st,
                                                  const LightCache& cache, int i, int64_t path,
                                                  CameraVertex& z, const SR& sr) {
    const int tri = ps.hit_prim[i];
    MediumSegmentPdf seg = bdpt_seg_load(bs, i);
    const Vec3 o = ps.ray_o[i], d = ps.ray_d[i];
    const float tmin = ps.ray_tmin[i];
    // a miss: to infinity, past the camera's clip end too (pt_medium_segment, D46)
    const float t_end = tri >= 0 ? ps.hit_t[i] : kInf;
    const int32_t med = ps.medium[i];
    const Medium* m = med >= 0 ? &s.media[med] : nullptr;
    if (m && m->hetero) return bdpt_camera_hetero_segment(s, ps, bs, st, cache, i, path, z, sr);
    const Vec3 beta = ps.throughput[i];
    // an emitting medium's emission along the piece, weight 1: no light path starts in a
    // medium, so only the camera path samples it (docs/volumes.md)
    if (m && m->emits) add_radiance(ps, i, beta * medium_emission_integral(*m, t_end - tmin));
    MediumStep step{t_end - tmin, false, vec3(1.0f)};
    if (m) {
        Rng rng = ps.rng[i];
        float uc = 0.0f, ud = 0.0f;
        if (m->scatters) {
            uc = rng.uniform();
            ud = rng.uniform();
        }
        ps.rng[i] = rng;
        step = bdpt_medium_flight(*m, t_end - tmin, uc, ud);
    }
    bdpt_camera_emission_medium(s, ps, bs, st, i, fminf(tmin + step.t, ps.ray_tmax[i]),
                                tri < 0 && !step.scattered, m, seg, beta, sr);
    ps.throughput[i] = beta * step.weight;
    medium_segment_piece(seg, m, step.t, step.scattered);
    if (step.scattered) {
        bdpt_camera_medium_vertex(s, ps, bs, st, cache, i, path, o + d * (tmin + step.t), d, med,
                                  seg, z);
        return true;
    }
    bdpt_seg_store(bs, i, seg);
    if (tri < 0 || is_black(ps.throughput[i])) return true;
    if (s.tri_flags[tri] & kVolumeBoundary) {
        bdpt_cross_boundary(s, st, ps, i, path, tri);  // (motion: at its time)
        return true;
    }
    return false;
}

}  // namespace lantern
