// The light pass of the bidirectional stages (bdpt.h): light sub-paths, the cache vertices
// they store and their light-tracing splats (t = 1). MIS quantities: bdpt_common.h.
#pragma once

#include "integrator/bdpt_common.h"
#include "integrator/bdpt_curve.h"
#include "integrator/bidir_linking.h"
#include "integrator/bdpt_medium.h"
#include "integrator/bdpt_motion.h"
#include "integrator/bdpt_sss_light.h"  // subsurface: the light paths' walks (CPU)
#include "integrator/pixel_conn.h"
#include "integrator/soft_light_medium.h"
#include "integrator/soft_light_path.h"

namespace lantern {

// scenes with media (bdpt_medium_stages.h)
LANTERN_HD inline void bdpt_light_generate_medium(const SceneView& s, const PathState& ps,
                                                  const BdptState& bs, int li,
                                                  const EmissionSample& es, int i);
template <class SR>
LANTERN_HD inline bool bdpt_light_medium_segment(const SceneView& s, const PathState& ps,
                                                 const BdptState& bs, const BdptSettings& st,
                                                 int i, int64_t path, const SR& sr);

LANTERN_HD inline void bdpt_light_generate(const SceneView& s, const PathState& ps,
                                           const BdptState& bs, const BdptSettings& st, int i,
                                           int64_t path) {
    Rng rng = Rng::for_path(st.seed ^ 0x4C5643ull, st.iteration, uint64_t(path));
    ps.alive[i] = 0;
    ps.dropped[i] = 0;
    ps.shadow_valid[i] = 0;
    ps.depth[i] = 0;
    ps.throughput[i] = vec3(1.0f);
    bs.power[i] = vec3(0.0f);
    bs.store[i] = 0;
    if (s.light_receivers && ps.recv_set) ps.recv_set[i] = 1;  // (bidir_linking_medium.h)
    float u_pick = rng.uniform();
    Vec2 u_pos = rng.uniform2(), u_dir = rng.uniform2();
    ps.rng[i] = rng;
    if (!s.emit_cdf) return;
    int li = sample_cdf(s.emit_cdf, s.num_lights, u_pick);
    const Light& l = s.lights[li];
    if (!(l.emit_pick_pdf > 0.0f)) return;
    // (a soft-falloff light: from its centre; its first hit picks y0, soft_light_path.h)
    EmissionSample es = light_receiver_dependent(l) ? sample_soft_emission(l, u_dir)
                                                    : sample_emission(s, l, u_pos, u_dir,
                                                                      s.motion.num_objects > 0
                                                                          ? bdpt_time(st, path)
                                                                          : 0.0f);
    if (!es.valid) return;
    const float pdf_emit = es.pdf_emit * l.emit_pick_pdf;
    bs.power[i] = es.le * (es.cos_light / pdf_emit);
    // ratios of the techniques that end on the light (s = 1, s = 0) to a connection (count r)
    const float inv_r = 1.0f / mis(st.r);
    // (next-event estimation's pick probability of this light depends on the receiver: the
    // first hit multiplies it in, bdpt_light_shade)
    bs.dvcm[i] = mis(es.pdf_direct / pdf_emit) * inv_r;
    bs.dvc[i] = (es.delta_pos || es.delta_dir)
                    ? 0.0f
                    : mis((es.finite ? es.cos_light : 1.0f) / pdf_emit) * inv_r;
    bs.light[i] = li;
    if (st.moments || st.conn_map) {  // pt's techniques: all camera-sampled (dVC's), next-event
        bs.dpt0[i] = bs.dvc[i];
        bs.dpt1[i] = 0.0f;
    }
    if (st.max_depth < 2) return;
    // an R light's paths are pt's (bidir_ray_visibility.h): none leaves it
    if (bidir_rays_on(s) && bidir_light_restricted(s, li)) return;
    ps.ray_o[i] = is_black(es.n) ? es.p : offset_ray_origin(es.p, es.n, es.d, s.offset_scale);
    ps.ray_d[i] = es.d;
    ps.ray_tmin[i] = 0.0f;
    ps.ray_tmax[i] = kInf;
    ps.prev_pdf_w[i] = pdf_emit;
    ps.alive[i] = 1;
    if (s.num_media > 0) bdpt_light_generate_medium(s, ps, bs, li, es, i);
}

// Weight of the light tracing splat (t = 1) of a light vertex: camera_pdf_a is the camera's
// density of this vertex (raster density 1 per pixel), pdf_rev the BSDF's density of the light
// path's incoming direction given the camera direction.
LANTERN_HD inline float bdpt_light_tracing_weight(const BdptSettings& st, float dvcm, float dvc,
                                                  float camera_pdf_a, float pdf_rev, int k) {
    const float n_lt = k == 1 ? st.n_lt * st.lt_direct : st.n_lt;  // (BdptSettings::lt_direct)
    float w_light = mis(camera_pdf_a * st.r / n_lt) * (dvcm + dvc * mis(pdf_rev));
    return 1.0f / (1.0f + w_light);
}

// At a light path's hit: MIS update, the vertex to store, the camera splat, the next direction.
// sr: the stage's own ray queries (a soft-falloff light's first hit tests y0 -> x1). L:
// linking's tests compiled in (bidir_links_on; false: a scene without them).
template <bool L = true, class SR>
LANTERN_HD inline void bdpt_light_shade(const SceneView& s, const PathState& ps,
                                        const BdptState& bs, const BdptSettings& st, int i,
                                        int64_t path, const SR& sr) {
    ps.shadow_valid[i] = 0;
    ps.alive[i] = 0;
    bs.store[i] = 0;
    int tri = ps.hit_prim[i];
    const bool media = s.num_media > 0;
    // media: the piece's flight, a medium vertex, a boundary passed (bdpt_medium_stages.h)
    if (media && bdpt_light_medium_segment(s, ps, bs, st, i, path, sr)) return;
    if (tri < 0) return;
    const Vec3 d = ps.ray_d[i];
    // (media: the segment from the last vertex, through its pieces)
    const Vec3 o_prev = media ? ps.prev_p[i] : ps.ray_o[i];
    float dist = ps.hit_t[i];
    const Light& l = s.lights[bs.light[i]];
    // a triangle's or a strand's surface (pt_curve.h; strands: the fiber measure, bdpt_curve.h)
    const bool strand = prim_is_strand(s, tri);
    // a soft-falloff light's first hit x1: the light arrives from y0 on the disk facing x1, not
    // from the centre the path left (soft_light_path.h); d_in is its direction (scenes with
    // strands start no light paths on these lights: scene_lights.cpp; media: y0 -> x1 through
    // them, soft_light_medium.h)
    Vec3 d_in = d;
    float soft_cos = 0.0f;  // the cosine at x1 towards the centre (the density of x1)
    float soft_pass = 1.0f;  // media: the s = 0 technique's factor over x1 -> y0
    if (ps.depth[i] == 0 && light_receiver_dependent(l)) {
#ifdef __CUDA_ARCH__
        // not on the GPU (its kernel's stack): no light path starts there on these lights
        // (HostScene's soft_light_paths is off for a GPU session, so their pick pdf is 0)
        return;
#else
        const SurfaceHit hc = bdpt_surface(s, st, path, tri, ps.hit_uv[i], d);
        Rng r = ps.rng[i];
        const Vec2 u = r.uniform2();
        ps.rng[i] = r;
        SoftFirstHit sf;
        if (media) {  // the flights' throughput becomes T(y0 -> x1) / F(c -> x1)
            const SoftFirstHitMedium sm = soft_light_first_hit_medium(
                s, sr, l, hc.p, hc.ng, ps.medium[i],
                medium_across(s, tri, hc.front, ps.medium[i]), u);
            sf = sm.hit;
            const float fwd = bs.seg_fwd[i];
            if (!sf.valid || !(fwd > 0.0f)) return;
            ps.throughput[i] = sm.tr * (1.0f / fwd);
            ps.medium[i] = sm.medium;  // the light arrives from y0's side
            soft_pass = sm.pass;
        } else {
            sf = soft_light_first_hit(s, sr, l, hc.p, hc.ng, u);
        }
        soft_cos = fabsf(dot(d, hc.ng));
        if (!sf.valid || !(soft_cos > 0.0f)) return;
        d_in = sf.wi;
        bs.power[i] = bs.power[i] * (sf.atten * sf.cos_light);
        bs.dvc[i] *= mis(sf.cos_light);
        if (st.moments || st.conn_map) bs.dpt0[i] *= mis(sf.cos_light);
#endif
    }
    SurfaceHit h = strand ? surface_of_hit(s, tri, ps.hit_uv[i], ps.ray_o[i], d, ps.hit_t[i],
                                           s.motion.curves ? bdpt_time(st, path) : 0.0f)
                          : bdpt_surface(s, st, path, tri, ps.hit_uv[i], d_in);  // (motion)
    if (media) dist = length(h.p - o_prev);
    MaterialScratch scratch;
    const Material& m = material_at_point(
        s, s.tri_material[tri],
        [&] { return shade_point(h, strand ? -1 : tri, ps.hit_uv[i], -d_in); }, scratch);
    const int k = ps.depth[i] + 1;  // segments from the light to this vertex
    ps.depth[i] = k;
    const Vec3 wo_w = -d_in;
    Frame frame = h.frame();
    // on a strand: the hair lobe's fiber measure, or a tube vertex (pt's surface point), which
    // must face both its neighbours (bdpt_curve.h)
    const bool fiber = strand && strand_fiber(m), tube = strand && !fiber;
    float cos_o_ns = fabsf(dot(wo_w, h.ns)), cos_o_ng = fabsf(dot(wo_w, h.ng));
    if (fiber) cos_o_ns = cos_o_ng = vertex_cos(true, frame, h.ng, wo_w);
    if (!(cos_o_ng > 0.0f) || !(dist > 0.0f)) return;
    // the geometric cosine of the density of this vertex: along the traced segment
    const float cos_a = soft_cos > 0.0f ? soft_cos : cos_o_ng;
    // (soft: the flux's cos_x1 is y0's, its density's the centre's)
    if (soft_cos > 0.0f) bs.power[i] = bs.power[i] * (cos_o_ng / soft_cos);

    // ---- MIS quantities at this vertex ----
    float dvcm = bs.dvcm[i], dvc = bs.dvc[i];
    const bool infinite = l.type == kLightSun || l.type == kLightWorld;
    if (k == 1 && !infinite) {
        // next-event estimation samples a sphere light's visible cap, a rectangle's solid
        // angle, a soft disk's cone: its area density at y0 depends on the receiver y1 (here),
        // not 1 / area as assumed at generation (a soft disk's path left its centre: no n0)
        const Vec3 n0 = l.type == kLightArea        ? -l.frame.axis(2)
                        : light_receiver_dependent(l) ? vec3(0.0f)
                                                      : normalize(o_prev - l.position);
        dvcm *= mis(direct_pdf_receiver_ratio(l, h.p, wo_w, dist, n0));
    }
    if (k == 1) {  // next-event estimation from here picks this light with this probability
        dvcm *= mis(light_pick_pmf(s, bs.light[i], h.p, light_pick_normal(s, tri, h.ng)));
    }
    // (media: a soft light's s = 0 technique flies x1 -> y0, not x1 -> c: its factor in dVC)
    MediumSegmentPdf sg = medium_segment_begin(false);
    if (media) {
        sg = bdpt_seg_load(bs, i);
        if (soft_cos > 0.0f) sg.rev = soft_pass;
        bdpt_medium_hit_update(dvcm, dvc, dist, cos_a, sg, k > 1 || !infinite);
    } else {
        if (k > 1 || !infinite) dvcm *= mis(dist * dist);
        dvcm /= mis(cos_a);
        dvc /= mis(cos_a);
    }
    // (moments) the parts of dvc that are pt's techniques: dpt0 all camera-sampled, dpt1 the
    // camera sampling all but y0, which next-event estimation samples (at k = 1: dvcm itself)
    // (a connection map too: they are the parts a pixel's count scales, pixel_conn.h)
    float dpt0 = 0.0f, dpt1 = 0.0f;
    if (st.moments || st.conn_map) {
        dpt0 = bs.dpt0[i] / mis(cos_a);
        dpt1 = bs.dpt1[i] / mis(cos_a);
        if (media) {  // the segment's factors, as dvc's (bdpt_medium_hit_update)
            dpt0 *= mis(sg.rev) / mis(sg.fwd);
            dpt1 *= mis(sg.rev) / mis(sg.fwd);
        }
    }

    const Vec3 wo = frame.to_local(wo_w);
    const Vec3 beta = bs.power[i] * ps.throughput[i];
    // linking (bidir_linking.h): y1 its light does not light ends the path; y1 of a shadow-linked
    // light or of a lamp without shadows is not the light path's, unless it scatters through a
    // delta lobe
    // (media: the first surface vertex decides where y1.. were medium vertices,
    // bidir_linking_medium.h)
    if (L && s.light_receivers &&
        (k == 1 || (s.num_media > 0 && ps.recv_set && ps.recv_set[i]))) {
        if (ps.recv_set) ps.recv_set[i] = 0;
        if (!bidir_links(s, bs.light[i], tri)) return;
    }
    const bool only_delta = L && k == 1 && bidir_light_path_delta_only(s, bs.light[i]);
    const bool delta = material_is_delta(m) || only_delta;
    // a vertex on an R surface: splatted only (bidir_ray_visibility.h)
    const bool restricted = L && bidir_tri_restricted(s, tri);

    if (!delta && !restricted) {
        LightVertex v;
        v.p = h.p;
        v.ng = h.ng;
        v.ns = h.ns;
        v.wo = wo_w;
        v.beta = beta;
        v.dvcm = dvcm;
        v.dvc = dvc;
        v.material = s.tri_material[tri];
        v.tri = tri;
        v.bary16 = bary16_encode(ps.hit_uv[i]);
        v.tangent_angle = h.tangent_angle;
        v.path = int32_t(path);
        v.length = int16_t(k);
        v.front = h.front ? 1 : 0;
        v.coat_n = (m.tex_flags & kCoatNormal) || material_keeps_unbent_normal(m)
                       ? oct_encode(h.coat_n)
                       : 0u;
        v.dpt0 = dpt0;
        v.dpt1 = dpt1;
        bs.vertex[i] = v;
        bs.store[i] = is_finite(beta) && is_finite(dvcm) && is_finite(dvc) ? 1 : 0;
    }

    // ---- t = 1: connect to the camera (k + 1 segments) ----
    if (!delta && k + 1 <= st.max_depth && (s.tri_flags[tri] & kVisibleCamera) != 0) {
        // (a moving camera: at the path's time, bdpt_motion.h)
        const CameraView cam = s.motion.camera_steps > 1 ? bdpt_camera_moved(s, st, path)
                                                         : s.camera;
        CameraConnection cc = connect_camera(cam, h.p, filter_radius(cam),
                                             lens_sample(cam, ps, i));
        if (cc.valid && view_side_agrees(m, cc.wc, h.ng, h.ns) &&
            !(tube && !(dot(cc.wc, h.ng) > 0.0f))) {
            BsdfEval e = bdpt_eval(m, h.front, wo, frame.to_local(cc.wc), Transport::Importance,
                                   h.coat_n, frame, h.ng);
            if (!is_black(e.f)) {
                float cos_wc_ng = vertex_cos(fiber, frame, h.ng, cc.wc);
                // f |wc.ns| times the adjoint shading-normal factor [Veach thesis (5.19)]
                float cos_y = cos_o_ns * cos_wc_ng / cos_o_ng;
                float w = st.conn_map
                              ? lt_weight_mapped(st, pixel_conn_at(st, s.camera, cc.raster_x,
                                                                   cc.raster_y).q,
                                                 dvcm, dvc, dpt0, dpt1,
                                                 cc.importance * cos_wc_ng, e.pdf_rev_w, k)
                              : bdpt_light_tracing_weight(st, dvcm, dvc,
                                                          cc.importance * cos_wc_ng,
                                                          e.pdf_rev_w, k);
                LightPathState lp{nullptr, bs.splat_xy};
                Vec3 c = beta * e.f * (cos_y * cc.importance * w);
                if (media) {  // the weight finished with the camera segment's factors
                    const float n_lt = k == 1 ? st.n_lt * st.lt_direct : st.n_lt;
                    bs.shadow_wn[i] = mis(cc.importance * cos_wc_ng * st.r / n_lt) *
                                      (dvcm + dvc * mis(e.pdf_rev_w));
                    bs.shadow_wf[i] = 0.0f;
                    bs.shadow_kind[i] = st.moments ? kMomOn | kMomNear : 0;
                    ps.shadow_medium[i] = dot(cc.wc, h.ng) < 0.0f
                                              ? medium_across(s, tri, h.front, ps.medium[i])
                                              : ps.medium[i];
                }
                if (st.moments) {
                    const float n_lt = k == 1 ? st.n_lt * st.lt_direct : st.n_lt;
                    const float x = mis(cc.importance * cos_wc_ng * st.r / n_lt);
                    const float a = x * dpt0 * mis(e.pdf_rev_w);
                    const float b = x * (k == 1 ? dvcm : dpt1 * mis(e.pdf_rev_w));
                    // f / q of the contribution the sum receives, c / st.n_lt (the splat's
                    // scale, wavefront.h's splat()), is that times st.n_lt / n_lt (the count its
                    // weight assumes: lt_direct): c / n_lt
                    if (media)  // channels at the camera segment (bdpt_medium_finish_c)
                        bs.shadow_mom[i] = Vec3{a, b, 1.0f / n_lt};
                    else
                        c = bdpt_moment(c, c * (1.0f / n_lt), bdpt_pt_factor(1.0f / w, a, b));
                }
                lt_queue_splat(ps, lp, i, h.p, h.ng, cc, c, s.offset_scale);
            }
        }
    }
    // subsurface: lt's choice, the walk stage takes it (bdpt_sss_light.h); on an R surface too
    // (the walk is no segment and x_o lies at the camera-side end of its light's segment)
    if (s.has_subsurface && !strand && !delta &&
        bdpt_light_sss_choose(s, ps, bs, st, i, m, h, wo_w, cos_o_ns, cos_o_ng, k, dvcm, dvc))
        return;
    if (restricted) return;
    if (k + 2 > st.max_depth) return;  // the next vertex could not be used by any technique

    // ---- continue with the adjoint BSDF ----
    Rng rng = ps.rng[i];
    Vec2 u_dir = rng.uniform2();
    BsdfSample b = material_sample(m, h.front, wo, Vec3{u_dir.x, u_dir.y, rng.uniform()},
                                   Transport::Importance, h.coat_n, frame.to_local(h.ng));
    Vec3 wi = frame.to_world(b.wi);
    // (a tube vertex left through its fiber: no camera path reaches it from there, pt's path
    // space ends here)
    if (b.valid && view_side_agrees(m, wi, h.ng, h.ns) &&
        (b.delta || (b.pdf_fwd_w > 0.0f && !only_delta)) && !(tube && !(dot(wi, h.ng) > 0.0f))) {
        float cos_i_ng = vertex_cos(fiber, frame, h.ng, wi);
        // (a strand: the lobe's Importance weight is the fiber measure's whole throughput)
        float adj = fiber ? 1.0f : cos_o_ns * cos_i_ng / (cos_o_ng * fabsf(b.wi.z));
        Vec3 t = ps.throughput[i] * b.weight * adj;
        if (russian_roulette(t, k + 1, st.rr_depth, rng) && max_component(t) > 0.0f &&
            is_finite(t)) {
            if (st.moments || st.conn_map) {  // dvc's recursion, each part on its own
                const float ratio = b.pdf_fwd_w > 0.0f ? b.pdf_rev_w / b.pdf_fwd_w : 1.0f;
                const float fwd = b.delta ? 1.0f : mis(cos_i_ng / b.pdf_fwd_w);
                const float rev = b.delta ? mis(cos_i_ng * ratio) : mis(b.pdf_rev_w);
                bs.dpt0[i] = fwd * dpt0 * rev;
                bs.dpt1[i] = fwd * (dpt1 * rev + (k == 1 && !b.delta ? dvcm : 0.0f));
            }
            bdpt_scatter_update(dvcm, dvc, b, cos_i_ng);
            ps.throughput[i] = t;
            bs.dvcm[i] = dvcm;
            bs.dvc[i] = dvc;
            set_next_ray(ps, i, h.p, h.ng, wi, b.delta ? 0.0f : b.pdf_fwd_w,
                         s.offset_scale);
            if (media) {
                if (dot(wi, h.ng) < 0.0f)  // through the surface
                    ps.medium[i] = medium_across(s, tri, h.front, ps.medium[i]);
                ps.prev_p[i] = h.p;
                bdpt_seg_store(bs, i, medium_segment_begin(false));
            }
        }
    }
    ps.rng[i] = rng;
}

}  // namespace lantern
