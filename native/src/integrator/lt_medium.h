// The light tracer's stages in homogeneous media (integrator "lt", docs/volumes.md): light
// paths start in the medium their light sits in (SceneView::light_medium), sample a free-flight
// distance on every segment in a medium (scene/medium.h, the same one-sample MIS over RGB that pt
// uses), and where it falls inside the segment make a medium vertex: connected to the camera with
// the Henyey-Greenstein phase function (no cosine at a medium point), then continued with a
// phase sample (weight 1). Volume boundaries are passed through; the camera segments carry the
// transmittance of every medium they cross. Run only where SceneView::num_media > 0.
// Heterogeneous media: spectral tracking (scene/medium_hetero.h) on the segments, ratio tracking
// on the camera segments. Emissive media send no light paths: the session hands such scenes to
// pt (session.cpp).
// Included by lt.h after lt_queue_splat and lt_linking.h, which it uses.
#pragma once

#include "integrator/lt_ray_visibility.h"
#include "integrator/medium_motion.h"
#include "integrator/pt_volume.h"

namespace lantern {

// The medium light l's paths start in, and the throughput factor of their way there: distant
// lights (sun, world) come from infinity through the world's medium, which lets none of its
// extinguished channels through (pt's rays escaping through world fog carry no light either).
LANTERN_HD inline int32_t lt_start_medium(const SceneView& s, int li, const EmissionSample& es,
                                          Vec3* factor) {
    *factor = vec3(1.0f);
    if (!es.finite) {
        if (s.world_medium >= 0) *factor = medium_transmittance(s.media[s.world_medium], kInf);
        return s.world_medium;
    }
    return s.light_medium ? s.light_medium[li] : s.world_medium;
}

// ---- lt's first segment's walk in media (lt_linking.h: a shadow-linked light's alone, the
// allocation hands the others to pt). pt's shadow ray from a vertex x1 of medium M(x1) toward
// x0 passes the surfaces and volume boundaries outside l's blockers with its medium unchanged
// and crosses a blocker's boundary (pt_volume.h pt_shadow_loop): its transmittance is
// exp(-tau') with tau' = sigma_t(M(x1)) |x1 - x_b| plus, for each stretch between two
// crossed blocker boundaries, sigma_t of the medium at the stretch's end (toward x1) times its
// length, x_b the last blocker boundary before x1 (x0 if none). The walk follows the media
// as lt's paths do (each boundary crossed, the medium inside a passed surface entered), so
// its vertices carry the walked transmittance exp(-tau): each takes exp(tau - tau'). walk_tau
// keeps tau less tau' of the closed stretches, walk_t0 the distance |x_b - x0| (-inf for a
// distant light: pt's shadow ray toward it never leaves M(x1), transmittance 0 where
// sigma_t > 0). Homogeneous media only (sigma_t constant): the allocation hands heterogeneous
// ones to pt. ----
LANTERN_HD inline bool lt_walk_media(const SceneView& s, const PathState& ps,
                                     const LightPathState& lp, int i) {
    return ps.walk_tau && ps.depth[i] == 0 && s.light_blockers && lp.light &&
           bidir_nee_only(s, lp.light[i]);
}
// sigma x len per channel, 0 where sigma is 0 (len may be infinite)
LANTERN_HD inline Vec3 lt_walk_depth(Vec3 sigma, float len) {
    return Vec3{sigma.x > 0.0f ? sigma.x * len : 0.0f, sigma.y > 0.0f ? sigma.y * len : 0.0f,
                sigma.z > 0.0f ? sigma.z * len : 0.0f};
}
LANTERN_HD inline Vec3 lt_walk_sigma(const SceneView& s, int32_t med) {
    return med >= 0 ? s.media[med].sigma_t : vec3(0.0f);
}
// The walk starts at x0 (lt_generate): nothing crossed yet.
LANTERN_HD inline void lt_walk_start(const PathState& ps, int i, bool finite) {
    if (!ps.walk_tau) return;
    ps.walk_tau[i] = vec3(0.0f);
    ps.walk_t0[i] = finite ? 0.0f : -kInf;
}
// A blocker's boundary crossed at q, the walk in medium med before it: a stretch closes.
LANTERN_HD inline void lt_walk_close(const SceneView& s, const PathState& ps, int i, Vec3 q,
                                     int32_t med) {
    const float t = length(q - ps.prev_p[i]);
    ps.walk_tau[i] = ps.walk_tau[i] - lt_walk_depth(lt_walk_sigma(s, med), t - ps.walk_t0[i]);
    ps.walk_t0[i] = t;
}
// The factor exp(tau - tau') of the walk's vertex at p in medium med (walk_tau holding the
// walked depth up to p).
LANTERN_HD inline Vec3 lt_walk_ratio(const SceneView& s, const PathState& ps, int i, Vec3 p,
                                     int32_t med) {
    const float t = length(p - ps.prev_p[i]);
    const Vec3 tau =
        ps.walk_tau[i] - lt_walk_depth(lt_walk_sigma(s, med), t - ps.walk_t0[i]);
    return Vec3{expf(tau.x), expf(tau.y), expf(tau.z)};
}

// ---- A medium vertex at p reached along d (the light's direction of travel): its connection
// to the camera, phase x importance (no cosine at p), through the medium it is in; a moving
// camera where it is at the path's time (lt_shade's) ----
LANTERN_HD inline void lt_medium_connect(const SceneView& s, const PathState& ps,
                                         const LightPathState& lp, int i, Vec3 p, Vec3 d,
                                         const Medium& m) {
#ifdef __CUDA_ARCH__  // (motion blur renders on the CPU only: medium_rays_timed)
    const CameraView& cam = s.camera;
#else
    const CameraView cam = s.motion.camera_steps > 1 ? camera_moved_at(s, motion_time(ps.rng[i]))
                                                     : s.camera;
#endif
    const CameraConnection cc = connect_camera(cam, p, filter_radius(cam),
                                               lens_sample(cam, ps, i));
    if (!cc.valid) return;
    float phase = hg_phase(m.g, dot(d, cc.wc));
    if (lt_rays_on(s))  // (ray visibility by kind: a phase scattering's factor, lt_ray_visibility.h)
        phase *= lt_rays_medium_weight(s, ps, i, lp.light ? lp.light[i] : -1, p, d, cc.wc, m.g);
    ps.shadow_medium[i] = ps.medium[i];
    lt_queue_splat(ps, lp, i, p, vec3(0.0f), cc,
                   lp.power[i] * ps.throughput[i] * (phase * cc.importance), s.offset_scale);
}

// ---- The traced segment in the slot's medium: a free-flight distance; true when the path
// scattered inside the segment (this stage made the medium vertex, its camera connection and
// its continuation; the hit is not shaded). Otherwise the throughput carries the segment's
// transmittance (over the probability of passing it) and the caller shades the hit. ----
#ifndef __CUDA_ARCH__
__attribute__((noinline))  // out of line on the host: lt_shade stays as small as without media
#endif
LANTERN_HD inline bool lt_medium_segment(const SceneView& s, const PathState& ps,
                                         const LightPathState& lp, const PtSettings& st, int i) {
    const Medium& m = s.media[ps.medium[i]];
    const bool walk = s.light_blockers && lt_walk_media(s, ps, lp, i);  // (lt_walk_ratio)
    const Vec3 o = ps.ray_o[i], d = ps.ray_d[i];
    const float tmin = ps.ray_tmin[i];
    const float t_end = ps.hit_prim[i] >= 0 ? ps.hit_t[i] : ps.ray_tmax[i];
    const Vec3 beta = ps.throughput[i];
    Rng rng = ps.rng[i];
    MediumStep step;
    if (m.hetero) {  // spectral tracking (scene/medium_hetero.h), channels by the path's flux
        Rng tr = medium_tracking_rng(rng, 0);
        rng.uniform();  // the next segment's tracking starts a block of its own
        Vec3 fo = o + d * tmin, fd = d;  // (a moving volume's density: its exported frame)
        if (s.motion.medium_objects)
            medium_frame_ray(s, ps.medium[i], motion_time(ps.rng[i]), &fo, &fd);
        const HeteroStep h = medium_track(s, m, ps.medium[i], fo, fd, t_end - tmin,
                                          lp.power[i] * beta, tr, [](float, Vec3, float) {},
                                          [](float, float, Vec3) {});
        step = MediumStep{h.t, h.scattered, h.weight};
    } else {
        const Vec3 pmf = medium_channel_pmf(lp.power[i] * beta);
        float u_channel = 0.0f, u_dist = 0.0f;
        if (m.scatters) {  // a medium that only absorbs spends no numbers
            u_channel = rng.uniform();
            u_dist = rng.uniform();
        }
        step = medium_sample_distance(m, t_end - tmin, pmf, u_channel, u_dist);
    }
    ps.rng[i] = rng;
    ps.throughput[i] = beta * step.weight;
    if (walk)  // (a walk's segment that ends nowhere ends the path)
        ps.walk_tau[i] = ps.walk_tau[i] + lt_walk_depth(m.sigma_t, step.t);
    if (!step.scattered) return false;

    const int depth = ps.depth[i] + 1;  // segments from the light to this vertex
    ps.depth[i] = depth;
    const Vec3 p = o + d * (tmin + step.t);
    // the walk's medium vertex: next-event estimation's alone in pt, its shadow ray's
    // transmittance
    if (walk) ps.throughput[i] = ps.throughput[i] * lt_walk_ratio(s, ps, i, p, ps.medium[i]);
    // light linking: a vertex in the world's medium decides the receiver set (0), one in a
    // mesh's volume keeps it pending, its splat the camera's (lt_linking.h)
    if (!lt_receiver_decides(s, ps, lp, i, -1, ps.medium[i] == s.world_medium)) return true;
    if (lt_pending_lit(s, ps, lp, i))
        lt_medium_connect(s, ps, lp, i, p, d, m);  // t = 1: depth + 1 segments
    if (depth + 2 > st.max_depth) return true;  // the next vertex's connection would be too long
    rng = ps.rng[i];
    float pdf_w = 0.0f;
    const Vec3 wi = hg_sample(m.g, d, rng.uniform2(), &pdf_w);  // weight phase / pdf = 1
    Vec3 t = ps.throughput[i];
    if (lt_rays_on(s))  // (ray visibility by kind; the next segment's E: a medium point's, all)
        t = t * lt_rays_medium_weight(s, ps, i, lp.light ? lp.light[i] : -1, p, d, wi, m.g);
    if (pdf_w > 0.0f && russian_roulette(t, depth + 1, st.rr_depth, rng) &&
        max_component(t) > 0.0f && is_finite(t)) {
        ps.throughput[i] = t;
        ps.ray_o[i] = p;
        ps.ray_d[i] = wi;
        ps.ray_tmin[i] = 0.0f;
        ps.ray_tmax[i] = kInf;
        ps.prev_pdf_w[i] = pdf_w;
        ps.alive[i] = 1;
        if (lt_rays_on(s)) ps.ray_kind[i] = uint8_t(kRayKindsAll << 4);
    }
    ps.rng[i] = rng;
    return true;
}

}  // namespace lantern
