// Random-walk subsurface scattering on the bidirectional integrators' camera paths (bdpt, lvc,
// cis; docs/subsurface.md, "Bidirectional integrators"). pt's model and walk (pt_sss.h): at a
// hit a camera path goes under the surface with probability P (bdpt_sss_choose, in the camera
// shade stage), the walk stage walks it to an exit (sss_walk_path), and the exit stage shades
// the exit as a camera vertex with a white Lambert lobe about the outward normal: next-event
// estimation, connections to the cache and a cosine continuation.
//
// MIS. The walk is sampled, never evaluated. Among the techniques whose camera sub-path holds
// the walk's exit the exit vertex starts its MIS quantities afresh as a camera does (camera
// vertices walk at every depth, as pt's), so that set's weights sum to 1 within it. Light
// paths walk too (Skin: bdpt_sss_light.h), and the techniques whose light sub-path holds the
// walk form a second set, which the exit's dVCM carries (lf D_front / r, made in the walk
// stage; 0 where light paths do not walk there: the sets are split as in bdpt_sss_light.h).
// The surface branch's probability 1 - P is left out of every technique's density (a stand-in
// of 1 on both sides: the weights stay a partition of unity).
#pragma once

#include "integrator/bdpt_camera.h"
#include "integrator/bdpt_motion.h"

namespace lantern {

constexpr uint8_t kAliveSssExit = 3;  // PathState::alive: the exit stage has this slot

// At a camera vertex (after emission, before next-event estimation): true when the path goes
// under the surface (the walk stage takes it); else z.beta and the slot's throughput carry
// 1 / (1 - P) and shading goes on. Out of line on the device (LANTERN_DEVICE_NOINLINE): in the
// camera shade kernel (camera_chunk #2.2, at the stack cap) a call measured 2,016 B, inline
// 2,032 B with more spills (docs/cuda_backend.md).
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline bool bdpt_sss_choose(const SceneView& s, const PathState& ps,
                                       const BdptState& bs, CameraVertex& z, int i, Rng& rng) {
    if (z.strand || !(z.m->subsurface > 0.0f) || z.tri >= s.num_triangles) return false;
    if (pt_sss_choose(ps, i, *z.m, z.wo, z.ng_l, rng)) {
        ps.rng[i] = rng;
        bs.dvcm[i] = z.dvcm;  // the camera path at the entry: D_front (bdpt_sss_walk)
        bs.dvc[i] = z.dvc;
        return true;
    }
    z.beta = ps.throughput[i];
    return false;
}

// The walk stage: a slot with alive == kAliveSss walks from its hit; where the walk leaves,
// the slot keeps the exit (triangle, barycentrics, the direction that found it, throughput,
// depth) for the exit stage, alive kAliveSssExit; otherwise it ends. kind: the RayKind
// of its rays; time: its camera path's shutter time (bdpt_time; 0 where nothing moves).
//
// The split (bdpt_sss_light.h): the exit's dVCM = lf D_front / r, with D_front the camera
// path's dVCM + dVC pdf_rev at the entry (pdf_rev: the light exit's lobe, lt_sss_exit_pdf, of
// the view given the walk's last direction) and r from the entry's view and the walk's first
// direction, which sss_walk_path draws first from the path's stream: drawn here again from a
// copy (the same u, so the same direction; pt_sss.h keeps its bits). 0: no walk's first
// direction. Out of line on the device (LANTERN_DEVICE_NOINLINE): its surface and material stay
// out of the walk kernel's frame, which holds the walk's ray query (as pt's sss_walk_start).
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline float bdpt_sss_camera_exit_dvcm(const SceneView& s, const PathState& ps,
                                                  const BdptState& bs, const BdptSettings& st,
                                                  int i, float time, Rng rng) {
    const int tri = ps.hit_prim[i];
    const Vec2 uv = ps.hit_uv[i];
    const Vec3 d = ps.ray_d[i];
    const SurfaceHit h = surface_at_time(s, tri, uv, d, time);  // as sss_walk_path's
    MaterialScratch scratch;
    const Material& m = sss_entry_material(s, h, tri, uv, d, scratch);
    const Frame frame = sss_entry_frame(h, -d);
    Vec3 wi_l;
    if (!sss_entry(m, frame.to_local(-d), rng.uniform2(), &wi_l)) return 0.0f;
    const Vec3 out = -frame.to_world(wi_l);  // the light's last walk direction, outward
    const float r = bdpt_sss_ratio(m, h, out, -d);
    if (!(r > 0.0f)) return 0.0f;
    const Frame gf = Frame::from_normal(dot(h.ng, d) < 0.0f ? h.ng : -h.ng);  // (faces -d)
    const float pdf_rev = lt_sss_exit_pdf(m, gf.to_local(out), gf.to_local(-d));
    const int depth = ps.depth[i];
    const float dvcm = depth == 1 ? bs.dvcm[i] : camera_conn_dvcm(st, bs.dvcm[i], depth);
    const float e = (dvcm + bs.dvc[i] * mis(pdf_rev)) / r;
    return is_finite(e) ? e : 0.0f;
}

template <class Rays, class Kind>
LANTERN_HD inline void bdpt_sss_walk(const SceneView& s, const Rays& rays, Kind kind,
                                     const PathState& ps, const BdptState& bs,
                                     const BdptSettings& st, int i, float time) {
    if (ps.alive[i] != kAliveSss) return;
    ps.alive[i] = 0;
    Rng rng = ps.rng[i];
    const float e = bdpt_sss_split_on(st) && s.sss_adjoint_control != 3
                        ? bdpt_sss_camera_exit_dvcm(s, ps, bs, st, i, time, rng)
                        : 0.0f;
    sss_walk_path(s, rays, kind, ps.hit_prim[i], ps.hit_uv[i], ps.ray_d[i],
                  ps.throughput[i], ps.depth[i], rng, time,
                  [&](int tri, Vec2 uv, Vec3 dir, Vec3, Vec3, Vec3, Vec3 beta, int depth) {
                      // the exit's dVCM (lf: the light can walk here), dVC 0
                      bs.dvcm[i] = bdpt_sss_light_walks(s, tri) ? e : 0.0f;
                      bs.dvc[i] = 0.0f;
                      ps.hit_prim[i] = tri;
                      ps.hit_uv[i] = uv;
                      ps.ray_d[i] = dir;
                      ps.throughput[i] = beta;
                      ps.depth[i] = depth;
                      ps.alive[i] = kAliveSssExit;
                  });
    ps.rng[i] = rng;
}

// The exits' lobe: white Lambert (pt_sss_exit's). The exit stage reads it from the executor's
// memory (Wavefront::sss_white), not a GPU thread's stack.
inline Material sss_exit_white() {
    Material white{};
    white.type = kMaterialDiffuse;
    white.base_color = vec3(1.0f);
    return white;
}

// The exit stage's camera vertex z at the walk's exit (the slot's triangle, barycentrics and the
// walk's last direction), its lobe white (sss_exit_white). Out of line on the device
// (LANTERN_DEVICE_NOINLINE): the surface's locals stay out of the exit kernel's frame.
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline void bdpt_sss_exit_vertex(const SceneView& s, const PathState& ps,
                                            const BdptState& bs, const BdptSettings& st_all,
                                            int i, int64_t path, const Material& white,
                                            CameraVertex& z) {
    z = CameraVertex{};
    z.tri = ps.hit_prim[i];
    z.uv = ps.hit_uv[i];
    z.h = bdpt_surface(s, st_all, path, z.tri, z.uv, ps.ray_d[i]);  // (at its time: motion)
    z.h.ng = -z.h.ng;  // the surface's normals face back along the walk: out is along it
    z.h.ns = -z.h.ns;
    z.h.front = !z.h.front;
    z.h.tangent_angle = 0.0f;
    z.h.coat_n = Vec3{0.0f, 0.0f, 1.0f};
    z.frame = Frame::from_normal(z.h.ns);
    z.wo = Vec3{0.0f, 0.0f, 1.0f};  // (a Lambert's reverse pdf; dVC = 0 leaves it unread)
    z.wo_w = z.h.ns;
    z.ng_l = z.frame.to_local(z.h.ng);
    z.m = &white;
    z.depth = ps.depth[i];
    // media (pt's rule, pt_sss.h): the walk leaves into the medium its path arrived in at the
    // entry, the slot's, which it kept; next event, connections and the continuation start there
    if (s.num_media > 0) {
        if (s.sss_adjoint_control == 5) ps.medium[i] = -1;  // (tests' control: into vacuum)
        z.slot_medium = ps.medium[i];
    }
    z.beta = ps.throughput[i];
    z.dvcm = bs.dvcm[i];  // the light-held set's techniques (bdpt_sss_walk), 0 where none
    z.dvc = 0.0f;
    // (light from under the face too: integrator/terminator.h; a lamp without shadows too, as
    // pt_sss_exit's and bdpt_camera_shade's)
    z.n_pick = (terminator_cutoff(s, z.tri) > 0.0f || s.light_rays) &&
                       dot(z.h.ns, z.h.ng) < 0.99999f
                   ? vec3(0.0f)
                   : light_pick_normal(s, z.tri, z.h.ng);
}

// The exit stage: the exit as a camera vertex with a white Lambert lobe (pt_sss_exit's), its
// dVCM the walk stage's, dVC 0 (above); next-event estimation, connections, a cosine
// continuation. The vertex is the slot's BdptState::cam_z (the events stage, which ran before,
// is done with it): off a GPU thread's stack, as the events stage's.
template <class SR>
LANTERN_HD inline void bdpt_sss_exit(const SceneView& s, const PathState& ps, const BdptState& bs,
                                     const BdptSettings& st_all, const LightCache& cache, int i,
                                     int64_t path, const SR& sr, const Material& white) {
    if (ps.alive[i] != kAliveSssExit) return;
    ps.alive[i] = 0;
    const BdptSettings st = camera_settings(st_all, pixel_conn_of_path(s, st_all, path));
    CameraVertex& z = bs.cam_z[i];
    bdpt_sss_exit_vertex(s, ps, bs, st_all, i, path, white, z);
    MaterialScratch scratch;  // the cache vertices' materials (kOneScratch)
    z.scratch = &scratch;
    const bool media = s.num_media > 0;
    if (z.depth >= st.max_depth) return;
    Rng rng = ps.rng[i];
    bdpt_camera_nee(s, ps, bs, st, z, i, rng, sr, path);
    // (a restricted path: pt's techniques alone, bidir_ray_visibility.h; the walk is no
    // segment: its rays see every surface, as pt's, and the exit lies at the camera-side end of
    // its continuation, so an exit on an R surface restricts nothing)
    if (!bidir_restricted(s, ps, i)) bdpt_camera_connect(s, bs, st, cache, z, i, path);
    float pdf_w = 0.0f;
    const Vec3 wi = z.frame.to_world(sample_cosine_hemisphere(rng.uniform2(), &pdf_w));
    Vec3 beta = z.beta;
    if (pdf_w > 0.0f && dot(wi, z.h.ng) > 0.0f &&
        russian_roulette(beta, z.depth, st.rr_depth, rng) && max_component(beta) > 0.0f &&
        is_finite(beta)) {
        ps.throughput[i] = beta;
        ps.depth[i] = z.depth + 1;
        bs.dvc[i] = mis(dot(wi, z.h.ng) / pdf_w) * z.dvcm;  // bdpt_scatter_update, dVC = 0
        bs.dvcm[i] = mis(1.0f / pdf_w);
        set_next_ray(ps, i, z.h.p, z.h.ng, wi, pdf_w, s.offset_scale);
        pt_set_receiver(s, ps, i, z.tri);  // light linking: the exit receives (s = 0), as pt's
        bidir_set_ray_kind(s, ps, i, kRayKindSubsurface);  // ray kinds: a diffuse bounce, as pt's
        ps.prev_p[i] = z.h.p;
        bs.prev_ng[i] = z.h.ng;
        if (s.light_tree_on || media) ps.prev_n[i] = z.n_pick;
        if (media) bdpt_seg_store(bs, i, medium_segment_begin(false));  // (above the surface)
    }
    ps.rng[i] = rng;
}

// s >= 2 to a light path's walk exit y (bdpt_sss_light.h): y's lobe is lt's f_adj (wo holds the
// walk's last direction d), its density of z the exit's continuation's (lt_sss_exit_pdf); y's
// dVCM is D_back (bdpt_sss_light.h), times r(w) here: the techniques where z samples y and the
// camera walks; y's dVC 0. z's side checked by bdpt_connect_in.
LANTERN_HD inline Connection bdpt_connect_sss_exit(const SceneView& s, const CameraVertex& z,
                                                   const LightVertex& y, Vec3 dir, float dist,
                                                   Vec3 wi_z) {
    Connection r{vec3(0.0f), vec3(0.0f), 0.0f, 0.0f, 0.0f};
    const Vec3 w = -dir;  // at y, towards z
    const float cos_y = dot(w, y.ng);
    if (!(cos_y > 0.0f)) return r;
    const BsdfEval ez = bdpt_eval(*z.m, z.h.front, z.wo, wi_z, Transport::Radiance, z.h.coat_n,
                                  z.frame, z.h.ng);
    if (is_black(ez.f)) return r;
    MaterialScratch scratch;
    const Material& my = material_at_point(s, y.material, [&] { return shade_point_lv(s, y, w); },
                                           scratch);
    SurfaceHit x;
    x.p = y.p;
    x.ng = y.ng;
    x.ns = y.ns;
    x.front = (y.front & 1) != 0;
    x.tangent_angle = y.tangent_angle;
    if ((my.tex_flags & kCoatNormal) || material_keeps_unbent_normal(my))
        x.coat_n = oct_decode(y.coat_n);
    const Vec3 f = lt_sss_exit_f(my, x, y.wo, w, s.sss_adjoint_control);
    if (is_black(f)) return r;
    const Frame gf = Frame::from_normal(y.ng);
    const float pdf_y_w = lt_sss_exit_pdf(my, gf.to_local(y.wo), gf.to_local(w));
    const float cos_z_ng = light_arrival_cos(z.strand && !z.tube, z.tube, z.frame, z.h.ng, dir);
    const float inv_d2 = 1.0f / (dist * dist);
    const float w_camera = mis(pdf_y_w * cos_z_ng * inv_d2) * (z.dvcm + z.dvc * mis(ez.pdf_rev_w));
    // the camera-held set: z samples y, walks (r) and meets the light path beyond (y's dVCM)
    const float w_light =
        mis(ez.pdf_fwd_w * cos_y * inv_d2) * bdpt_sss_ratio(my, x, y.wo, w) * y.dvcm;
    const float wt = 1.0f / (1.0f + w_light + w_camera);
    r.c = z.beta * ez.f * y.beta * f * (fabsf(wi_z.z) * cos_y * inv_d2 * wt);
    if (!is_finite(r.c)) r.c = vec3(0.0f);
    r.dir = dir;
    r.dist = dist;
    r.bsdf_target = luminance(ez.f) * luminance(f);
    return r;
}

}  // namespace lantern
