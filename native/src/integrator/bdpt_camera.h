// The camera pass of the bidirectional stages (bdpt.h): camera sub-paths with emission (s = 0),
// next-event estimation (s = 1) and connections to the cache (s >= 2): own path (bdpt),
// uniform (lvc) or resampled (cis). MIS quantities: bdpt_common.h.
#pragma once

#include "integrator/bdpt_camera_emission.h"  // generation, emission (s = 0)
#include "integrator/bdpt_camera_vertex.h"
#include "integrator/bdpt_common.h"
#include "integrator/bdpt_curve.h"
#include "integrator/bdpt_medium.h"
#include "integrator/bdpt_motion.h"  // bdpt_emitter_time
#include "integrator/bdpt_sss_light.h"  // subsurface: the split, light exits (CPU)
#include "integrator/bidir_no_shadow.h"
#include "integrator/pixel_conn.h"
#include "integrator/soft_light_path.h"
#include "integrator/terminator.h"

namespace lantern {

// The camera vertex's material, resolved (again) into its scratch: shade_point as the shade
// stage built it. Out of line on the device (LANTERN_DEVICE_NOINLINE): the resolution's locals
// stay out of the frames of the kernels that call it (the shade, the events stage).
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline const Material& camera_vertex_material(const SceneView& s,
                                                         const CameraVertex& z) {
    return material_at_point(
        s, s.tri_material[z.tri],
        [&] { return shade_point(z.h, z.strand ? -1 : z.tri, z.uv, z.wo_w); }, *z.scratch);
}

// Shadow segment from p (normal n) to q (normal nq; zero: no offset), shortened at both ends.
LANTERN_HD inline void shadow_segment(Vec3 p, Vec3 n, Vec3 q, Vec3 nq, Vec3 dir, float scale,
                                      Vec3* o, Vec3* sd, float* tmax) {
    *o = offset_ray_origin(p, n, dir, scale);
    Vec3 target = is_black(nq) ? q : offset_ray_origin(q, nq, -dir, scale);
    Vec3 seg = target - *o;
    float len = length(seg);
    *sd = len > 0.0f ? seg / len : dir;
    *tmax = len * (1.0f - 1e-4f);
}

// s = 1: one light sample; the shadow ray waits in the slot's shadow fields. Out of line on the
// device: ptxas compiles the camera shade kernel in pieces (LANTERN_DEVICE_NOINLINE).
// L: linking's tests compiled in (bidir_links_on; false: a scene without them).
template <bool L = true, class SR>
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline void bdpt_camera_nee(const SceneView& s, const PathState& ps,
                                       const BdptState& bs, const BdptSettings& st,
                                       const CameraVertex& z, int i, Rng& rng, const SR& sr,
                                       int64_t path) {
    Vec2 u_pick = rng.uniform2();
    Vec2 u_light = rng.uniform2();
    const LightPick pick = light_pick(s, z.h.p, z.n_pick, u_pick.x);
    if (!(pick.pmf > 0.0f)) return;
    // light linking: nothing from a light that does not light z (bidir_linking.h)
    if (L && s.light_receivers && !bidir_links(s, pick.light, z.tri)) return;
    const Light& l = s.lights[pick.light];
    // (a moving emitter: where it is at the path's time, its densities then)
    const float time = bdpt_emitter_time(s, st, path);
    LightSample ls = sample_light(s, l, z.h.p, u_light, time);
    // geo_side false: a smooth mesh's light from under its face (integrator/terminator.h),
    // which no other technique samples (z's BSDF keeps to the face's side; a light path reaching
    // z from there would meet the face's back): weight 1
    const bool geo_side = light_side_agrees(*z.m, ls.wi, z.h.ng, z.h.ns);
    // a lamp without shadows: pt's weights and no shadow ray, at any offset (bidir_linking.h)
    const bool unshadowed = L && s.light_rays && pt_lamp_unshadowed(s, pick.light);
    if (!ls.valid || is_black(ls.le) ||
        !(geo_side || terminator_passes(s, z.tri, ls.wi, z.h.ng, z.h.ns) ||
          (unshadowed && !sides_agree(ls.wi, z.h.ng, z.h.ns))))
        return;
    // ray visibility by kind (bidir_ray_visibility.h): only the leaves whose closure class sees
    // the light (pt_nee_leaves), the whole BSDF's pdf, as pt's next event
    const bool rays = L && bidir_rays_on(s);
    const uint32_t lit = rays ? pt_nee_leaves(s, pick.light, *z.m, ls.wi, z.h.ng) : kNeeAllLit;
    if (!lit) return;
    BsdfEval e = material_eval(*z.m, z.h.front, z.wo, z.frame.to_local(ls.wi), Transport::Radiance,
                               z.h.coat_n, z.ng_l);
    if (lit != kNeeAllLit)
        e.f = pt_eval_lit(*z.m, z.h.front, z.wo, z.frame.to_local(ls.wi), z.h.coat_n, lit);
    float pdf_light_w = pick.pmf * ls.pdf_w;
    if (is_black(e.f) || !(pdf_light_w > 0.0f)) return;
    const bool infinite = !(ls.dist < kInf);
    const float cos_z = light_arrival_cos(z.strand && !z.tube, z.tube, z.frame, z.h.ng, ls.wi);
    // densities of the light point: by next-event estimation, by the light sub-path (s = 2)
    float cos_l = is_black(ls.n_light) ? 1.0f : fabsf(dot(ls.wi, ls.n_light));
    float pdf_nee, pdf_lp;
    float pdf_emit = l.emit_pick_pdf * emission_pdf(s, l, ls.n_light, -ls.wi, time).pdf_emit;
    if (infinite) {
        pdf_nee = pdf_light_w;
        pdf_lp = pdf_emit * cos_z;
    } else {
        float d2 = ls.dist * ls.dist;
        pdf_nee = ls.delta ? pick.pmf : pdf_light_w * cos_l / d2;
        pdf_lp = pdf_emit * cos_z / d2;
    }
    // a soft-falloff light's path makes z from its centre, when it sees z (soft_light_path.h;
    // r = 0, no light-path technique here: no ray)
    // (media: through them, the flights' factor in the density, soft_light_medium.h)
    const bool soft = light_receiver_dependent(l);
    if (soft)
        pdf_lp = !(st.r > 0.0f) ? 0.0f
                 : s.num_media > 0 ? soft_light_path_pdf_a_medium(s, sr, l, z.h.p, z.h.ng)
                                   : soft_light_path_pdf_a(s, sr, l, z.h.p, z.h.ng);
    float w_light =
        ls.delta || (!geo_side && !unshadowed) ? 0.0f : mis(e.pdf_fwd_w / pdf_light_w);
    // (the first vertex: z.dvcm is light tracing's term alone, BdptSettings::lt_direct)
    const float dvcm_z = z.depth == 1 ? z.dvcm * bdpt_direct_lt(st)
                                      : camera_conn_dvcm(st, z.dvcm, z.depth);
    float w_camera =
        geo_side ? mis(st.r * pdf_lp / pdf_nee) * (dvcm_z + z.dvc * mis(e.pdf_rev_w)) : 0.0f;
    if (L) bidir_nee_weights(s, ps, i, pick.light, unshadowed, w_light, w_camera);  // (linking)
    // (a restricted path, an R light: pt's two techniques and weights, bidir_ray_visibility.h)
    const bool pt_w = rays && bidir_rays_pt_nee(s, ps, i, pick.light);
    if (pt_w) w_camera = 0.0f;
    bidir_no_shadow_ratio(s, bs, i, w_light, w_camera);  // (objects without shadows)
    float w = 1.0f / (w_light + 1.0f + w_camera);
    float cos_i = fabsf(dot(ls.wi, z.h.ns));
    Vec3 c = z.beta * e.f * ls.le * (cos_i * w / pdf_light_w);
    if (st.moments && s.num_media == 0) {  // (media: at the shadow ray, bdpt_medium_finish_c)
        // a shadow-linked light: pt's channel where the segment is free (bidir_linked_moment)
        if (L && ps.shadow_mis)
            ps.shadow_mis[i] = bidir_nee_only(s, pick.light) && !ls.delta && geo_side
                                   ? bdpt_moment(c, c, bdpt_pt_factor(
                                                           1.0f, mis(e.pdf_fwd_w / pdf_light_w),
                                                           1.0f)).y
                                   : -1.0f;
        c = bdpt_moment(c, c, bdpt_pt_factor(w_light + 1.0f + w_camera, w_light, 1.0f));
    }
    if (!is_finite(c)) {
        ps.dropped[i] = 1;
        return;
    }
    if (unshadowed) {  // Cast Shadow off: no ray
        add_radiance(ps, i, c);
        return;
    }
    Vec3 target_n = ls.dist < kInf ? ls.n_light : vec3(0.0f);
    const Vec3 zp = terminator_origin(s, z.tri, z.h.p, z.h.ng, z.h.ns, ls.wi, time);
    if (ls.dist < kInf) {
        shadow_segment(zp, z.h.ng, ls.p_light, target_n, ls.wi, s.offset_scale, &ps.shadow_o[i],
                       &ps.shadow_d[i], &ps.shadow_tmax[i]);
    } else {
        ps.shadow_o[i] = offset_ray_origin(zp, z.h.ng, ls.wi, s.offset_scale);
        ps.shadow_d[i] = ls.wi;
        ps.shadow_tmax[i] = kInf;
    }
    ps.shadow_contrib[i] = c;
    ps.shadow_valid[i] = 1;
    if (s.num_media > 0) {  // its weight finished at the shadow test (bdpt_medium_stages.h)
        bs.shadow_wn[i] = w_camera;
        bs.shadow_wf[i] = pt_w ? 0.0f : w_light;  // (pt's weight: no flight factor)
        bs.shadow_kind[i] = (st.moments ? kMomOn | kMomFar | kMomOwnB : 0) |
                            (soft ? kConnNearFixed : 0);  // (F(c -> z) is in pdf_lp)
        if (st.moments) bs.shadow_mom[i] = Vec3{w_light, 1.0f, 1.0f};
        ps.shadow_medium[i] = dot(ls.wi, geo_side ? z.h.ng : z.h.ns) < 0.0f
                                  ? medium_across(s, z.tri, z.h.front, z.slot_medium)
                                  : z.slot_medium;
    }
}

// s >= 2: the unshadowed, MIS-weighted contribution of connecting z to cache vertex y (per unit
// estimator weight), and the BSDF-product target. Zero when the path would be too long.
struct Connection {
    Vec3 c;
    Vec3 dir;      // unit, z -> y
    float dist;
    float bsdf_target;
    float pt_factor;  // BdptSettings::moments: bdpt_pt_factor
    // scenes with media (bdpt_connect_medium): the weight's parts for the near (z) and far (y)
    // end's distance factors, the medium the segment starts in, ConnKind
    float wn = 0.0f, wf = 0.0f;
    int32_t medium = -1, kind = 0;
    float y_strand_cut = 0.0f;  // bdpt_curve.h strand_end_shorten
};

LANTERN_HD inline Connection bdpt_connect_medium(const SceneView& s, const BdptSettings& st,
                                                 const CameraVertex& z, const LightVertex& y,
                                                 bool* clobbered);  // bdpt_medium_stages.h


LANTERN_HD inline Connection bdpt_connect_in(const SceneView& s, const BdptSettings& st,
                                             const CameraVertex& z, const LightVertex& y,
                                             bool* clobbered) {
    Connection r{vec3(0.0f), vec3(0.0f), 0.0f, 0.0f, 0.0f};
    if (z.depth + 1 + y.length > st.max_depth) return r;
    Vec3 dir = y.p - z.h.p;
    float d2 = length_sq(dir);
    if (!(d2 > 0.0f) || !is_finite(d2)) return r;
    float dist = sqrtf(d2);
    dir = dir / dist;
    // each dot product once (the frames' third axes are the shading normals: the local
    // directions' z are dir.ns): light_side_agrees of (dir, z), view_side_agrees of (-dir, y)
    const Vec3 wi_z = z.frame.to_local(dir);
    const float dz_ng = dot(dir, z.h.ng), dy_ng = dot(-dir, y.ng);
    // (no terminator here: integrator/terminator.h lifts next-event rays to lights alone; pt
    // gathers the light of other vertices by BSDF sampling, on the facet's side, unlifted)
    if (!(material_corrects_view(*z.m) ? dz_ng > 0.0f : dz_ng * wi_z.z > 0.0f)) return r;
#ifndef __CUDACC__  // a light path's walk exit: lt's lobe f_adj (bdpt_sss.h)
    if (y.front & kLvSssExit) return bdpt_connect_sss_exit(s, z, y, dir, dist, wi_z);
#endif
    const float dy_ns = dot(-dir, y.ns);
    const bool y_geometric = material_view_geometric(s.materials[y.material]);
    if (!(y_geometric ? dy_ng > 0.0f : dy_ng * dy_ns > 0.0f)) return r;
    // y on a strand: the hair lobe's fiber measure, or a tube vertex, which faces z (bdpt_curve.h)
    const bool y_fiber = prim_is_strand(s, y.tri) && strand_fiber(s.materials[y.material]);
    if (prim_is_strand(s, y.tri) && !y_fiber && !(dy_ng > 0.0f)) return r;
    BsdfEval ez = bdpt_eval(*z.m, z.h.front, z.wo, wi_z, Transport::Radiance, z.h.coat_n,
                            z.frame, z.h.ng);
    if (is_black(ez.f)) return r;
#ifdef __CUDA_ARCH__
    MaterialScratch& scratch = *z.scratch;  // kOneScratch: z's material is not read again here
#else
    MaterialScratch scratch;
#endif
    const Material& my = material_at_point(s, y.material, [&] { return shade_point_lv(s, y, -dir); },
                                            scratch);
    *clobbered = &my == &scratch.m;
    Frame fy = Frame::from_normal_angle(y.ns, y.tangent_angle);
    const Vec3 coat_y = (my.tex_flags & kCoatNormal) || material_keeps_unbent_normal(my)
                            ? oct_decode(y.coat_n)
                            : vec3(0.0f, 0.0f, 1.0f);
    const Vec3 wo_y = fy.to_local(y.wo);
    const Vec3 wi_y = Vec3{dot(-dir, fy.s), dot(-dir, fy.t), dy_ns};
    BsdfEval ey = bdpt_eval(my, lv_front(y), wo_y, wi_y, Transport::Importance, coat_y, fy, y.ng);
    if (is_black(ey.f)) return r;
    // (strands: the fiber measure's cosines, bdpt_curve.h; the lobe's Importance f is the
    // fiber measure's, so y's adjoint factor is 1)
    const float cos_z_ng = light_arrival_cos(z.strand && !z.tube, z.tube, z.frame, z.h.ng, dir);
    const float cos_y_ng = vertex_cos(y_fiber, fy, y.ng, dir);
    const float cos_z_ns = fabsf(wi_z.z);
    float cos_yo_ns = fabsf(wo_y.z), cos_yo_ng = fabsf(dot(y.wo, y.ng));
    if (!(cos_yo_ng > 0.0f)) return r;
    if (y_fiber) cos_yo_ns = cos_yo_ng;
    // light side: f |dir.ns| with the adjoint shading-normal factor
    const float cos_y = cos_yo_ns * cos_y_ng / cos_yo_ng;
    const float inv_d2 = 1.0f / d2;
    float pdf_cam_a = ez.pdf_fwd_w * cos_y_ng * inv_d2;   // camera BSDF samples y
    float pdf_light_a = ey.pdf_fwd_w * cos_z_ng * inv_d2; // light BSDF samples z
    float y_dvcm, y_dvc;  // (for this pixel's count: pixel_conn.h)
    light_vertex_mis(st, y, &y_dvcm, &y_dvc);
    float w_light = mis(pdf_cam_a) * (y_dvcm + y_dvc * mis(ey.pdf_rev_w));
    float w_camera = mis(pdf_light_a) * (z.dvcm + z.dvc * mis(ez.pdf_rev_w));
    float w = 1.0f / (w_light + 1.0f + w_camera);
    r.c = z.beta * ez.f * y.beta * ey.f * (cos_z_ns * cos_y * inv_d2 * w);
    if (!is_finite(r.c)) r.c = vec3(0.0f);
    r.dir = dir;
    r.dist = dist;
    if (y_fiber) r.y_strand_cut = strand_end_shorten(s, y.tri, y.ng, dir, fy);
    r.bsdf_target = luminance(ez.f) * luminance(ey.f);
    if (st.moments) {  // pt's techniques: dpt0, dpt1 as dvc's parts (dvcm itself for y1)
        const float rev = mis(ey.pdf_rev_w), x = mis(pdf_cam_a);
        r.pt_factor = bdpt_pt_factor(w_light + 1.0f + w_camera, x * y.dpt0 * rev,
                                     x * (y.length == 1 ? y.dvcm : y.dpt1 * rev));
    }
    return r;
}

// Out of line on the device (LANTERN_DEVICE_NOINLINE): bdpt_camera_connect connects at four
// sites (own path, lvc, cis's candidates and its picks), each a copy in the camera shade kernel.
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline Connection bdpt_connect(const SceneView& s, const BdptSettings& st,
                                          const CameraVertex& z, const LightVertex& y) {
    bool clobbered = false;  // the cache vertex's material took z's scratch (kOneScratch)
    if (s.num_media > 0 && s.light_receivers) {  // y's set decided by z (bidir_linking_medium.h)
        const int ly = lv_pending_light(y.bary16, y.tri);
        if (ly >= 0 && !pt_light_links(s, ly, camera_vertex_set(s, z.tri)))
            return Connection{vec3(0.0f), vec3(0.0f), 0.0f, 0.0f, 0.0f};
    }
    const Connection r = s.num_media > 0 ? bdpt_connect_medium(s, st, z, y, &clobbered)
                                         : bdpt_connect_in(s, st, z, y, &clobbered);
    if (kOneScratch && clobbered && z.m && z.m == &z.scratch->m) camera_vertex_material(s, z);
    return r;
}

// mom_u >= 0 (moments in media): contrib stays RGB and becomes channels at its shadow ray, its
// unit contribution mom_u times it (bdpt_medium_finish_c)
LANTERN_HD inline void bdpt_queue_connection(const BdptState& bs, int i, const CameraVertex& z,
                                             const LightVertex& y, const Connection& c,
                                             Vec3 contrib, float offset_scale,
                                             float mom_u = -1.0f) {
    int j = bs.conn_n[i];
    if (j >= bs.conn_cap || is_black(contrib) || !is_finite(contrib)) return;
    int e = i * bs.conn_cap + j;
    shadow_segment(z.h.p, z.h.ng, y.p, y.ng, c.dir, offset_scale, &bs.conn_o[e], &bs.conn_d[e],
                   &bs.conn_tmax[e]);
    if (c.y_strand_cut > 0.0f)  // y on a strand, seen from its fiber's far side (bdpt_curve.h)
        bs.conn_tmax[e] = fmaxf(bs.conn_tmax[e] - c.y_strand_cut, 0.0f);
    bs.conn_c[e] = contrib;
    bs.conn_n[i] = j + 1;
    if (bs.conn_wn) {  // scenes with media (bdpt_medium_stages.h)
        bs.conn_wn[e] = c.wn;
        bs.conn_wf[e] = c.wf;
        bs.conn_kind[e] = c.kind | (mom_u >= 0.0f ? kMomOn | kMomFar | kMomG : 0);
        bs.conn_mom[e] = Vec3{c.pt_factor, 0.0f, mom_u};
        bs.conn_medium[e] = c.medium;
    }
}

// A candidate the CPU keeps for its picks: what bdpt_queue_connection reads of its Connection.
struct KeptCandidate {
    float cx, cy, cz, dx, dy, dz, pt_factor;
    float wn, wf;          // scenes with media (Connection)
    int32_t medium, kind;
    float y_strand_cut;    // Connection
};

// cis's candidates per camera vertex at most (BdptSettings::candidates); SceneView's
// cis_candidates holds 2 x kCisCandidates floats per GPU thread.
constexpr int kCisCandidates = 64;

// A uniform index in [0, size) from 32 random bits: an integer multiply-shift (Lemire 2019), so
// that every vertex of a cache of up to 2^31 is reachable, each by floor or ceil(2^32 / size)
// words. (A 24-bit float times the size, int(u * size), reaches at most 2^24 of them.)
LANTERN_HD inline int32_t cache_pick(uint32_t bits, int32_t size) {
    return int32_t((uint64_t(bits) * uint64_t(uint32_t(size))) >> 32);
}

// Connections of camera vertex z to the cache: bdpt (own light path), lvc (uniform) or cis
// (resampled). Each queued shadow ray carries its estimator weight. Out of line on the device
// (LANTERN_DEVICE_NOINLINE): one copy for the surface and the medium vertex.
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline void bdpt_camera_connect(const SceneView& s, const BdptState& bs,
                                           const BdptSettings& st, const LightCache& cache,
                                           const CameraVertex& z, int i, int64_t path) {
    bs.conn_n[i] = 0;
    // every cache vertex is at least one segment from its light: past max_depth from here;
    // a pixel of N = 0 pays for no candidates (pixel_conn.h)
    if (cache.size <= 0 || z.depth + 2 > st.max_depth || st.connections <= 0) return;
    // moments in media: channels made at the shadow ray (bdpt_medium_finish_c)
    const bool media = s.num_media > 0;
    auto mom_u = [&](float u) { return st.moments && media ? u : -1.0f; };
    if (st.mode == kBdptOwnPath) {
        for (int k = cache.path_offset[path]; k < cache.path_offset[path + 1]; ++k) {
            const LightVertex& y = cache.v[cache.path_vertex[k]];
            Connection c = bdpt_connect(s, st, z, y);
            const Vec3 contrib = st.moments && !media ? bdpt_moment(c.c, c.c, c.pt_factor) : c.c;
            bdpt_queue_connection(bs, i, z, y, c, contrib, s.offset_scale, mom_u(1.0f));
        }
        return;
    }
    // own stream per (path, depth), so that the three camera-pass stages never share one
    Rng rng = Rng::hashed(Rng::for_camera(st.seed ^ 0x434F4E4Eull ^ (uint64_t(z.depth) << 40),
                                          st.iteration, st.spp_per_iteration, path));
    const float size = float(cache.size);
    auto pick = [&](uint32_t bits) { return cache_pick(bits, cache.size); };
    if (st.mode == kLvcUniform) {
        const float weight = size / float(st.connections) * st.inv_light_paths;
        for (int j = 0; j < st.connections; ++j) {
            const LightVertex& y = cache.v[pick(rng.next())];
            Connection c = bdpt_connect(s, st, z, y);
            Vec3 contrib = c.c * weight;
            if (st.moments && !media) contrib = bdpt_moment(contrib, contrib, c.pt_factor);
            bdpt_queue_connection(bs, i, z, y, c, contrib, s.offset_scale, mom_u(1.0f));
        }
        return;
    }
    // cis: M uniform candidates with w_j = p-hat(x_j) |C|, N picks proportional to w_j, each
    // carrying W / (N L) with W = (1 / p-hat(y)) (1/M) sum_j w_j  (DESIGN.md)
    constexpr int kMaxCandidates = kCisCandidates;
#ifdef __CUDA_ARCH__
    // a GPU thread keeps (index, p-hat) per candidate and connects the picked ones again (the
    // same arithmetic, so the same connection): 64 connections would be 2 KB of its stack
    constexpr int kKept = 1;
#else
    constexpr int kKept = kMaxCandidates;  // the CPU keeps them: each is evaluated once
#endif
    const int m = min_int(st.candidates, kMaxCandidates);
    // per candidate p-hat and its pick count; the cumulative sums are summed again in the same
    // order (the same bits), and a GPU thread draws the indices again from a copy of the
    // stream: it holds 320 bytes here, not 1,024 (the CPU keeps the indices with the
    // connections)
    [[maybe_unused]] Rng rng_candidates = rng;
#ifdef __CUDA_ARCH__
    // and those 320 bytes are its column of SceneView::cis_candidates ([candidate][thread],
    // as program registers): p-hats, then the pick counts as floats (exact up to 64)
    const uint32_t t = launch_thread(s.cis_candidates, s.device_threads);
    const ProgramRegs p_hats{s.cis_candidates + t, s.device_threads};
    const ProgramRegs count = p_hats + kMaxCandidates;
#else
    float p_hats[kMaxCandidates];
    uint8_t count[kMaxCandidates];  // of st.connections <= 64 picks (Session checks)
#endif
    KeptCandidate cand[kKept];  // plain floats: a Connection array would be zero-filled
    [[maybe_unused]] int idx[kKept];
    float sum = 0.0f;
    for (int j = 0; j < m; ++j) {
        const int index = pick(rng.next());
        const Connection c = bdpt_connect(s, st, z, cache.v[index]);
        if constexpr (kKept > 1) {
            cand[j] = KeptCandidate{c.c.x, c.c.y, c.c.z, c.dir.x, c.dir.y, c.dir.z, c.pt_factor,
                                    c.wn, c.wf, c.medium, c.kind, c.y_strand_cut};
            idx[j] = index;
        }
        float p_hat = st.target == kTargetBsdf ? (is_black(c.c) ? 0.0f : c.bsdf_target)
                                               : luminance(c.c);
        if (!(p_hat > 0.0f) || !is_finite(p_hat)) p_hat = 0.0f;
        p_hats[j] = p_hat;
        sum += p_hat * size;
    }
    if (!(sum > 0.0f) || !is_finite(sum)) return;
    for (int j = 0; j < m; ++j) count[j] = 0;
    for (int n = 0; n < st.connections; ++n) {
        float u = rng.uniform() * sum;
        int j = 0;
        float cdf = p_hats[0] * size;  // the first loop's running sum, term for term
        while (j < m - 1 && !(u < cdf)) cdf += p_hats[++j] * size;
        while (j > 0 && p_hats[j] == 0.0f) --j;  // never a zero-weight candidate
        ++count[j];
    }
    // the same candidate picked twice shares one shadow ray (same segment, same visibility)
    for (int j = 0; j < m; ++j) {
        int index;
        if constexpr (kKept > 1)
            index = idx[j];
        else
            index = pick(rng_candidates.next());  // every j, in order: the same stream
        const LightVertex& y = cache.v[index];
        const float p_hat = p_hats[j];
        if (count[j] == 0 || !(p_hat > 0.0f)) continue;
        float w_ris = st.naive_ris ? size : (sum / float(m)) / p_hat;
        float weight = w_ris * float(count[j]) / float(st.connections) * st.inv_light_paths;
        Connection c;
        if constexpr (kKept > 1) {
            c.c = vec3(cand[j].cx, cand[j].cy, cand[j].cz);
            c.dir = vec3(cand[j].dx, cand[j].dy, cand[j].dz);
            c.pt_factor = cand[j].pt_factor;
            c.wn = cand[j].wn;
            c.wf = cand[j].wf;
            c.medium = cand[j].medium;
            c.kind = cand[j].kind;
            c.y_strand_cut = cand[j].y_strand_cut;
        } else {
            c = bdpt_connect(s, st, z, y);
        }
        Vec3 contrib = c.c * weight;
        // (moments: the unit contribution is the uniform pick's, size / (N L))
        const float uniform = size / float(st.connections) * st.inv_light_paths;
        if (st.moments && !media) contrib = bdpt_moment(contrib, c.c * uniform, c.pt_factor);
        bdpt_queue_connection(bs, i, z, y, c, contrib, s.offset_scale,
                              mom_u(weight > 0.0f ? uniform / weight : 0.0f));
    }
}

LANTERN_HD inline bool bdpt_sss_choose(const SceneView& s, const PathState& ps,
                                       const BdptState& bs, CameraVertex& z, int i,
                                       Rng& rng);  // subsurface: bdpt_sss.h

// A camera vertex's next event (s = 1) and connections (s >= 2), queued: z and the slot's
// stream for the events stage (bdpt_camera_events.h), which makes them after this stage. Its
// next event draws two uniform2 (the light pick's, the light sample's) whatever it finds: the
// caller's stream skips them (bdpt_skip_camera_events, bdpt_common.h).
LANTERN_HD inline void bdpt_queue_camera_events(const BdptState& bs, int i, const CameraVertex& z,
                                                const Rng& rng) {
    bs.cam_z[i] = z;
    bs.cam_rng[i] = rng;
    bs.cam_on[i] = 1;
}

// Camera-path shading after the segment's emission (bdpt_camera_emission, a stage before this
// one in scenes without media): the segment's media, then at a surface its emission, the next
// event and connections queued for the events stage (bdpt_camera_events.h), and the next
// direction. No ray and no connection here: on a GPU the stages are kernels of their own
// (each with its own stack: issue 30); sr (a StageRaysRef) serves only the weight of a
// soft-falloff disk hit inside a medium segment (soft_light_medium.h: the route's flights
// from the centre, which the GPU does not start, so there it traces nothing). L: linking's
// tests compiled in (bidir_links_on).
template <bool L = true, class SR>
LANTERN_HD inline void bdpt_camera_shade(const SceneView& s, const PathState& ps,
                                         const BdptState& bs, const BdptSettings& st_all,
                                         const LightCache& cache, int i, int64_t path,
                                         const SR& sr) {
    const BdptSettings st = camera_settings(st_all, pixel_conn_of_slot(st_all, bs, i));
    ps.shadow_valid[i] = 0;
    ps.alive[i] = 0;
    bs.conn_n[i] = 0;
    bs.cam_on[i] = 0;
    const int tri = ps.hit_prim[i];
    const Vec3 d = ps.ray_d[i];
    float t_hit = ps.hit_t[i];
    const bool media = s.num_media > 0;
    // one camera vertex and one scratch for the whole call, the medium vertex's too (passed
    // down): on a GPU thread each is a frame under every call chain of the shade kernel.
    CameraVertex z;
    MaterialScratch scratch;  // z.m points here when the material is resolved
    z.scratch = &scratch;
    // the piece's flight, lights crossed, a medium vertex, a boundary passed
    if (media && bdpt_camera_medium_segment(s, ps, bs, st, cache, i, path, z, sr)) return;
    if (tri < 0) return;
    // ray visibility by kind: a bounce ray meeting an R surface (bidir_ray_visibility.h)
    if (L && s.tri_rays && ps.depth[i] > 1 && bidir_tri_restricted(s, tri) &&
        bdpt_camera_meets_restricted(s, ps, st, i, tri, path))
        return;
    z.strand = prim_is_strand(s, tri);  // a triangle's or a strand's surface (pt_curve.h)
    z.h = s.motion.num_objects > 0 && tri < s.num_triangles  // motion blur: bdpt_motion.h
              ? surface_moved_at(s, tri, ps.hit_uv[i], d, bdpt_time(st, path))
              : surface_of_hit(s, tri, ps.hit_uv[i], ps.ray_o[i], d, ps.hit_t[i],
                               s.motion.curves ? bdpt_time(st, path) : 0.0f);
    z.tri = tri;
    z.uv = ps.hit_uv[i];
    z.wo_w = -d;
    z.m = &camera_vertex_material(s, z);
    z.tube = z.strand && !strand_fiber(*z.m);  // (bdpt_curve.h)
    z.depth = ps.depth[i];
    if (media) z.slot_medium = ps.medium[i];
    z.frame = z.h.frame();
    const float cos_in = vertex_cos(z.strand && !z.tube, z.frame, z.h.ng, d);
    if (!(cos_in > 0.0f) || !(t_hit > 0.0f)) return;
    // MIS update for the new vertex (an orthographic camera's first vertex has no distance term)
    float dvcm = bs.dvcm[i], dvc = bs.dvc[i];
    Vec3 o_prev = ps.ray_o[i];
    if (media) {  // the segment from the last vertex, through its pieces (bdpt_medium.h)
        o_prev = ps.prev_p[i];
        t_hit = length(z.h.p - o_prev);
        bdpt_medium_hit_update(dvcm, dvc, t_hit, cos_in, bdpt_seg_load(bs, i),
                               !(z.depth == 1 && s.camera.orthographic));
    } else {
        if (!(z.depth == 1 && s.camera.orthographic)) dvcm *= mis(t_hit * t_hit);
        dvcm /= mis(cos_in);
        dvc /= mis(cos_in);
    }
    // emission of a mesh light at the hit
    const Material& m = *z.m;
    const int li = s.tri_light ? s.tri_light[tri] : -1;
    if (!is_black(m.emission) && (!L || bidir_emission_counts(s, ps, i, li))) {  // (linking)
        float w = 1.0f, nee = 0.0f;
        if (z.depth > 1 && li >= 0) {
            const Light& l = s.lights[li];
            const float pick = s.light_tree_on ? light_pick_pmf(s, li, ps.prev_p[i], ps.prev_n[i])
                                               : l.nee_pdf;  // at the previous vertex
            // (a moving emitter: its densities at the path's time, where it was hit)
            const float time = bdpt_emitter_time(s, st, path);
            float pdf_direct = pick * light_pdf_w_at(s, l, o_prev, d, t_hit, z.h.ng, time) *
                               cos_in / (t_hit * t_hit);
            float pdf_emit = l.emit_pick_pdf * emission_pdf(s, l, z.h.ng, -d, time).pdf_emit;
            const float dvc_e = z.depth == 2 ? dvc * bdpt_direct_lt(st) : dvc;  // (lt_direct)
            w = 1.0f / (1.0f + mis(pdf_direct) * dvcm + mis(st.r * pdf_emit) * dvc_e);
            nee = mis(pdf_direct) * dvcm;
            if (L && bidir_rays_on(s) && bidir_rays_pt_weight(s, ps, i, li))  // (ray kinds)
                w = bidir_rays_emission_weight(s, ps, i, li, o_prev, d, t_hit, z.h.ng, time);
        }
        // the camera's direct view of a Principled emitter: under its coat and sheen
        // (principled_emission_through; light it casts stays undimmed)
        const Vec3 le = z.depth <= 1 ? m.emission * principled_emission_through(m, dot(d, z.h.ng))
                                     : m.emission;
        Vec3 c = ps.throughput[i] * le * w;
        if (st.moments) c = bdpt_moment(c, c, bdpt_pt_factor(1.0f / w, 1.0f, nee));
        add_radiance(ps, i, c);
    }
    if (z.depth >= st.max_depth) return;
    z.wo = z.frame.to_local(-d);
    z.ng_l = z.frame.to_local(z.h.ng);
    z.beta = ps.throughput[i];
    z.dvcm = dvcm;
    z.dvc = dvc;
    // (light from under the face too: integrator/terminator.h; as pt's, a lamp without
    // shadows too, bidir_linking.h)
    z.n_pick = (terminator_cutoff(s, tri) > 0.0f || (L && s.light_rays)) &&
                       dot(z.h.ns, z.h.ng) < 0.99999f
                   ? vec3(0.0f)
                   : light_pick_normal(s, tri, z.h.ng);
    Rng rng = ps.rng[i];
    if (s.has_subsurface && bdpt_sss_choose(s, ps, bs, z, i, rng)) return;  // under the surface
    // next event and connections: the events stage's (bdpt_camera_events.h), from z and this
    // stream; here their draws are skipped
    if (!material_is_delta(m)) bdpt_queue_camera_events(bs, i, z, rng);
    bdpt_skip_camera_events(rng);
    // continue
    Vec2 u_dir = rng.uniform2();
    BsdfSample b = material_sample(m, z.h.front, z.wo, Vec3{u_dir.x, u_dir.y, rng.uniform()},
                                   Transport::Radiance, z.h.coat_n, z.ng_l);
    Vec3 wi = z.frame.to_world(b.wi);
    if (b.valid && light_side_agrees(m, wi, z.h.ng, z.h.ns) && (b.delta || b.pdf_fwd_w > 0.0f)) {
        Vec3 beta = z.beta * b.weight;
        if (russian_roulette(beta, z.depth, st.rr_depth, rng) && max_component(beta) > 0.0f &&
            is_finite(beta)) {
            dvcm = camera_conn_dvcm(st, dvcm, z.depth);  // (N = 0: no connection's term)
            bdpt_scatter_update(dvcm, dvc, b,
                                light_arrival_cos(z.strand && !z.tube, z.tube, z.frame, z.h.ng, wi));
            ps.throughput[i] = beta;
            ps.depth[i] = z.depth + 1;
            bs.dvcm[i] = dvcm;
            bs.dvc[i] = dvc;
            set_next_ray(ps, i, z.h.p, z.h.ng, wi, b.delta ? 0.0f : b.pdf_fwd_w,
                         s.offset_scale);
            if (L) pt_set_receiver(s, ps, i, tri);  // light linking: this vertex receives (s = 0)
            if (L) bidir_set_ray_kind(s, ps, i, pt_sampled_kind(m, b.lobe, wi, z.h.ng));
            ps.prev_p[i] = z.h.p;  // (and for a soft-falloff light's weight: its normal)
            bs.prev_ng[i] = z.h.ng;
            if (s.light_tree_on || media) ps.prev_n[i] = z.n_pick;
            if (media) {
                if (dot(wi, z.h.ng) < 0.0f)  // through the surface
                    ps.medium[i] = medium_across(s, tri, z.h.front, ps.medium[i]);
                bdpt_seg_store(bs, i, medium_segment_begin(false));
            }
        }
    }
    ps.rng[i] = rng;
}

}  // namespace lantern
