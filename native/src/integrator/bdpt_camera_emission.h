// The camera pass's generation and emission (s = 0) of the bidirectional stages: the camera
// ray's density, the camera sub-path's start with its MIS quantities, the weight of emission a
// camera path finds (soft-falloff lights' stand-in included). Split from bdpt_camera.h, which
// includes it; MIS quantities: bdpt_common.h.
#pragma once

#include "integrator/bdpt_common.h"
#include "integrator/bdpt_curve.h"
#include "integrator/bidir_linking.h"
#include "integrator/bdpt_medium.h"
#include "integrator/bdpt_motion.h"
#include "integrator/bdpt_sss_light.h"  // subsurface: the split (CPU)
#include "integrator/pixel_conn.h"
#include "integrator/soft_light_medium.h"
#include "integrator/soft_light_path.h"

namespace lantern {

// Solid-angle density of a pinhole camera ray along d for a raster density of one per pixel
// (orthographic: the area density on the lens plane).
LANTERN_HD inline float camera_pdf(const CameraView& c, Vec3 d) {
    if (c.panoramic) {  // one sample per pixel's solid angle
        float pixel_w;
        Vec3 dl = {dot(d, c.to_world.axis(0)), dot(d, c.to_world.axis(1)),
                   dot(d, c.to_world.axis(2))};
        pano_raster(c, dl, &pixel_w);
        return pixel_w > 0.0f ? 1.0f / pixel_w : 0.0f;
    }
    float sw = c.screen[1] - c.screen[0], sh = c.screen[3] - c.screen[2];
    float a_pix = sw * sh / (float(c.width) * float(c.height));
    if (c.orthographic) return 1.0f / a_pix;
    float cos_c = -dot(d, c.to_world.axis(2));
    if (!(cos_c > 0.0f)) return 0.0f;
    return 1.0f / (a_pix * cos_c * cos_c * cos_c);
}

// scenes with media (bdpt_medium_stages.h)
LANTERN_HD inline void bdpt_camera_generate_medium(const PathState& ps, const BdptState& bs,
                                                   int i);
struct CameraVertex;
template <class SR>  // (the attribute here: a template's redeclaration cannot add it)
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline bool bdpt_camera_medium_segment(const SceneView& s, const PathState& ps,
                                                  const BdptState& bs, const BdptSettings& st,
                                                  const LightCache& cache, int i, int64_t path,
                                                  CameraVertex& z, const SR& sr);

LANTERN_HD inline void bdpt_camera_generate(const SceneView& s, const PathState& ps,
                                            const BdptState& bs, const BdptSettings& st_all,
                                            int i, int64_t path) {
    // the pixel's counts (pixel_conn.h: r, N, M; st_all itself without a map), kept for the
    // path's later stages (pixel_conn_of_slot)
    const PixelConn pc = pixel_conn_of_path(s, st_all, path);
    if (st_all.conn_map) bs.cam_conn[i] = pixel_conn_pack(pc);
    const BdptSettings st = camera_settings(st_all, pc);
    // the same camera sample as pt's (same random stream), plus the MIS quantities
    const PtSettings pst{st.max_depth, st.rr_depth, st.spp_per_iteration, st.seed, st.iteration};
    // (a moving camera: at the path's time, bdpt_motion.h, its density in that camera)
    pt_generate<kPtAll & ~kPtMotion>(s, ps, pst, i, path);
    const bool moving = s.motion.camera_steps > 1;
    if (moving) camera_ray_moved_at(s, bdpt_time(st, path), ps.ray_o[i], ps.ray_d[i]);
    if (bidir_rays_on(s) && ps.ray_kind) ps.ray_kind[i] = 0;  // (bidir_ray_visibility.h)
    bs.conn_n[i] = 0;
    // the light tracing technique relative to a connection (count r); none without light paths
    // (then r = 0 too: every weight of the camera pass is path tracing's)
    bs.dvcm[i] = st.n_lt > 0.0f ? mis(st.n_lt / (st.r * camera_pdf(moving
                                                            ? bdpt_camera_moved(s, st, path)
                                                            : s.camera, ps.ray_d[i])))
                                : 0.0f;
    bs.dvc[i] = 0.0f;
    if (s.num_media > 0) bdpt_camera_generate_medium(ps, bs, i);
}

// Weight of emission le found by the camera path at distance t_light along its ray, on light l
// with geometric normal n there. dvcm, dvc are the slot's values before this segment.
// soft_emit >= 0: a soft-falloff light's stand-in for pdf_emit (bdpt_soft_hit_emit).
LANTERN_HD inline float bdpt_emission_weight(const SceneView& s, const PathState& ps,
                                             const BdptState& bs, const BdptSettings& st, int i,
                                             const Light& l, float t_light, Vec3 n,
                                             float* nee_ratio = nullptr, float soft_emit = -1.0f) {
    if (ps.depth[i] <= 1) return 1.0f;  // seen directly: no other technique renders it
    const Vec3 o = ps.ray_o[i], d = ps.ray_d[i];
    const bool infinite = l.type == kLightSun || l.type == kLightWorld;
    float dvcm = bs.dvcm[i], dvc = bs.dvc[i];
    const int li = int(&l - s.lights);
    const float pick = s.light_tree_on ? light_pick_pmf(s, li, ps.prev_p[i], ps.prev_n[i])
                                       : l.nee_pdf;  // at the previous vertex
    float pdf_direct = pick * (l.type == kLightWorld ? world_pdf_w(s, d)
                                                     : light_pdf_w(l, o, d, t_light, n));
    if (!infinite) {
        float cos_l = fabsf(dot(d, n));
        if (!(cos_l > 0.0f)) return 0.0f;
        dvcm *= mis(t_light * t_light) / mis(cos_l);
        dvc /= mis(cos_l);
        pdf_direct *= cos_l / (t_light * t_light);  // area
    }
    float pdf_emit = soft_emit >= 0.0f ? soft_emit
                                       : l.emit_pick_pdf * emission_pdf(s, l, n, -d, 0.0f).pdf_emit;
    // (the second vertex: dvc is light tracing's term alone, BdptSettings::lt_direct)
    if (ps.depth[i] == 2) dvc *= bdpt_direct_lt(st);
    float w_camera = mis(pdf_direct) * dvcm + mis(st.r * pdf_emit) * dvc;
    if (nee_ratio) *nee_ratio = mis(pdf_direct) * dvcm;  // next-event estimation's (moments)
    return 1.0f / (1.0f + w_camera);
}

// A camera path from vertex x (the slot's prev_p, geometric normal bs.prev_ng) hits the disk
// of soft-falloff light l at y0 = o + t d. The light path makes x with area density
// emit_pick p(w) / (pi r^2) |cos_x,c| / |x - c|^2 V(c, x) where the usual light's would be
// pdf_emit |cos_x,d| / t^2: the stand-in for pdf_emit that makes bdpt_emission_weight's
// (which divides by |cos_x,d| / t^2 through dVC) that density (soft_light_path.h).
template <class SR>
LANTERN_HD inline float bdpt_soft_hit_emit(const SceneView& s, const PathState& ps,
                                           const BdptState& bs, const SR& sr, int i,
                                           const Light& l, float t) {
    const Vec3 x = ps.prev_p[i], ng = bs.prev_ng[i], d = ps.ray_d[i];
    const float pdf_a = soft_light_path_pdf_a(s, sr, l, x, ng);
    if (!(pdf_a > 0.0f)) return 0.0f;
    const Vec3 y0 = ps.ray_o[i] + d * t;
    const float cos_d = fabsf(dot(d, ng));
    const float r = pdf_a * length_sq(y0 - x) / cos_d;
    return cos_d > 0.0f && is_finite(r) ? r : 0.0f;
}

// A bounce ray of camera slot i hit R surface tri (bidir_ray_visibility.h): the path becomes
// restricted; where tri is hidden from the ray's kind the ray goes on past it (pt_pass_hidden:
// the same segment, the last vertex's MIS state kept) and this returns true. Out of line on the
// device (LANTERN_DEVICE_NOINLINE): the shade kernel's frame stays as it was.
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline bool bdpt_camera_meets_restricted(const SceneView& s, const PathState& ps,
                                                    const BdptSettings& st, int i, int tri,
                                                    int64_t path) {
    const uint8_t kind = ps.ray_kind[i];
    ps.ray_kind[i] = uint8_t(kind | kRayRestricted);
    if ((s.tri_rays[tri] & pt_object_kind(kind) & kRayKindsAll) != 0) return false;  // it lands there
    if (tri >= s.num_triangles) {  // a strand (pt_pass_hidden_strand)
        pt_pass_hidden_strand(s, ps, i);
        return true;
    }
    const Vec3 d = ps.ray_d[i];
    const SurfaceHit h = s.motion.num_objects > 0 && tri < s.num_triangles
                             ? surface_moved_at(s, tri, ps.hit_uv[i], d, bdpt_time(st, path))
                             : surface_of_hit(s, tri, ps.hit_uv[i], ps.ray_o[i], d, ps.hit_t[i],
                                              s.motion.curves ? bdpt_time(st, path) : 0.0f);
    pt_pass_hidden(s, ps, i, h.p, h.ng);
    return true;
}

// Integrator auto's moment channels (bdpt_moment) of emission that a restricted path's bounce
// ray found (bidir_ray_visibility.h), at pt's weight w = 1 / (1 + a): next-event estimation's
// squared ratio a to BSDF sampling, from pt's own weight (bdpt_emission_weight's ratio is
// measured from the ray's origin, which a ray that passed hidden surfaces moved past the real
// vertex).
LANTERN_HD inline float bidir_rays_nee_ratio(float w) { return w > 0.0f ? 1.0f / w - 1.0f : 0.0f; }

// Lights crossed by the segment, and the background on a miss (s = 0). L: linking's tests
// compiled in (bidir_links_on).
template <bool L = true, class SR>
LANTERN_HD inline void bdpt_camera_emission(const SceneView& s, const PathState& ps,
                                            const BdptState& bs, const BdptSettings& st, int i,
                                            float t_end, bool miss, const SR& sr) {
    const Vec3 o = ps.ray_o[i], d = ps.ray_d[i];
    const bool camera = ps.depth[i] <= 1;
    for (int k = 0; k < s.num_hittable_lights; ++k) {
        const Light& l = s.lights[s.hittable_lights[k]];
        if (camera && !l.visible_camera) continue;
        if (L && !bidir_emission_counts(s, ps, i, s.hittable_lights[k])) continue;  // (linking)
        if (L && pt_lamp_unseen(s, ps, i, s.hittable_lights[k])) continue;  // (ray kinds)
        LightHit h = intersect_light(l, o, d, ps.ray_tmin[i], t_end);
        if (!h.hit || is_black(h.le)) continue;
        float nee = 0.0f;
        float soft = -1.0f;  // (a soft-falloff light's stand-in for pdf_emit; r = 0: no ray)
        if (!camera && light_receiver_dependent(l))
            soft = st.r > 0.0f ? bdpt_soft_hit_emit(s, ps, bs, sr, i, l, h.t) : 0.0f;
        float w = bdpt_emission_weight(s, ps, bs, st, i, l, h.t, h.n, &nee, soft);
        if (L && w > 0.0f && bidir_pt_weight(s, ps, i, s.hittable_lights[k]))
            w = 1.0f / (1.0f + nee);
        if (L && w > 0.0f && bidir_rays_on(s) &&
            bidir_rays_pt_weight(s, ps, i, s.hittable_lights[k])) {  // (bidir_ray_visibility.h)
            w = bidir_rays_emission_weight(s, ps, i, s.hittable_lights[k], o, d, h.t, h.n,
                                           0.0f);  // (a lamp)
            nee = bidir_rays_nee_ratio(w);
        }
        Vec3 c = ps.throughput[i] * h.le * w;
        if (st.moments) c = bdpt_moment(c, c, bdpt_pt_factor(1.0f / w, 1.0f, nee));
        add_radiance(ps, i, c);
    }
    if (!miss) return;
    for (int k = 0; k < s.num_miss_lights; ++k) {
        const Light& l = s.lights[s.miss_lights[k]];
        if (l.type == kLightSun && (l.cos_sun >= 1.0f || (camera && !l.visible_camera) ||
                                    dot(d, -l.direction) < l.cos_sun))
            continue;  // a sun lamp is hidden from the camera; the world's disc (of_world) not
        if (l.type == kLightWorld && camera && !l.visible_camera) continue;
        if (L && !bidir_emission_counts(s, ps, i, s.miss_lights[k])) continue;  // (linking)
        if (L && pt_lamp_unseen(s, ps, i, s.miss_lights[k])) continue;  // (ray kinds)
        float nee = 0.0f;
        float w = bdpt_emission_weight(s, ps, bs, st, i, l, kInf, vec3(0.0f), &nee);
        if (L && w > 0.0f && bidir_pt_weight(s, ps, i, s.miss_lights[k]))
            w = 1.0f / (1.0f + nee);
        if (L && w > 0.0f && bidir_rays_on(s) &&
            bidir_rays_pt_weight(s, ps, i, s.miss_lights[k])) {
            w = bidir_rays_emission_weight(s, ps, i, s.miss_lights[k], o, d, kInf, vec3(0.0f),
                                           0.0f);
            nee = bidir_rays_nee_ratio(w);
        }
        Vec3 le = l.type == kLightWorld ? world_radiance(s, l, d) : l.radiance;
        Vec3 c = ps.throughput[i] * le * w;
        if (st.moments) c = bdpt_moment(c, c, bdpt_pt_factor(1.0f / w, 1.0f, nee));
        add_radiance(ps, i, c);
    }
}

}  // namespace lantern
