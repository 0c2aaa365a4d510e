// The adjoint random walk on the light tracer's paths (integrator lt; docs/subsurface.md, "The
// adjoint walk"). The camera side (pt_sss.h) enters a material with subsurface at x_i through a
// rough refraction q(wi | wo) with the weight W_e(wo) of the view (sss_entry_weight), walks, and
// leaves at x_o through a white Lambert lobe. A light path samples the same transport from the
// other end: at x_o (lt_sss_choose, in lt_shade) it goes under the surface with probability P
// (else it stays a surface vertex with 1 / (1 - P)), enters by a cosine about the inward
// geometric normal (weight 1: the Lambert lobe's 1 / pi times the area measure's cosine over the
// cosine's density; the incoming side carries the shading normal's adjoint factor), walks the
// medium backwards (the same walk: distances, transmittance, Henyey-Greenstein phases are
// reciprocal) and where it reaches x_i (last direction d, outward) shades the exit with the
// entry lobe evaluated in reverse:
//
//     f_adj(w) = W_e(w) q(-d | w) / |d . n_g(x_i)|      (lt_sss_exit_f)
//
// the 1 / |cos| turning the walk's arrival density at x_i into area measure. The exit connects
// to the camera (the splat) and continues by half a cosine, half the refraction out
// (lt_sss_exit_sample), weight f_adj |cos| / pdf. lt renders Skin only: session.cpp hands Random
// Walk to pt (heavy tails: short renders read low; docs/subsurface.md). Neither the walk
// nor its exit counts a segment (as the camera side: D41).
#pragma once

#include "integrator/lt_ray_visibility.h"
#include "integrator/pt_sss.h"

namespace lantern {

// ---- At a light vertex on a material with subsurface (h facing the light, after the camera
// connection): true when the path goes under the surface (alive = kAliveSss; lt_sss_walk takes
// it), false when it stays a surface vertex; either way the throughput carries 1 / the branch's
// probability. Where the vertex cannot continue (max_depth) the walk is the only branch left:
// its exit still connects to the camera at the same depth. ----
LANTERN_HD inline bool lt_sss_choose(const SceneView& s, const PathState& ps,
                                     const PtSettings& st, int i, const Material& m,
                                     const SurfaceHit& h, Vec3 wo_w, float cos_o_ns,
                                     float cos_o_ng, int depth) {
    if (!(m.subsurface > 0.0f) || ps.hit_prim[i] >= s.num_triangles) return false;
    // the camera side's Lambert exit takes light from above its shading normal only
    const float mu = dot(wo_w, h.ns);
    if (!(mu > 0.0f)) return false;
    const float p = depth + 2 > st.max_depth ? 1.0f : sss_pick_prob(m, mu);
    if (!(p > 0.0f)) return false;
    Rng rng = ps.rng[i];
    const bool walk = rng.uniform() < p;
    ps.rng[i] = rng;
    if (walk) {  // (Veach's adjoint shading-normal factor for the incoming side)
        ps.throughput[i] = ps.throughput[i] * (cos_o_ns / (cos_o_ng * p));
        ps.alive[i] = kAliveSss;
        return true;
    }
    ps.throughput[i] = ps.throughput[i] * (1.0f / (1.0f - p));
    return false;
}

// ---- The exit's lobe f_adj(w) at x_i (x facing out, along the walk's last direction d): the
// camera side's entry weight and density for the view w, over |d . n_g|; 0 where the camera
// could not have entered (w under the geometric normal). The entry's frame as sss_walk_path's:
// the shading normal's, or the geometric normal's where the shading one turns away from w. ----
// (control: SceneView::sss_adjoint_control, tests' negative controls only)
LANTERN_HD inline Vec3 lt_sss_exit_f(const Material& m, const SurfaceHit& x, Vec3 d, Vec3 w,
                                     int control) {
    const float cos_d = fabsf(dot(d, x.ng));
    if (!(dot(w, x.ng) > 0.0f) || !(cos_d > 0.0f)) return vec3(0.0f);
    if (control == 1) return vec3(dot(w, x.ns) > 0.0f ? kInvPi : 0.0f);  // the forward exit
    const Frame frame = sss_entry_frame(x, w);
    const Vec3 wo = frame.to_local(w);
    const float q = sss_entry_pdf(m, wo, frame.to_local(-d));
    if (!(q > 0.0f)) return vec3(0.0f);
    return sss_entry_weight(m, x.coat_n, wo, vec3(control == 2 ? q : q / cos_d));
}

// ---- The continuation's proposal at the exit (local to the geometric normal, d.z > 0 the
// walk's last direction): half a cosine, half the refraction of d out through a GGX normal
// visible from inside (the entry lobe's reverse, so that the weight f_adj |cos| / pdf stays
// near W_e eta^2 instead of multiplying the lobe's peaks along a path); alpha its roughness
// (Skin: 1), at least 0.05. lt_sss_exit_pdf: the density of a direction c above ----
LANTERN_HD inline float lt_sss_exit_alpha(const Material& m) {
    return m.ss_skin ? 1.0f : fmaxf(m.roughness * m.roughness, 0.05f);
}

LANTERN_HD inline float lt_sss_exit_pdf(const Material& m, Vec3 d, Vec3 c) {
    if (!(c.z > 0.0f) || !(d.z > 0.0f)) return 0.0f;
    const float eta = m.ss_ior;
    float pdf = 0.5f * c.z * kInvPi;
    Vec3 h = d * eta - c;  // the refraction's normal, up to its length
    if (!(length_sq(h) > 1e-20f)) return pdf;
    h = normalize(h);
    if (h.z < 0.0f) h = -h;
    const float d_h = dot(d, h), c_h = dot(c, h);
    if (!(d_h > 0.0f) || !(c_h > 0.0f)) return pdf;
    const float q = Ggx::isotropic(lt_sss_exit_alpha(m)).pdf_visible(d, h) * c_h /
                    sqr(c_h - eta * d_h);
    return is_finite(q) ? pdf + 0.5f * q : pdf;
}

LANTERN_HD inline bool lt_sss_exit_sample(const Material& m, Vec3 d, Vec3 u, Vec3* c) {
    if (u.z < 0.5f) {
        float pdf = 0.0f;
        *c = sample_cosine_hemisphere(Vec2{u.x, u.y}, &pdf);
        return pdf > 0.0f;
    }
    const Vec3 h = Ggx::isotropic(lt_sss_exit_alpha(m)).sample_visible(d, Vec2{u.x, u.y});
    const float eta = m.ss_ior, cos1 = dot(d, h);
    const float sin2_sq = eta * eta * (1.0f - cos1 * cos1);
    if (!(cos1 > 0.0f) || !(sin2_sq < 1.0f)) return false;  // total internal reflection
    *c = normalize(d * eta - h * (eta * cos1 - sqrtf(1.0f - sin2_sq)));
    return c->z > 0.0f && is_finite(*c);
}

// The exit's continuation (lt's and the bidirectional light paths', bdpt_sss_light.h): a
// direction wo from the exit lobe about x's geometric normal, its density pdf_w and the
// throughput t after it (beta: before; Russian roulette at segment depth + 1). False: the path
// ends. Draws uniform2, uniform, then the roulette's.
LANTERN_HD inline bool lt_sss_exit_continue(const SceneView& s, const Material& m,
                                            const SurfaceHit& x, Vec3 d, Vec3 beta, int depth,
                                            int rr_depth, Rng& rng, Vec3* wo, float* pdf_w,
                                            Vec3* t) {
    const Frame gf = Frame::from_normal(x.ng);
    const Vec3 dl = gf.to_local(d);
    Vec3 c;
    const Vec2 u2 = rng.uniform2();
    if (!lt_sss_exit_sample(m, dl, Vec3{u2.x, u2.y, rng.uniform()}, &c)) return false;
    *pdf_w = lt_sss_exit_pdf(m, dl, c);
    *wo = gf.to_world(c);
    if (!(*pdf_w > 0.0f)) return false;
    *t = beta * lt_sss_exit_f(m, x, d, *wo, s.sss_adjoint_control) * (c.z / *pdf_w);
    return russian_roulette(*t, depth + 1, rr_depth, rng) && max_component(*t) > 0.0f &&
           is_finite(*t);
}

// ---- The exit at x_i: triangle tri, barycentrics uv, reached along d with throughput beta
// (the light's power apart); the splat to the camera, then the continuation. Media (pt's rule,
// pt_sss.h): the walk leaves into the medium its path arrived in at x_o, the slot's, which it
// kept; the splat's segment and the continuation (both above x's geometric normal) start there.
// Out of line on the device (LANTERN_DEVICE_NOINLINE): the walk kernel's frame holds the query ----
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline void lt_sss_exit(const SceneView& s, const PathState& ps,
                                   const LightPathState& lp, const PtSettings& st, int i, int tri,
                                   Vec2 uv, Vec3 d, Vec3 beta, int depth, float time, Rng& rng) {
    const SurfaceHit x = surface_at_time(s, tri, uv, -d, time);  // faces out, along d
    MaterialScratch scratch;
    const Material& m = material_at_point(
        s, s.tri_material[tri], [x, tri, uv] { return shade_point(x, tri, uv, x.ns); }, scratch);
    if (!(m.subsurface > 0.0f)) return;  // the camera walks only into subsurface
    if (s.num_media > 0 && s.sss_adjoint_control == 5) ps.medium[i] = -1;  // (tests' control)
    if ((s.tri_flags[tri] & kVisibleCamera) != 0) {
        const CameraView cam = s.motion.camera_steps > 1 ? camera_moved_at(s, motion_time(rng))
                                                         : s.camera;
        const bool lens = cam.lens_radius > 0.0f && !cam.orthographic && !cam.panoramic;
        const Vec2 u_lens = lens ? sample_aperture(cam, rng.uniform2()) : Vec2{};
        const CameraConnection cc = connect_camera(cam, x.p, filter_radius(cam), u_lens);
        if (cc.valid) {
            const Vec3 f = lt_sss_exit_f(m, x, d, cc.wc, s.sss_adjoint_control);
            if (s.num_media > 0) ps.shadow_medium[i] = ps.medium[i];  // (below)
            if (!is_black(f))
                lt_queue_splat(ps, lp, i, x.p, x.ng, cc,
                               lp.power[i] * beta * f * (dot(cc.wc, x.ng) * cc.importance),
                               s.offset_scale);
        }
    }
    if (depth + 2 > st.max_depth) return;  // the next vertex's connection would be too long
    Vec3 wo, t;
    float pdf_w;
    if (!lt_sss_exit_continue(s, m, x, d, beta, depth, st.rr_depth, rng, &wo, &pdf_w, &t)) return;
    ps.throughput[i] = t;
    set_next_ray(ps, i, x.p, x.ng, wo, pdf_w, s.offset_scale);
    // the next segment's kinds start at the exit x_i, pt's entry: the camera-side ray that
    // reaches it sees it (lt_ray_visibility.h lt_rays_next; the walk and x_o read no kinds past
    // lt_rays_sss_weight)
    if (lt_rays_on(s)) lt_rays_next(s, ps, i, tri);
}

// ---- lt's entry at x_o (surface(): the hit at triangle tri, barycentrics uv, reached along d,
// facing the light; beta the path's throughput there): a cosine about the inward geometric
// normal, the walk in the medium of x_o's material, exit(prim, uv, last, beta) where it leaves.
// lt's walk stage and the bidirectional light paths' (bdpt_sss_light.h) share it. Draws
// uniform2 (the cosine), then the walk's. The start (the hit, its material, the first direction
// and the medium: lt_sss_walk_start) is out of line on the device (LANTERN_DEVICE_NOINLINE), as
// pt's sss_walk_start: its locals stay out of the walk kernel's frame, which holds the walk's ray
// query (docs/cuda_backend.md) ----
template <class Surface>
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline bool lt_sss_walk_start(const SceneView& s, const Surface& surface, int tri,
                                         Vec2 uv, Vec3 d, Vec3 beta_in, Rng& rng, SssMedium* md,
                                         Vec3* o, Vec3* dir, Vec3* beta) {
    const SurfaceHit h = surface();
    MaterialScratch scratch;
    const Material& m = sss_entry_material(s, h, tri, uv, d, scratch);
    float pdf_w = 0.0f;
    *dir = Frame::from_normal(-h.ng).to_world(sample_cosine_hemisphere(rng.uniform2(), &pdf_w));
    if (!(pdf_w > 0.0f) || !(dot(*dir, h.ng) < 0.0f)) return false;
    *md = sss_medium(m);
    *o = offset_ray_origin(h.p, h.ng, *dir, s.offset_scale);
    *beta = beta_in * md->low;
    return true;
}

template <class Rays, class Kind, class Surface, class Exit>
LANTERN_HD inline void lt_sss_entry(const SceneView& s, const Rays& rays, Kind kind,
                                    const Surface& surface, int tri, Vec2 uv, Vec3 d, Vec3 beta,
                                    Rng& rng, float time, const Exit& exit) {
    SssMedium md;
    Vec3 o, dir, beta0;
    if (!lt_sss_walk_start(s, surface, tri, uv, d, beta, rng, &md, &o, &dir, &beta0)) return;
    sss_walk_medium(s, rays, kind, md, o, dir, beta0, rng, time, exit);
}

// ---- The walk stage, after the bounce's splats (schedule_lt.h): for a path with alive ==
// kAliveSss, the entry at its hit (x_o: the hit and the ray lt_shade shaded), the walk in the
// medium of x_o's material, the exit. Every other slot's splat is done: its shadow is cleared
// so that the exits' splats go alone through a second round of camera segments. ----
template <class Rays, class Kind>
LANTERN_HD inline void lt_sss_walk(const SceneView& s, const Rays& rays, Kind kind,
                                   const PathState& ps, const LightPathState& lp,
                                   const PtSettings& st, int i) {
    ps.shadow_valid[i] = 0;
    if (ps.alive[i] != kAliveSss) return;
    ps.alive[i] = 0;
    Rng rng = ps.rng[i];
    const float time = s.motion.rays_timed() ? motion_time(rng) : 0.0f;  // (the path's)
    const int tri = ps.hit_prim[i];
    const Vec2 uv = ps.hit_uv[i];
    const Vec3 d = ps.ray_d[i];
    const int depth = ps.depth[i];
    lt_sss_entry(s, rays, kind,
                 [&] { return surface_at_time(s, tri, uv, d, time); },  // faces the light
                 tri, uv, d, ps.throughput[i], rng, time,
                 [&](int prim, Vec2 xuv, Vec3 last, Vec3 beta) {
                     lt_sss_exit(s, ps, lp, st, i, prim, xuv, last, beta, depth, time, rng);
                 });
    ps.rng[i] = rng;
}

}  // namespace lantern
