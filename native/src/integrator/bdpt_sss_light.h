// Random-walk subsurface on the light paths of bdpt, lvc and cis (docs/subsurface.md, "Light
// paths walk"): lt's adjoint walk (lt_sss.h: the choice, the walk, the exit's lobe f_adj and its
// continuation) with the exit stored as a light vertex (connectable, splatted) and the MIS split
// between the two sets of techniques that can make a path with a walk. The walk is a stage of
// the light pass on every executor (schedule_bdpt.h; on a GPU a kernel of its own within the
// stack cap, its start and exit out of line: docs/cuda_backend.md).
//
// The split (2026-12-06, ssssplit). A path with a walk W is made by the techniques whose camera
// sub-path holds W (set C: the camera enters at x_front, exits at x_back) and those whose light
// sub-path holds it (set L: the light enters at x_back, exits at x_front). The walk is sampled,
// never evaluated, but its interior is reciprocal: the two sets' densities differ only at W's
// ends, by r = mis(pi q(w_1 | w) / |w_1 . n_g|) at x_front (w the view, w_1 the camera's first
// walk direction; q the entry's density, sss_entry_pdf; at x_back the light's cosine entry and
// the camera's arrival cancel), and by the segments beyond W's ends, which VCM's recursion
// already weighs. So each side's exit carries the other set as a dVCM: the camera exit
// dVCM = lf D_front / r (D_front = dVCM + dVC pdf_rev of the camera path at x_front, pdf_rev the
// light exit's lobe, lt_sss_exit_pdf, of the view), dVC = 0; the light exit
// dVCM = cf D_back (D_back = dVCM + dVC pdf_rev of the light path at x_back, pdf_rev the camera
// exit's Lambert lobe of the light's incoming direction), dVC = 0, times r(w) at each use (its
// r depends on the view w of the vertex that meets it: its connections, its splat, its
// continuation). lf, cf: whether the other side could have walked there. Every technique then
// weighs every other of both sets with the power heuristic over the whole path: the camera's
// pixel density against light tracing's count, the lamp's next-event density against its
// emission, the connections' densities. The light exit's splat counts lt_direct at x_back's
// k = 1 as the camera side does at a first vertex (NEE; the second vertex's emission). Several
// walks compose through the recursion. (sssbidir's 14-bit split code, which weighed the sets by
// r alone and 0/1 connectability, was removed after the whole-path split made it inert: every
// technique read 1 from it; sssbidir2.) Which side can walk at W: the camera on any triangle with subsurface, the light on those with Skin (lt's
// rule: lt hands Random Walk to pt, its tails; LANTERN_SSS_ADJOINT lets light paths walk Random
// Walk). Control 3 (LANTERN_SSS_ADJOINT=nosplit, the tests' negative control): both exits'
// dVCM 0, each set weighed within itself alone, every path both can make counted twice.
#pragma once

#include "integrator/bdpt_common.h"
#include "integrator/bdpt_motion.h"
#include "integrator/bidir_ray_visibility.h"
#include "integrator/lt_sss.h"

namespace lantern {

constexpr int16_t kLvSssExit = 2;  // LightVertex::front: the vertex is a light path's walk exit

// (the material as stored: its walk's weight and probability are not textured; sss_pick_prob
// at normal view stands in for every view, 0 only where the base has no share: metal, glass)
LANTERN_HD inline bool bdpt_sss_camera_walks(const SceneView& s, int tri) {
    return tri >= 0 && tri < s.num_triangles &&
           sss_pick_prob(s.materials[s.tri_material[tri]], 1.0f) > 0.0f;
}
// (scenes with media: no light path walks, and the camera's walks are not split, as with
// moments: the light exit's medium and its split in the media stages are not written)
LANTERN_HD inline bool bdpt_sss_light_walks(const SceneView& s, int tri) {
    if (s.num_media > 0 || !bdpt_sss_camera_walks(s, tri)) return false;
    return s.materials[s.tri_material[tri]].ss_skin || s.sss_adjoint_control != 0;
}
// Whether light paths walk and the exits carry the split: not where moments or a per-pixel
// connection map are on (their parts of dVC, pt's techniques, are not carried through a walk):
// there the camera side walks alone, its exits starting afresh (dVCM 0), as before sssbidir.
LANTERN_HD inline bool bdpt_sss_split_on(const BdptSettings& st) {
    return !st.moments && !st.conn_map;
}
// r at a walk's entry x (normals facing the view w): d the walk's direction at x, outward (the
// light's last, the camera's first reversed); the frame as sss_walk_path's and lt_sss_exit_f's
LANTERN_HD inline float bdpt_sss_ratio(const Material& m, const SurfaceHit& x, Vec3 d, Vec3 w) {
    const float cos_d = fabsf(dot(d, x.ng));
    if (!(cos_d > 0.0f)) return 0.0f;
    const Frame frame = sss_entry_frame(x, w);
    const float r = mis(kPi * sss_entry_pdf(m, frame.to_local(w), frame.to_local(-d)) / cos_d);
    return is_finite(r) ? r : 0.0f;
}
// s >= 2 to a light exit (bdpt_connect_in calls it; defined in bdpt_sss.h)
struct Connection;  // bdpt_camera.h
LANTERN_HD inline Connection bdpt_connect_sss_exit(const SceneView& s, const CameraVertex& z,
                                                   const LightVertex& y, Vec3 dir, float dist,
                                                   Vec3 wi_z);

// ---- At a light vertex (after its store and splat): lt's choice (lt_sss_choose). On a walk
// the slot keeps x_o's dVCM, dVC for the exit's count. ----
LANTERN_HD inline bool bdpt_light_sss_choose(const SceneView& s, const PathState& ps,
                                             const BdptState& bs, const BdptSettings& st, int i,
                                             const Material& m, const SurfaceHit& h, Vec3 wo_w,
                                             float cos_o_ns, float cos_o_ng, int k, float dvcm,
                                             float dvc) {
    const int tri = ps.hit_prim[i];
    if (!bdpt_sss_split_on(st) || k + 1 > st.max_depth || !bdpt_sss_light_walks(s, tri)) return false;
    if (!(sss_pick_prob(m, dot(wo_w, h.ns)) > 0.0f)) return false;  // (lt: 1 at max_depth)
    const PtSettings pst{st.max_depth, st.rr_depth, st.spp_per_iteration, st.seed, st.iteration};
    if (!lt_sss_choose(s, ps, pst, i, m, h, wo_w, cos_o_ns, cos_o_ng, k)) return false;
    // D_back: the camera-held set's techniques beyond x_o relative to the light's arrival at
    // x_o (the camera exit's Lambert lobe samples wo_w by |cos| / pi: dVC's reverse density)
    bs.dvcm[i] = s.sss_adjoint_control == 3 ? 0.0f : dvcm + dvc * mis(fabsf(cos_o_ns) * kInvPi);
    bs.dvc[i] = 0.0f;
    return true;
}

// ---- The exit at x_i (triangle tri, barycentrics uv, reached along d with throughput beta,
// the light's power apart): a light vertex with f_adj for its lobe (wo holds d), stored, splatted
// (weighed against the camera-held set: D_back r(view)) and continued as lt's exit; its
// dVCM = D_back (times r(w) where used), dVC = 0. Out of line on the device
// (LANTERN_DEVICE_NOINLINE): the walk kernel's frame holds the query ----
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline void bdpt_light_sss_exit(const SceneView& s, const PathState& ps,
                                           const BdptState& bs, const BdptSettings& st, int i,
                                           int64_t path, int tri, Vec2 uv, Vec3 d, Vec3 beta,
                                           Rng& rng) {
    if (tri >= s.num_triangles) return;
    const SurfaceHit x = bdpt_surface(s, st, path, tri, uv, -d);  // faces out, along d
    MaterialScratch scratch;
    const Material& m = material_at_point(
        s, s.tri_material[tri], [x, tri, uv] { return shade_point(x, tri, uv, x.ns); }, scratch);
    if (!(m.subsurface > 0.0f)) return;  // the camera walks only into subsurface
    const int k = ps.depth[i];
    // the exit's dVCM: D_back times cf (the camera can walk here); each use multiplies r(w) in
    const float d_back = bdpt_sss_camera_walks(s, tri) ? bs.dvcm[i] : 0.0f;
    const Vec3 power_beta = bs.power[i] * beta;
    LightVertex v;
    v.p = x.p;
    v.ng = x.ng;
    v.ns = x.ns;
    v.wo = d;
    v.beta = power_beta;
    v.dvcm = d_back;  // (times r(w) where used: bdpt_connect_sss_exit)
    v.dvc = 0.0f;
    v.material = s.tri_material[tri];
    v.tri = tri;
    v.bary16 = bary16_encode(uv);
    v.tangent_angle = x.tangent_angle;
    v.path = int32_t(path);
    v.length = int16_t(k);
    v.front = int16_t(uint16_t((x.front ? 1 : 0) | kLvSssExit));
    v.coat_n = (m.tex_flags & kCoatNormal) || material_keeps_unbent_normal(m)
                   ? oct_encode(x.coat_n)
                   : 0u;
    v.dpt0 = 0.0f;
    v.dpt1 = 0.0f;
    bs.vertex[i] = v;
    // an exit on an R surface is splatted only (bidir_ray_visibility.h: as x1 alone it restricts
    // nothing; stored or continued it would be the light-side end of a segment past x1)
    const bool restricted = bidir_tri_restricted(s, tri);
    bs.store[i] = is_finite(power_beta) && !restricted ? 1 : 0;
    if (k + 1 <= st.max_depth && (s.tri_flags[tri] & kVisibleCamera) != 0) {  // t = 1
        const CameraView cam = s.motion.camera_steps > 1 ? bdpt_camera_moved(s, st, path)
                                                         : s.camera;
        const bool lens = cam.lens_radius > 0.0f && !cam.orthographic && !cam.panoramic;
        const Vec2 u_lens = lens ? sample_aperture(cam, rng.uniform2()) : Vec2{};
        const CameraConnection cc = connect_camera(cam, x.p, filter_radius(cam), u_lens);
        if (cc.valid) {
            const Vec3 f = lt_sss_exit_f(m, x, d, cc.wc, s.sss_adjoint_control);
            const float cos_c = dot(cc.wc, x.ng);
            // bdpt_light_tracing_weight's count, k x_o's: the camera side's techniques count
            // light tracing as the path's first light vertex were this exit (NEE at a first
            // camera vertex, emission at a second: BdptSettings::lt_direct). Control 6
            // (LANTERN_SSS_ADJOINT=nodirect, a test's): n_lt alone
            const float n_lt =
                k == 1 && s.sss_adjoint_control != 6 ? st.n_lt * st.lt_direct : st.n_lt;
            if (!is_black(f)) {
                LightPathState lp{nullptr, bs.splat_xy};
                lt_queue_splat(ps, lp, i, x.p, x.ng, cc,
                               power_beta * f *
                                   (cos_c * cc.importance *
                                    (1.0f / (1.0f + mis(cc.importance * cos_c * st.r / n_lt) *
                                                        d_back * bdpt_sss_ratio(m, x, d, cc.wc)))),
                               s.offset_scale);
            }
        }
    }
    if (restricted || k + 2 > st.max_depth) return;  // (no technique could use the next vertex)
    Vec3 wo, t;
    float pdf_w;
    if (!lt_sss_exit_continue(s, m, x, d, beta, k, st.rr_depth, rng, &wo, &pdf_w, &t)) return;
    ps.throughput[i] = t;
    // bdpt_scatter_update with the exit's dVCM = D_back r(wo), dVC = 0
    bs.dvc[i] = mis(fabsf(dot(wo, x.ng)) / pdf_w) * d_back * bdpt_sss_ratio(m, x, d, wo);
    bs.dvcm[i] = mis(1.0f / pdf_w);
    set_next_ray(ps, i, x.p, x.ng, wo, pdf_w, s.offset_scale);
}

// ---- The walk stage of the light pass (schedule_bdpt.h, after the bounce's stores and
// splats): for a slot with alive == kAliveSss, lt's entry at x_o (a cosine about the inward
// geometric normal), the walk in x_o's medium, the exit. Every other slot's store and splat is
// done: cleared, so that the exits' go alone through a second round. ----
template <class Rays, class Kind>
LANTERN_HD inline void bdpt_light_sss_walk(const SceneView& s, const Rays& rays, Kind kind,
                                           const PathState& ps, const BdptState& bs,
                                           const BdptSettings& st, int i, int64_t path) {
    ps.shadow_valid[i] = 0;
    bs.store[i] = 0;
    if (ps.alive[i] != kAliveSss) return;
    ps.alive[i] = 0;
    Rng rng = ps.rng[i];
    const float time = s.motion.rays_timed() ? bdpt_time(st, path) : 0.0f;
    const int tri = ps.hit_prim[i];
    const Vec2 uv = ps.hit_uv[i];
    const Vec3 d = ps.ray_d[i];
    lt_sss_entry(s, rays, kind,
                 [&] { return bdpt_surface(s, st, path, tri, uv, d); },  // faces the light
                 tri, uv, d, ps.throughput[i], rng, time,
                 [&](int prim, Vec2 xuv, Vec3 last, Vec3 beta) {
                     bdpt_light_sss_exit(s, ps, bs, st, i, path, prim, xuv, last, beta, rng);
                 });
    ps.rng[i] = rng;
}

}  // namespace lantern
