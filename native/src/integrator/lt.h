// The light tracer's stages (integrator "lt", a reference for the light pass of BDPT): light
// paths from emission samples, every vertex connected to the camera (t = 1) and splatted through
// the pixel filter. Each stage touches one path slot; the session reduces splats in slot order.
#pragma once

#include "bsdf/material.h"
#include "core/offset.h"
#include "integrator/camera.h"
#include "integrator/light_path.h"
#include "integrator/motion_stage.h"
#include "integrator/path_state.h"
#include "integrator/bdpt_curve.h"
#include "integrator/pt.h"
#include "integrator/soft_light_path.h"

namespace lantern {

// What a light path carries beyond PathState: its flux and this bounce's splat position.
struct LightPathState {
    Vec3* power;      // emission flux / pick probability, constant along the path
    Vec2* splat_xy;   // raster position of this bounce's camera connection (shadow_contrib)
    int32_t* light = nullptr;  // lt: the light the path started on (soft_light_path.h's lines)
};

// ---- Pixel filter: the density camera.h importance-samples, normalised over [-w, w] ----
// w is Blender's filter size (HostScene::build_filter clamps it the same way).
LANTERN_HD inline float filter_radius(const CameraView& c) {
    float w = c.filter_width;
    if (!(w > 0.0f) || !is_finite(w)) w = 1.5f;
    return fminf(w, 16.0f);
}
LANTERN_HD inline float filter_density_1d(float x, float w) {
    if (fabsf(x) >= w) return 0.0f;
    // the window's integral over its width 2w is 0.35875 * 2w
    return fmaxf(0.0f, blackman_harris(x, 2.0f * w)) / (0.35875f * 2.0f * w);
}

// One splat position through the separable filter; `wrap`: columns wrap around (a
// 360-degree panorama), else the image's edges clip it.
template <typename Add>
LANTERN_HD inline void splat_at(const CameraView& c, Vec2 r, float w, bool wrap, double scale,
                                Add&& add) {
    int x0 = int(ceilf(r.x - 0.5f - w)), x1 = int(floorf(r.x - 0.5f + w));
    if (!wrap) {
        x0 = max_int(0, x0);
        x1 = min_int(c.width - 1, x1);
    }
    int y0 = max_int(0, int(ceilf(r.y - 0.5f - w)));
    int y1 = min_int(c.height - 1, int(floorf(r.y - 0.5f + w)));
    for (int py = y0; py <= y1; ++py) {
        float fy = filter_density_1d(r.y - (float(py) + 0.5f), w);
        if (fy <= 0.0f) continue;
        for (int px = x0; px <= x1; ++px) {
            double f = double(fy) * filter_density_1d(r.x - (float(px) + 0.5f), w) * scale;
            int qx = wrap ? ((px % c.width) + c.width) % c.width : px;
            if (f > 0.0) add(py * c.width + qx, f);
        }
    }
}

// A camera splat at raster position r through the pixel filter: add(pixel, weight) for every
// pixel the filter reaches, weight = filter density x `scale` (pixel = y * width + x).
// The CPU session adds in slot order; the CUDA backend adds with atomics. On a full
// panorama the filter wraps as camera rays do: across the left and right edges, and over a
// pole (a camera sample above the top row looks over the pole, half a turn round).
template <typename Add>
LANTERN_HD inline void splat_pixels(const CameraView& c, Vec2 r, double scale, Add&& add) {
    const float w = filter_radius(c);
    const bool wrap = c.panoramic && c.pano_range[1] - c.pano_range[0] >= 2.0f * kPi - 1e-4f;
    splat_at(c, r, w, wrap, scale, add);
    if (!wrap) return;
    const float half = 0.5f * float(c.width), h = float(c.height);
    if (c.pano_range[3] >= 0.5f * kPi - 1e-4f && r.y < w)
        splat_at(c, Vec2{r.x - half, -r.y}, w, true, scale, add);
    if (c.pano_range[2] <= -0.5f * kPi + 1e-4f && r.y > h - w)
        splat_at(c, Vec2{r.x - half, 2.0f * h - r.y}, w, true, scale, add);
}

// ---- Camera importance: where y projects, and We * G / (raster pdf) for a point at y ----
struct CameraConnection {
    Vec3 wc;         // unit direction from y to the camera
    float dist;      // length of the segment to test (clip range excluded)
    float raster_x, raster_y;
    float importance;  // d(raster)/d(area at y) without the cosine at y
    bool valid;
};

// `lens`: a point of the aperture (sample_aperture) when the camera has depth of field: the
// connection goes to it, and y lands where its ray through the lens meets the focal plane.
LANTERN_HD inline CameraConnection connect_camera(const CameraView& c, Vec3 y, float w,
                                                  Vec2 lens = Vec2{}) {
    CameraConnection cc{};
    cc.valid = false;
    const bool thin_lens = c.lens_radius > 0.0f && !c.orthographic && !c.panoramic;
    Vec3 ax = c.to_world.axis(0), ay = c.to_world.axis(1), az = c.to_world.axis(2);
    Vec3 lens_p = c.to_world.origin();
    if (thin_lens) lens_p = lens_p + ax * lens.x + ay * lens.y;
    Vec3 rel = y - lens_p;
    float lx = dot(rel, ax), ly = dot(rel, ay), depth = -dot(rel, az);
    if (c.panoramic) {  // the pixel's solid angle over d^2: d(raster) / d(area at y)
        float d = length(rel);
        if (!(d >= c.clip_start && d <= c.clip_end) || !(d > 0.0f)) return cc;
        cc.wc = -rel / d;
        cc.dist = d - c.clip_start;
        float pixel_w;
        Vec2 r = pano_raster(c, vec3(lx, ly, -depth) / d, &pixel_w);
        cc.raster_x = r.x;
        cc.raster_y = r.y;
        cc.importance = 1.0f / (pixel_w * d * d);
        if (r.x <= -w || r.x >= float(c.width) + w || r.y <= -w || r.y >= float(c.height) + w)
            return cc;  // (w: the filter's reach past a partial range's edge)
        cc.valid = cc.importance > 0.0f && is_finite(cc.importance);
        return cc;
    }
    if (!(depth >= c.clip_start && depth <= c.clip_end) || depth <= 0.0f) return cc;
    float sw = c.screen[1] - c.screen[0], sh = c.screen[3] - c.screen[2];
    float a_pix = sw * sh / (float(c.width) * float(c.height));  // screen area of a pixel
    float sx, sy;
    if (c.orthographic) {
        sx = lx;
        sy = ly;
        cc.wc = normalize(az);
        cc.dist = depth - c.clip_start;
        cc.importance = 1.0f / a_pix;  // dA_screen = |cos_y| dA_y
    } else {
        sx = lx / depth;
        sy = ly / depth;
        if (thin_lens) {  // the focal-plane point of the ray, seen from the lens centre
            sx = (lens.x + lx * (c.focus_distance / depth)) / c.focus_distance;
            sy = (lens.y + ly * (c.focus_distance / depth)) / c.focus_distance;
        }
        float d2 = length_sq(rel);
        float d = sqrtf(d2);
        float cos_c = depth / d;
        cc.wc = -rel / d;
        cc.dist = d * (1.0f - c.clip_start / depth);
        // dA_plane(z=-1) = dw / cos^3, dw = |cos_y| dA_y / d^2  [Veach thesis (10.8)-(10.9)]
        cc.importance = 1.0f / (a_pix * cos_c * cos_c * cos_c * d2);
    }
    cc.raster_x = (sx - c.screen[0]) / sw * float(c.width);
    cc.raster_y = (c.screen[3] - sy) / sh * float(c.height);
    if (cc.raster_x <= -w || cc.raster_x >= float(c.width) + w || cc.raster_y <= -w ||
        cc.raster_y >= float(c.height) + w)
        return cc;
    cc.valid = cc.importance > 0.0f && is_finite(cc.importance);
    return cc;
}

// A lens point for a connection to the camera, drawn from the slot's stream (a pinhole draws
// nothing, so that its images keep their bits).
LANTERN_HD inline Vec2 lens_sample(const CameraView& c, const PathState& ps, int i) {
    if (!(c.lens_radius > 0.0f) || c.orthographic || c.panoramic) return Vec2{};
    Rng rng = ps.rng[i];
    Vec2 u = rng.uniform2();
    ps.rng[i] = rng;
    return sample_aperture(c, u);
}

// Shadow ray from y (normal n, zero for none) to the camera; the splat waits for its result.
LANTERN_HD inline void lt_queue_splat(const PathState& ps, const LightPathState& lp, int i, Vec3 y,
                                      Vec3 n, const CameraConnection& cc, Vec3 contrib,
                                      float offset_scale) {
    if (!is_finite(contrib)) {
        ps.dropped[i] = 1;
        return;
    }
    if (is_black(contrib)) return;
    Vec3 o = is_black(n) ? y : offset_ray_origin(y, n, cc.wc, offset_scale);
    ps.shadow_o[i] = o;
    ps.shadow_d[i] = cc.wc;
    ps.shadow_tmax[i] = fmaxf(0.0f, cc.dist - length(o - y)) * (1.0f - 1e-4f);
    ps.shadow_contrib[i] = contrib;
    ps.shadow_valid[i] = 1;
    lp.splat_xy[i] = {cc.raster_x, cc.raster_y};
}

}  // namespace lantern

#include "integrator/lt_linking.h"  // shadow linking, Cast Shadow off, linking in media
#include "integrator/lt_medium.h"  // media: uses lt_queue_splat
#include "integrator/lt_ray_visibility.h"  // ray visibility by kind
#include "integrator/lt_sss.h"  // subsurface: the adjoint walk, uses lt_queue_splat
#include "integrator/lt_strand.h"  // through a strand

namespace lantern {

// ---- Generate: pick a light by power, sample its emission, connect it to the camera ----
LANTERN_HD inline void lt_generate(const SceneView& s, const PathState& ps,
                                   const LightPathState& lp, const PtSettings& st, int i,
                                   int64_t path) {
    Rng rng = Rng::for_path(st.seed ^ 0x4C54ull, st.iteration, uint64_t(path));
    ps.alive[i] = 0;
    ps.dropped[i] = 0;
    ps.shadow_valid[i] = 0;
    ps.depth[i] = 0;  // segments from the light to the current vertex
    ps.throughput[i] = vec3(1.0f);
    ps.radiance[i] = vec3(0.0f);
    float u_pick = rng.uniform();
    Vec2 u_pos = rng.uniform2(), u_dir = rng.uniform2();
    if (s.num_lights == 0) return;
    int li = sample_cdf(s.light_cdf, s.num_lights, u_pick);
    const Light& l = s.lights[li];
    // (a soft-falloff light: a line through its ball, soft_light_path.h)
    const bool soft = light_receiver_dependent(l);
    // (a moving emitter: where it is at the path's time, motion_time of its stream)
    const float time = s.motion.num_objects > 0 ? motion_time(rng) : 0.0f;
    EmissionSample es = soft ? sample_soft_line(l, u_pos, u_dir)
                             : sample_emission(s, l, u_pos, u_dir, time, kTightDisk);  // no MIS
    if (!es.valid || !(l.pick_pdf > 0.0f)) return;
    lp.power[i] = emission_weight(es) / l.pick_pdf;
    if (lp.light) lp.light[i] = li;
    ps.rng[i] = rng;
    // linking (lt_linking.h): the receiver set pending till the first vertex; the light's point
    // for the first segment's walk
    if (s.light_receivers) ps.recv_set[i] = 1;
    if (lt_rays_on(s)) {  // ray visibility by kind (lt_ray_visibility.h): x0 for w_nee
        lt_rays_start(ps, i, es);
        ps.prev_p[i] = es.p;
        ps.prev_n[i] = es.n;
    }
    if ((s.light_blockers || s.light_rays || s.no_shadow_objects) && lt_walks(s, li)) {
        ps.walk_passed(i) = 0;
        ps.prev_p[i] = es.p;
        ps.prev_n[i] = es.n;
        if (s.num_media > 0) lt_walk_start(ps, i, es.finite);  // (lt_medium.h lt_walk_ratio)
    }
    if (s.num_media > 0) {  // the medium it emits into (lt_medium.h)
        Vec3 f;
        ps.medium[i] = lt_start_medium(s, li, es, &f);
        ps.shadow_medium[i] = ps.medium[i];
        lp.power[i] = lp.power[i] * f;
    }

    // the emitter itself seen by the camera (one segment): finite, non-delta surfaces
    bool visible = l.type == kLightTriangle
                       ? (s.tri_flags[l.triangle] & kVisibleCamera) != 0
                       : (l.visible_camera != 0 && (l.type == kLightArea || l.type == kLightPoint ||
                                                    l.type == kLightSpot));
    if (visible && es.finite && !es.delta_pos && !soft) {  // (a soft disk faces the camera)
        // (a moving camera: at the path's time, its own: motion_time of its stream)
        const CameraView cam = s.motion.camera_steps > 1 ? camera_moved_at(s, motion_time(rng))
                                                         : s.camera;
        float w = filter_radius(cam);
        CameraConnection cc = connect_camera(cam, es.p, w, lens_sample(cam, ps, i));
        float cos_c = cc.valid ? dot(cc.wc, es.n) : 0.0f;
        if (l.type == kLightTriangle) cos_c = fabsf(cos_c);
        if (cos_c > 0.0f) {
            // the camera's direct view of a Principled emitter: under its coat and sheen
            Vec3 le = l.type == kLightTriangle ? es.le * triangle_emission_through(s, l, cos_c)
                                               : l.radiance;
            if (l.type == kLightSpot) le = le * spot_attenuation(l, cc.wc);
            // Le * cos / (pick * pdf_a): the vertex's area density, not pdf_emit
            Vec3 c = le * (cos_c * cc.importance / (l.pick_pdf * es.pdf_direct));
            lt_queue_splat(ps, lp, i, es.p, es.n, cc, c, s.offset_scale);
        }
    }
    if (st.max_depth < 2) return;
    ps.ray_o[i] = is_black(es.n) ? es.p : offset_ray_origin(es.p, es.n, es.d, s.offset_scale);
    ps.ray_d[i] = es.d;
    ps.ray_tmin[i] = 0.0f;
    ps.ray_tmax[i] = kInf;
    ps.prev_pdf_w[i] = es.pdf_emit;
    ps.alive[i] = 1;
}

// ---- Shade: connect the hit to the camera, then continue with the adjoint BSDF ----
LANTERN_HD inline void lt_shade(const SceneView& s, const PathState& ps, const LightPathState& lp,
                                const PtSettings& st, int i) {
    ps.shadow_valid[i] = 0;
    ps.alive[i] = 0;
    int tri = ps.hit_prim[i];
    // in a medium: a free flight, and where it scatters a medium vertex (lt_medium.h)
    if (s.num_media > 0 && ps.medium[i] >= 0 && lt_medium_segment(s, ps, lp, st, i)) return;
    if (tri < 0) return;
    if (s.num_media > 0 && (s.tri_flags[tri] & kVolumeBoundary)) {  // no surface: go on
        // (the first segment's walk across a blocker's boundary: lt_medium.h lt_walk_close)
        if (lt_walk_media(s, ps, lp, i) && !lt_shadow_passes(s, lp.light[i], tri))
            lt_walk_close(s, ps, i, ps.ray_o[i] + ps.ray_d[i] * ps.hit_t[i], ps.medium[i]);
        pt_cross_boundary(s, ps, i, tri);
        return;
    }
    Vec3 d = ps.ray_d[i];
    // a soft-falloff light's line: its first hit needs its y0 on the disk facing it
    if (ps.depth[i] == 0 && lp.light && light_receiver_dependent(s.lights[lp.light[i]]) &&
        !soft_line_hit_valid(s.lights[lp.light[i]], ps.ray_o[i], d, ps.hit_t[i]))
        return;
    // linking (lt_linking.h): the first segment walks past surfaces that cast its light no
    // shadow (passed > 0: a vertex only next-event estimation makes); the first surface vertex
    // decides the receiver set, and a set its light does not light ends the path
    int passed = 0;
    const bool walk = ps.depth[i] == 0 &&
                      (s.light_blockers || s.light_rays || s.no_shadow_objects) && lp.light &&
                      lt_walks(s, lp.light[i]);
    // (ray visibility by kind: the segment walks past surfaces hidden from some kind, the first
    // one past those that cast its light no shadow too: its weights are lt_rays_weight's)
    if (s.tri_rays && !lt_rays_step(s, ps, i, lp.light ? lp.light[i] : -1, tri,
                                    ps.ray_o[i] + d * ps.hit_t[i], walk))
        return;
    // (in media: pt's shadow ray's transmittance over the walked one, lt_medium.h; the
    // non-delta lobes', a delta lobe's at h1 the walked one)
    const bool walk_media = s.num_media > 0 && lt_walk_media(s, ps, lp, i);
    if (walk && !s.tri_rays) {
        passed = ps.walk_passed(i);
        if (!lt_walk_step(s, ps, i, lp.light[i], tri, ps.ray_o[i] + d * ps.hit_t[i],
                          bidir_links(s, lp.light[i], tri)))
            return;
    }
    if (!lt_receiver_decides(s, ps, lp, i, tri, false)) return;
    // a triangle's or a strand's surface (pt_curve.h); strands: the fiber measure (bdpt_curve.h)
    const bool strand = prim_is_strand(s, tri);
    // (motion blur: the path's time is motion_time of its stream, motion_stage.h)
    SurfaceHit h = s.motion.num_objects > 0 && !strand
                       ? surface_moved_at(s, tri, ps.hit_uv[i], d, motion_time(ps.rng[i]))
                       : surface_of_hit(s, tri, ps.hit_uv[i], ps.ray_o[i], d, ps.hit_t[i],
                                        s.motion.curves ? motion_time(ps.rng[i]) : 0.0f);
    MaterialScratch scratch;
    const Material* mp = &material_at_point(
        s, s.tri_material[tri],
        [&] { return shade_point(h, strand ? -1 : tri, ps.hit_uv[i], -d); }, scratch);
#ifndef __CUDACC__  // (strands render on the CPU only: session.cpp)
    // a tube vertex whose BSDF transmits: with 1/2 the point where the ray leaves the strand,
    // the light inside its fiber (lt_strand.h)
    MaterialScratch scratch_exit;
    bool inside_fiber = false;  // (the continuation's proposal: lt_strand_inside_sample)
    if (strand && !strand_fiber(*mp) && material_transmits(*mp) && s.lt_strand_control == 0) {
        Rng rng = ps.rng[i];
        const bool inside = rng.uniform() < 0.5f;
        ps.rng[i] = rng;
        ps.throughput[i] = ps.throughput[i] * 2.0f;
        inside_fiber = inside;
        if (inside) {  // its material there
            if (!lt_strand_exit(s, ps.ray_o[i], d, ps.hit_t[i],
                                s.motion.curves ? motion_time(ps.rng[i]) : 0.0f, &tri, &h))
                return;
            mp = &material_at_point(
                s, s.tri_material[tri], [&] { return shade_point(h, -1, Vec2{h.st.x, 0.0f}, -d); },
                scratch_exit);
        }
    }
#endif
    const Material& m = *mp;
    int depth = ps.depth[i] + 1;  // segments from the light to this vertex
    ps.depth[i] = depth;
    Vec3 wo_w = -d;  // towards the light
    float cos_o_ns = fabsf(dot(wo_w, h.ns)), cos_o_ng = fabsf(dot(wo_w, h.ng));
    if (!(cos_o_ng > 0.0f)) return;
    Frame frame = h.frame();
    // on a strand: the hair lobe's fiber measure, or a tube vertex (pt's surface point), which
    // must face both its neighbours (bdpt_curve.h)
    const bool fiber = strand && strand_fiber(m), tube = strand && !fiber;
    if (fiber) cos_o_ns = cos_o_ng = vertex_cos(true, frame, h.ng, wo_w);
    Vec3 wo = frame.to_local(wo_w);
    Vec3 beta = lp.power[i] * ps.throughput[i];
    const int li = lp.light ? lp.light[i] : -1;
    const Vec3 w_media = walk_media ? lt_walk_ratio(s, ps, i, h.p, ps.medium[i]) : vec3(1.0f);

    // ---- Connect to the camera (t = 1): depth + 1 segments ----
    if ((s.tri_flags[tri] & kVisibleCamera) != 0) {
        const CameraView cam = s.motion.camera_steps > 1
                                   ? camera_moved_at(s, motion_time(ps.rng[i]))
                                   : s.camera;
        CameraConnection cc = connect_camera(cam, h.p, filter_radius(cam),
                                             lens_sample(cam, ps, i));
        if (cc.valid && !material_is_delta(m) && view_side_agrees(m, cc.wc, h.ng, h.ns) &&
            !(tube && !(dot(cc.wc, h.ng) > 0.0f)) &&
            (!lt_rays_on(s) || lt_rays_kind_ok(s, ps, i, li, m, h.ng, wo_w, cc.wc))) {
            BsdfEval e = material_eval(m, h.front, wo, frame.to_local(cc.wc),
                                       Transport::Importance, h.coat_n, frame.to_local(h.ng));
            // f * |cos_ns(wc)| with the adjoint shading-normal factor
            // |wo.ns| |wc.ng| / (|wo.ng| |wc.ns|)  [Veach thesis (5.19)]
            float cos_y = cos_o_ns * vertex_cos(fiber, frame, h.ng, cc.wc) / cos_o_ng;
            if (s.num_media > 0)  // through the surface: the medium beyond it
                ps.shadow_medium[i] = dot(cc.wc, h.ng) < 0.0f
                                          ? medium_across(s, tri, h.front, ps.medium[i])
                                          : ps.medium[i];
            // (past a transparent surface: next-event estimation's share, lt_linking.h)
            float w = passed > 0 ? lt_nee_weight(s, ps, i, lp.light[i], tri, m, h, wo_w, cc.wc,
                                                 e.pdf_rev_w)
                                 : 1.0f;
            if (s.tri_rays)  // (past surfaces hidden from its kind: pt's bounce ray's share)
                w *= lt_rays_weight(s, ps, i, li, tri, m, h, wo_w, cc.wc, e.pdf_rev_w, false);
            lt_queue_splat(ps, lp, i, h.p, h.ng, cc,
                           beta * w_media * e.f * (cos_y * cc.importance * w), s.offset_scale);
        }
    }
    // under the surface: the walk stage takes the path (integrator/lt_sss.h)
    // (past a transparent surface: pt's next-event weight at a walk's exit, lt_linking.h)
    if (s.has_subsurface && !strand &&
        lt_sss_choose(s, ps, st, i, m, h, wo_w, cos_o_ns, cos_o_ng, depth)) {
        float w = passed > 0 ? lt_sss_nee_weight(s, ps, i, lp.light[i], tri, h, wo_w) : 1.0f;
        // (ray visibility by kind: pt's exit there is a diffuse scattering)
        if (lt_rays_on(s)) w *= lt_rays_sss_weight(s, ps, i, li, tri, h, wo_w);
        ps.throughput[i] = ps.throughput[i] * w_media * w;
        return;
    }
    if (depth + 2 > st.max_depth) return;  // the next vertex's connection would be too long

    // ---- Continue: cosine sampling, adjoint weight, roulette ----
    Rng rng = ps.rng[i];
    Vec2 u_dir = rng.uniform2();
    const Vec3 u_bsdf{u_dir.x, u_dir.y, rng.uniform()};
#ifndef __CUDACC__
    BsdfSample bs = inside_fiber
                        ? lt_strand_inside_sample(m, h.front, wo, u_bsdf, rng.uniform(),
                                                  h.coat_n, frame.to_local(h.ng))
                        : material_sample(m, h.front, wo, u_bsdf, Transport::Importance,
                                          h.coat_n, frame.to_local(h.ng));
#else
    BsdfSample bs = material_sample(m, h.front, wo, u_bsdf, Transport::Importance, h.coat_n,
                                    frame.to_local(h.ng));
#endif
    Vec3 wi = frame.to_world(bs.wi);
    // (a tube vertex left through its fiber: outside pt's path space, bdpt_curve.h)
    // (past a transparent surface: non-delta lobes only, next-event estimation's share)
    if (bs.valid && view_side_agrees(m, wi, h.ng, h.ns) && !(tube && !(dot(wi, h.ng) > 0.0f)) &&
        !(passed > 0 && (bs.delta || !(bs.pdf_fwd_w > 0.0f))) &&
        (!lt_rays_on(s) || lt_rays_kind_ok(s, ps, i, li, m, h.ng, wo_w, wi, bs.delta))) {
        // (a strand: the lobe's Importance weight is the fiber measure's whole throughput)
        float adj = fiber ? 1.0f
                           : cos_o_ns * fabsf(dot(wi, h.ng)) / (cos_o_ng * fabsf(bs.wi.z));
        if (passed > 0)
            adj *= lt_nee_weight(s, ps, i, lp.light[i], tri, m, h, wo_w, wi, bs.pdf_rev_w);
        if (s.tri_rays)
            adj *= lt_rays_weight(s, ps, i, li, tri, m, h, wo_w, wi, bs.pdf_rev_w, bs.delta);
        Vec3 t = ps.throughput[i] * bs.weight * adj;
        if (!bs.delta) t = t * w_media;
        if (russian_roulette(t, depth + 1, st.rr_depth, rng) && max_component(t) > 0.0f &&
            is_finite(t)) {
            ps.throughput[i] = t;
            set_next_ray(ps, i, h.p, h.ng, wi, bs.pdf_fwd_w,
                         s.offset_scale);
            if (s.num_media > 0 && dot(wi, h.ng) < 0.0f)  // through the surface
                ps.medium[i] = medium_across(s, tri, h.front, ps.medium[i]);
            if (lt_rays_on(s)) lt_rays_next(s, ps, i, tri);
        }
    }
    ps.rng[i] = rng;
}

}  // namespace lantern
