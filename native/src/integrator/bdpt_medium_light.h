// The light pass of the bidirectional stages in media (split from bdpt_medium_stages.h, which
// includes it; the rules there and in bdpt_medium.h): the start medium, the traced piece's
// flight, a medium vertex (stored, splatted to the camera, continued with the phase function),
// and a soft-falloff light's first vertex in a medium (soft_light_medium.h).
#pragma once

#include "integrator/bdpt_medium.h"
#include "integrator/bidir_linking.h"  // shadow linking (y1)
#include "integrator/soft_light_medium.h"

namespace lantern {
// ---------------------------------------------------------------------------------------------
// Light pass
// ---------------------------------------------------------------------------------------------

// After generation: the medium the path starts in (lt's rule), its factor, the segment state.
LANTERN_HD inline void bdpt_light_generate_medium(const SceneView& s, const PathState& ps,
                                                  const BdptState& bs, int li,
                                                  const EmissionSample& es, int i) {
    Vec3 f;
    ps.medium[i] = lt_start_medium(s, li, es, &f);
    bs.power[i] = bs.power[i] * f;
    ps.prev_p[i] = es.p;
    bdpt_seg_store(bs, i, medium_segment_begin(false));
}

// sr: the stage's own ray queries (a soft-falloff light's first vertex traces y0 -> p).
template <class SR>
LANTERN_HD inline void bdpt_light_medium_vertex(const SceneView& s, const PathState& ps,
                                                const BdptState& bs, const BdptSettings& st,
                                                int i, int64_t path, Vec3 p, Vec3 d,
                                                int32_t med, MediumSegmentPdf seg,
                                                const SR& sr) {
    const Medium& m = s.media[med];
    const int k = ps.depth[i] + 1;
    ps.depth[i] = k;
    const Light& l = s.lights[bs.light[i]];
    const bool infinite = l.type == kLightSun || l.type == kLightWorld;
    const float dist = length(p - ps.prev_p[i]);
    if (!(dist > 0.0f)) return;
    // light linking (bidir_linking_medium.h): a vertex in the world's medium receives as set 0,
    // which decides a pending set; where l does not light it the sub-path ends here
    if (s.light_receivers && ps.recv_set && ps.recv_set[i] && med == s.world_medium) {
        ps.recv_set[i] = 0;
        if (!pt_light_links(s, bs.light[i], 0)) return;
    }
    // shadow linking, a lamp without shadows (bidir_linking.h): y1 of such a light scattering
    // off the phase function (no delta lobe) is next-event estimation's (and s = 0's for the
    // lamp) alone: not stored, splatted, continued
    if (k == 1 && bidir_light_path_delta_only(s, bs.light[i])) return;
    const bool soft = k == 1 && light_receiver_dependent(l);
    if (soft) {  // the light arrives from y0 on the disk facing p (soft_light_medium.h)
#ifdef __CUDA_ARCH__
        return;  // (no such path starts on the device: bdpt_light_shade)
#else
        Rng r = ps.rng[i];
        const Vec2 u = r.uniform2();
        ps.rng[i] = r;
        const SoftFirstHitMedium sm = soft_light_first_hit_medium(s, sr, l, p, vec3(0.0f), med,
                                                                  med, u);
        if (!sm.hit.valid || !(seg.fwd > 0.0f)) return;
        d = sm.hit.wi;
        bs.power[i] = bs.power[i] * (sm.hit.atten * sm.hit.cos_light);
        ps.throughput[i] = sm.tr * m.sigma_s * (1.0f / seg.fwd);  // T(y0 -> p) sigma_s / F
        bs.dvc[i] *= mis(sm.hit.cos_light);
        if (st.moments || st.conn_map) bs.dpt0[i] *= mis(sm.hit.cos_light);
        seg.rev = sm.pass;  // the s = 0 technique flies p -> y0
#endif
    }
    float dvcm = bs.dvcm[i], dvc = bs.dvc[i];
    if (k == 1 && !infinite) {  // (bdpt_light_shade; a soft disk's path left its centre)
        const Vec3 n0 = l.type == kLightArea ? -l.frame.axis(2)
                        : soft                ? vec3(0.0f)
                                              : normalize(ps.prev_p[i] - l.position);
        dvcm *= mis(direct_pdf_receiver_ratio(l, p, -d, dist, n0));
    }
    if (k == 1) dvcm *= mis(light_pick_pmf(s, bs.light[i], p, vec3(0.0f)));
    // (moments, a map: dvc's parts that are pt's techniques, bdpt_light_shade, with the factors)
    const bool dpt = st.moments || st.conn_map;
    const float dpt0 = dpt ? bs.dpt0[i] * mis(seg.rev) / mis(seg.fwd) : 0.0f;
    const float dpt1 = dpt ? bs.dpt1[i] * mis(seg.rev) / mis(seg.fwd) : 0.0f;
    bdpt_medium_hit_update(dvcm, dvc, dist, 1.0f, seg, k > 1 || !infinite);
    const Vec3 beta = bs.power[i] * ps.throughput[i];
    bs.vertex[i] = lv_make_medium(p, -d, beta, dvcm, dvc, med, int32_t(path), k);
    bs.vertex[i].dpt0 = dpt0;
    bs.vertex[i].dpt1 = dpt1;
    // light linking, its set not known yet (bidir_linking_medium.h): the light kept with it
    const bool pending = s.light_receivers && ps.recv_set && ps.recv_set[i];
    if (pending) bs.vertex[i].bary16 = uint32_t(bs.light[i] + 1);
    bs.store[i] = is_finite(beta) && is_finite(dvcm) && is_finite(dvc) ? 1 : 0;
    // t = 1: no cosine at the vertex; the camera's density of it times its factor (near end)
    if (k + 1 <= st.max_depth && !(pending && !pt_light_links(s, bs.light[i], 0))) {
#ifdef __CUDA_ARCH__  // (motion blur renders on the CPU only: medium_rays_timed)
        const CameraView& cam = s.camera;
#else
        const CameraView cam = s.motion.camera_steps > 1 ? bdpt_camera_moved(s, st, path)
                                                         : s.camera;  // (bdpt_light_shade's)
#endif
        const CameraConnection cc = connect_camera(cam, p, filter_radius(cam),
                                                   lens_sample(cam, ps, i));
        if (cc.valid) {
            const float phase = hg_phase(m.g, dot(d, cc.wc));
            const float n_lt = k == 1 ? st.n_lt * st.lt_direct : st.n_lt;
            const float wn = mis(cc.importance * st.r / n_lt) * (dvcm + dvc * mis(phase));
            bs.shadow_wn[i] = wn;
            bs.shadow_wf[i] = 0.0f;
            bs.shadow_kind[i] = kConnNearMedium | (st.moments ? kMomOn | kMomNear : 0);
            if (st.moments) {  // pt's techniques (bdpt_light_shade), both near-end
                const float x = mis(cc.importance * st.r / n_lt);
                bs.shadow_mom[i] = Vec3{x * dpt0 * mis(phase),
                                        x * (k == 1 ? dvcm : dpt1 * mis(phase)), 1.0f / n_lt};
            }
            ps.shadow_medium[i] = med;
            LightPathState lp{nullptr, bs.splat_xy};
            lt_queue_splat(ps, lp, i, p, vec3(0.0f), cc,
                           beta * (phase * cc.importance / (1.0f + wn)), s.offset_scale);
        }
    }
    if (k + 2 > st.max_depth) return;
    Rng rng = ps.rng[i];
    float pdf_w = 0.0f;
    const Vec3 wi = hg_sample(m.g, d, rng.uniform2(), &pdf_w);  // weight 1
    Vec3 t = ps.throughput[i];
    if (pdf_w > 0.0f && russian_roulette(t, k + 1, st.rr_depth, rng) &&
        max_component(t) > 0.0f && is_finite(t)) {
        if (dpt) {  // dvc's recursion, each part on its own (the phase's pdfs are equal)
            bs.dpt0[i] = dpt0;
            bs.dpt1[i] = dpt1 + (k == 1 ? mis(1.0f / pdf_w) * dvcm : 0.0f);
        }
        bdpt_medium_scatter_update(dvcm, dvc, pdf_w);
        ps.throughput[i] = t;
        bs.dvcm[i] = dvcm;
        bs.dvc[i] = dvc;
        ps.ray_o[i] = p;
        ps.ray_d[i] = wi;
        ps.ray_tmin[i] = 0.0f;
        ps.ray_tmax[i] = kInf;
        ps.prev_pdf_w[i] = pdf_w;
        ps.alive[i] = 1;
        ps.prev_p[i] = p;
        bdpt_seg_store(bs, i, medium_segment_begin(true));
    }
    ps.rng[i] = rng;
}

// The traced piece: true when this stage handled the slot (a medium vertex, a volume boundary
// passed, the path lost); false at a surface, whose shading (bdpt_light_shade) reads the
// segment's factors from the slot.
template <class SR>
LANTERN_HD inline bool bdpt_light_medium_segment(const SceneView& s, const PathState& ps,
                                                 const BdptState& bs, const BdptSettings& st,
                                                 int i, int64_t path, const SR& sr) {
    const int tri = ps.hit_prim[i];
    MediumSegmentPdf seg = bdpt_seg_load(bs, i);
    const Vec3 o = ps.ray_o[i], d = ps.ray_d[i];
    const float tmin = ps.ray_tmin[i];
    const float t_end = tri >= 0 ? ps.hit_t[i] : ps.ray_tmax[i];
    const int32_t med = ps.medium[i];
    if (med >= 0) {
        const Medium& m = s.media[med];
        Rng rng = ps.rng[i];
        MediumStep step;
        Vec3 fo = o + d * tmin, fd = d;  // (a moving volume's density: its exported frame)
        if (m.hetero && s.motion.medium_objects)
            medium_frame_ray(s, med, bdpt_time(st, path), &fo, &fd);
        if (m.hetero) {  // tracking; the stand-in's factors (bdpt_medium_hetero.h)
            step = bdpt_hetero_flight(s, med, fo, fd, t_end - tmin,
                                      bs.power[i] * ps.throughput[i], rng);
        } else {
            float uc = 0.0f, ud = 0.0f;
            if (m.scatters) {
                uc = rng.uniform();
                ud = rng.uniform();
            }
            step = bdpt_medium_flight(m, t_end - tmin, uc, ud);
        }
        ps.rng[i] = rng;
        ps.throughput[i] = ps.throughput[i] * step.weight;
        medium_segment_piece_at(seg, s, med, fo, fd, step.t, step.scattered);
        if (step.scattered) {
            bdpt_light_medium_vertex(s, ps, bs, st, i, path, o + d * (tmin + step.t), d, med,
                                     seg, sr);
            return true;
        }
    } else {
        medium_segment_piece(seg, nullptr, t_end - tmin, false);
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
