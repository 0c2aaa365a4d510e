// Bidirectional stages shared by the integrators "bdpt", "lvc" and "cis": light sub-paths whose
// non-delta vertices go into the light vertex cache (LVC) and are splatted to the camera (t = 1),
// and camera sub-paths that add emission (s = 0), next-event estimation (s = 1) and connections
// to cache vertices (s >= 2). MIS: the balance of Georgiev's "Implementing Vertex Connection and
// Merging" (2012) report with the power heuristic, i.e. SmallVCM's recursive dVCM / dVC, with the
// sample counts of the cache folded in (docs/lvc_notes.md, "MIS with a vertex cache"):
//
//   technique              count per camera sample
//   s = 0 (hit a light)    1
//   s = 1 (next event)     1
//   s >= 2 (connection)    r = N L / |C|   (bdpt: 1, every vertex of the paired light path)
//   t = 1 (light tracing)  n_lt = L / spp_per_iteration
//
// Every stage touches one path slot; the session (bdpt_session.cpp) runs them over queues.
#pragma once

#include "bsdf/material.h"
#include "integrator/light_path.h"
#include "integrator/lt.h"

namespace lantern {

LANTERN_HD inline float mis(float x) { return x * x; }  // power heuristic, beta = 2

enum BdptMode : int32_t {
    kBdptOwnPath = 0,  // "bdpt": camera path i connects to every vertex of light path i
    kLvcUniform = 1,   // "lvc": N uniform picks from the cache
    kCisResampled = 2, // "cis": M uniform candidates, N picks proportional to a target p-hat
};
enum CisTarget : int32_t { kTargetContribution = 0, kTargetBsdf = 1 };

// One stored light vertex: what a later connection needs.
struct LightVertex {
    Vec3 p;
    Vec3 ng;        // geometric normal on the side the light arrived from
    Vec3 ns;        // shading normal, same side as ng
    Vec3 wo;        // unit direction towards the previous vertex of the light path
    Vec3 beta;      // light sub-path throughput, emitted flux / pick probability included
    float dvcm, dvc;
    uint32_t material;
    int32_t tri;    // the triangle and (bary16) its barycentrics, 2 x 16-bit unorm: textured
    uint32_t bary16;  // and node-graph materials are resolved at connection (shade_point_lv)
    float tangent_angle;  // anisotropic materials: the frame's turn about ns (SurfaceHit)
    int32_t path;   // light path index (bdpt pairs camera path i with light path i)
    int16_t length; // segments from the light to this vertex (y1 has 1; max_depth <= 1024)
    int16_t front;
    uint32_t coat_n;  // kCoatNormal, material_keeps_unbent_normal: SurfaceHit::coat_n (oct_encode)
    float dpt0, dpt1; // BdptSettings::moments: path tracing's techniques (BdptState::dpt0)
};

static_assert(sizeof(LightVertex) == 104, "update the cache size in docs/lvc_notes.md");

LANTERN_HD inline uint32_t bary16_encode(Vec2 b) {
    auto q = [](float v) { return uint32_t(clampf(v, 0.0f, 1.0f) * 65535.0f + 0.5f); };
    return q(b.x) | (q(b.y) << 16);
}
LANTERN_HD inline Vec2 bary16_decode(uint32_t c) {
    return Vec2{float(c & 0xFFFFu) * (1.0f / 65535.0f), float(c >> 16) * (1.0f / 65535.0f)};
}
// The shading point of a cache vertex, seen from direction wo (the camera vertex it connects
// to: Cycles' I for view-dependent nodes).
LANTERN_HD inline ShadePoint shade_point_lv(const SceneView& s, const LightVertex& y, Vec3 wo) {
    ShadePoint sp;
    sp.p = y.p;
    sp.n = y.ns;
    sp.ng = y.ng;
    sp.wo = wo;
    sp.tri = y.tri;
    sp.bary = bary16_decode(y.bary16);
    sp.st = triangle_uv(s, y.tri, sp.bary);
    sp.backfacing = y.front == 0;
    return sp;
}

// material_eval with its commonest case inline, the same arithmetic: an unbumped Lambert (a
// connection evaluates two BSDFs per candidate, M per camera vertex; the call costs as much as
// the eval). Cycles' diffuse reads the light's side only, its view-side pdf about ng.
LANTERN_HD inline BsdfEval bdpt_eval(const Material& m, bool front, Vec3 wo, Vec3 wi,
                                     Transport mode, Vec3 coat_n, const Frame& f, Vec3 ng) {
    if (material_is_lambert(m) && !(m.tex_flags & (kTexBump | kTexNormal)))
        return lambert_bumped_eval(m.base_color, Vec3{0.0f, 0.0f, 1.0f}, f.to_local(ng), wo, wi,
                                   mode == Transport::Radiance);
    return material_eval(m, front, wo, wi, mode, coat_n, f.to_local(ng));
}

struct BdptSettings {
    int32_t max_depth, rr_depth, spp_per_iteration;
    uint64_t seed, iteration;
    int32_t mode;        // BdptMode
    int32_t connections; // N
    int32_t candidates;  // M
    int32_t target;      // CisTarget
    int32_t naive_ris;   // test only: give resampled picks the uniform weight |C|/N (biased)
    float r;             // MIS count of a connection: N L / |C| (bdpt: 1)
    float n_lt;          // MIS count of light tracing: L / spp_per_iteration
    float inv_light_paths;  // 1 / L
    float lt_direct;     // light tracing's count for direct light, relative to n_lt (see below)
    int32_t moments;     // integrator "auto"'s cis trials: moment channels (bdpt_moment)
};

// Integrator "auto" (allocation.h) estimates path tracing's second moment from cis's samples
// through the MIS identity: for weights that sum to one, sum_t sum_i w_t g / p_t is unbiased
// for the integral of g; with g = f^2 / q (q: pt's density of the path, its own power-heuristic
// mix of BSDF sampling, s = 0, and next-event estimation, s = 1), each contribution c = w_t f /
// (n_t p_t) adds c f / q. With a = (p_0 / n_t p_t)^2, b = (p_1 / n_t p_t)^2 (the squared
// ratios the recursive weights sum; cis's s = 0 and s = 1 are pt's techniques, count 1) and
// 1 / w_t = 1 + sum of every ratio, f / q = c_unit (1 / w_t) (a^1.5 + b^1.5) / (a + b)^2, where
// pt's power heuristic makes its second moment f^2 (p_0^3 + p_1^3) / (p_0^2 + p_1^2)^2.
// c_unit: c without resampling's random weight (its expectation is the same). A cis trial of
// "auto" (moments on) writes instead of each contribution's RGB the channels (luminance of c,
// its pt second-moment term, luminance of light pt cannot sample: a + b = 0). Only the
// luminance of the contributions is used, and a splat's filter weight enters linearly: an
// estimate for a choice, never an image (trials are never added to it).
LANTERN_HD inline float bdpt_pt_factor(float inv_w, float a, float b) {
    if (!(a + b > 0.0f)) return -1.0f;  // pt cannot sample the path
    const float mx = fmaxf(a, b), an = a / mx, bn = b / mx;  // (overflows late)
    return inv_w * (an * sqrtf(an) + bn * sqrtf(bn)) / ((an + bn) * (an + bn) * sqrtf(mx));
}
LANTERN_HD inline Vec3 bdpt_moment(Vec3 c, Vec3 c_unit, float pt_factor) {
    const float l = fabsf(luminance(c));
    if (!(l > 0.0f)) return vec3(0.0f);
    if (pt_factor < 0.0f) return Vec3{l, 0.0f, l};
    float m = l * fabsf(luminance(c_unit)) * pt_factor;
    if (!(m < 1e30f)) m = 1e30f;
    return Vec3{l, m, 0.0f};
}

// Light tracing's MIS count on paths of two segments (light, surface, camera: direct light),
// relative to n_lt. Next-event estimation and light tracing often have similar densities there,
// and the power heuristic then shares direct light between them, but light tracing's number of
// paths that reach a pixel is random where a pixel's camera samples are a fixed number: its
// share is noisier than its density says (room_area_point at max_depth 2: cis 2.3x pt's noise
// at equal spp with the count n_lt, 0.98x with n_lt / 4; bench/results/2026-12-04-cis-profile).
// Any positive count keeps the weights a partition of unity, as long as every technique of
// such a path uses it: the light tracing splat of a first light vertex (k = 1), next-event
// estimation at the first camera vertex and the second camera vertex's emission (where the
// light tracing term is the whole of z.dvcm, respectively dvc). Longer paths keep n_lt.
LANTERN_HD inline float bdpt_direct_lt(const BdptSettings& st) { return mis(st.lt_direct); }

// Slots beyond PathState. Light pass: the light a path started on, the vertex it may store and
// its splat position. Camera pass: up to conn_cap connection shadow rays per slot.
struct BdptState {
    float* dvcm;
    float* dvc;
    int32_t* light;
    uint8_t* store;
    LightVertex* vertex;
    Vec2* splat_xy;
    Vec3* power;        // light pass: emitted flux / pick probability (constant along the path;
                        // kept out of the throughput so that roulette does not depend on units)
    int32_t conn_cap;
    int32_t* conn_n;
    Vec3* conn_o;
    Vec3* conn_d;
    float* conn_tmax;
    Vec3* conn_c;
    float* dpt0;  // BdptSettings::moments, light pass: dvc's parts that are pt's techniques
    float* dpt1;
};

// What the camera pass reads of the cache.
struct LightCache {
    const LightVertex* v;
    int32_t size;
    const int32_t* path_offset;  // bdpt: vertices of light path j are path_vertex[off[j] .. off[j+1])
    const int32_t* path_vertex;
};

// ---- Light pass ---------------------------------------------------------------------------------

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
    float u_pick = rng.uniform();
    Vec2 u_pos = rng.uniform2(), u_dir = rng.uniform2();
    ps.rng[i] = rng;
    if (!s.emit_cdf) return;
    int li = sample_cdf(s.emit_cdf, s.num_lights, u_pick);
    const Light& l = s.lights[li];
    if (!(l.emit_pick_pdf > 0.0f)) return;
    EmissionSample es = sample_emission(s, l, u_pos, u_dir);
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
    if (st.moments) {  // path tracing's techniques: all camera-sampled (dVC's), next-event
        bs.dpt0[i] = bs.dvc[i];
        bs.dpt1[i] = 0.0f;
    }
    if (st.max_depth < 2) return;
    ps.ray_o[i] = is_black(es.n) ? es.p : offset_ray_origin(es.p, es.n, es.d, s.offset_scale);
    ps.ray_d[i] = es.d;
    ps.ray_tmin[i] = 0.0f;
    ps.ray_tmax[i] = kInf;
    ps.prev_pdf_w[i] = pdf_emit;
    ps.alive[i] = 1;
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

// MIS recursion after sampling a direction with pdfs (fwd, rev) at a vertex whose geometric
// cosine with the sampled direction is cos_out (both sub-paths use it).
LANTERN_HD inline void bdpt_scatter_update(float& dvcm, float& dvc, const BsdfSample& b,
                                           float cos_out) {
    if (b.delta) {  // a delta vertex cannot be connected (dVCM = 0); the discrete probabilities
                    // of the two directions (equal for a pure delta lobe) stay as their ratio
        dvc *= mis(cos_out * (b.pdf_fwd_w > 0.0f ? b.pdf_rev_w / b.pdf_fwd_w : 1.0f));
        dvcm = 0.0f;
    } else {
        dvc = mis(cos_out / b.pdf_fwd_w) * (dvc * mis(b.pdf_rev_w) + dvcm);
        dvcm = mis(1.0f / b.pdf_fwd_w);
    }
}

// At a light path's hit: MIS update, the vertex to store, the camera splat, the next direction.
LANTERN_HD inline void bdpt_light_shade(const SceneView& s, const PathState& ps,
                                        const BdptState& bs, const BdptSettings& st, int i,
                                        int64_t path) {
    ps.shadow_valid[i] = 0;
    ps.alive[i] = 0;
    bs.store[i] = 0;
    int tri = ps.hit_prim[i];
    if (tri < 0) return;
    const Vec3 d = ps.ray_d[i];
    const float dist = ps.hit_t[i];
    SurfaceHit h = pt_surface(s, tri, ps.hit_uv[i], d);
    MaterialScratch scratch;
    const Material& m = material_at_point(
        s, s.tri_material[tri], [&] { return shade_point(h, tri, ps.hit_uv[i], -d); }, scratch);
    const int k = ps.depth[i] + 1;  // segments from the light to this vertex
    ps.depth[i] = k;
    const Vec3 wo_w = -d;
    const float cos_o_ns = fabsf(dot(wo_w, h.ns)), cos_o_ng = fabsf(dot(wo_w, h.ng));
    if (!(cos_o_ng > 0.0f) || !(dist > 0.0f)) return;

    // ---- MIS quantities at this vertex ----
    float dvcm = bs.dvcm[i], dvc = bs.dvc[i];
    const Light& l = s.lights[bs.light[i]];
    const bool infinite = l.type == kLightSun || l.type == kLightWorld;
    if (k == 1 && (l.type == kLightPoint || l.type == kLightSpot) && l.radius > 0.0f) {
        // next-event estimation samples a sphere light's visible cap: its area density at y0
        // depends on the receiver y1 (here), not 1 / area as assumed at generation
        Vec3 y0 = ps.ray_o[i];
        Vec3 n0 = normalize(y0 - l.position);
        float pdf_a = light_pdf_w(l, h.p, wo_w, dist, n0) * fabsf(dot(d, n0)) / (dist * dist);
        dvcm *= mis(pdf_a * (4.0f * kPi * l.radius * l.radius));
    }
    if (k == 1) {  // next-event estimation from here picks this light with this probability
        dvcm *= mis(light_pick_pmf(s, bs.light[i], h.p, light_pick_normal(s, tri, h.ng)));
    }
    if (k > 1 || !infinite) dvcm *= mis(dist * dist);
    dvcm /= mis(cos_o_ng);
    dvc /= mis(cos_o_ng);
    // (moments) the parts of dvc that are pt's techniques: dpt0 all camera-sampled, dpt1 the
    // camera sampling all but y0, which next-event estimation samples (at k = 1: dvcm itself)
    float dpt0 = 0.0f, dpt1 = 0.0f;
    if (st.moments) {
        dpt0 = bs.dpt0[i] / mis(cos_o_ng);
        dpt1 = bs.dpt1[i] / mis(cos_o_ng);
    }

    Frame frame = h.frame();
    const Vec3 wo = frame.to_local(wo_w);
    const Vec3 beta = bs.power[i] * ps.throughput[i];
    const bool delta = material_is_delta(m);

    if (!delta) {
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
        CameraConnection cc = connect_camera(s.camera, h.p, filter_radius(s.camera),
                                             lens_sample(s.camera, ps, i));
        if (cc.valid && view_side_agrees(m, cc.wc, h.ng, h.ns)) {
            BsdfEval e = bdpt_eval(m, h.front, wo, frame.to_local(cc.wc), Transport::Importance,
                                   h.coat_n, frame, h.ng);
            if (!is_black(e.f)) {
                float cos_wc_ng = fabsf(dot(cc.wc, h.ng));
                // f |wc.ns| times the adjoint shading-normal factor [Veach thesis (5.19)]
                float cos_y = cos_o_ns * cos_wc_ng / cos_o_ng;
                float w = bdpt_light_tracing_weight(st, dvcm, dvc, cc.importance * cos_wc_ng,
                                                    e.pdf_rev_w, k);
                LightPathState lp{nullptr, bs.splat_xy};
                Vec3 c = beta * e.f * (cos_y * cc.importance * w);
                if (st.moments) {
                    const float n_lt = k == 1 ? st.n_lt * st.lt_direct : st.n_lt;
                    const float x = mis(cc.importance * cos_wc_ng * st.r / n_lt);
                    const float a = x * dpt0 * mis(e.pdf_rev_w);
                    const float b = x * (k == 1 ? dvcm : dpt1 * mis(e.pdf_rev_w));
                    // f / q of the contribution the sum receives, c / st.n_lt (the splat's
                    // scale, wavefront.h's splat()), is that times st.n_lt / n_lt (the count its
                    // weight assumes: lt_direct): c / n_lt
                    c = bdpt_moment(c, c * (1.0f / n_lt), bdpt_pt_factor(1.0f / w, a, b));
                }
                lt_queue_splat(ps, lp, i, h.p, h.ng, cc, c, s.offset_scale);
            }
        }
    }
    if (k + 2 > st.max_depth) return;  // the next vertex could not be used by any technique

    // ---- continue with the adjoint BSDF ----
    Rng rng = ps.rng[i];
    Vec2 u_dir = rng.uniform2();
    BsdfSample b = material_sample(m, h.front, wo, Vec3{u_dir.x, u_dir.y, rng.uniform()},
                                   Transport::Importance, h.coat_n, frame.to_local(h.ng));
    Vec3 wi = frame.to_world(b.wi);
    if (b.valid && view_side_agrees(m, wi, h.ng, h.ns) && (b.delta || b.pdf_fwd_w > 0.0f)) {
        float cos_i_ng = fabsf(dot(wi, h.ng));
        float adj = cos_o_ns * cos_i_ng / (cos_o_ng * fabsf(b.wi.z));
        Vec3 t = ps.throughput[i] * b.weight * adj;
        if (russian_roulette(t, k + 1, st.rr_depth, rng) && max_component(t) > 0.0f &&
            is_finite(t)) {
            if (st.moments) {  // dvc's recursion, each part on its own (dvcm: k = 1 only)
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
        }
    }
    ps.rng[i] = rng;
}

// ---- Camera pass --------------------------------------------------------------------------------

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

LANTERN_HD inline void bdpt_camera_generate(const SceneView& s, const PathState& ps,
                                            const BdptState& bs, const BdptSettings& st, int i,
                                            int64_t path) {
    // the same camera sample as pt's (same random stream), plus the MIS quantities
    const PtSettings pst{st.max_depth, st.rr_depth, st.spp_per_iteration, st.seed, st.iteration};
    pt_generate(s, ps, pst, i, path);
    bs.conn_n[i] = 0;
    // the light tracing technique relative to a connection (count r); none without light paths
    // (then r = 0 too: every weight of the camera pass is path tracing's)
    bs.dvcm[i] = st.n_lt > 0.0f ? mis(st.n_lt / (st.r * camera_pdf(s.camera, ps.ray_d[i])))
                                : 0.0f;
    bs.dvc[i] = 0.0f;
}

// Weight of emission le found by the camera path at distance t_light along its ray, on light l
// with geometric normal n there. dvcm, dvc are the slot's values before this segment.
LANTERN_HD inline float bdpt_emission_weight(const SceneView& s, const PathState& ps,
                                             const BdptState& bs, const BdptSettings& st, int i,
                                             const Light& l, float t_light, Vec3 n,
                                             float* nee_ratio = nullptr) {
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
    float pdf_emit = l.emit_pick_pdf * emission_pdf(s, l, n, -d).pdf_emit;
    // (the second vertex: dvc is light tracing's term alone, BdptSettings::lt_direct)
    if (ps.depth[i] == 2) dvc *= bdpt_direct_lt(st);
    float w_camera = mis(pdf_direct) * dvcm + mis(st.r * pdf_emit) * dvc;
    if (nee_ratio) *nee_ratio = mis(pdf_direct) * dvcm;  // next-event estimation's (moments)
    return 1.0f / (1.0f + w_camera);
}

// Lights crossed by the segment, and the background on a miss (s = 0).
LANTERN_HD inline void bdpt_camera_emission(const SceneView& s, const PathState& ps,
                                            const BdptState& bs, const BdptSettings& st, int i,
                                            float t_end, bool miss) {
    const Vec3 o = ps.ray_o[i], d = ps.ray_d[i];
    const bool camera = ps.depth[i] <= 1;
    for (int k = 0; k < s.num_hittable_lights; ++k) {
        const Light& l = s.lights[s.hittable_lights[k]];
        if (camera && !l.visible_camera) continue;
        LightHit h = intersect_light(l, o, d, ps.ray_tmin[i], t_end);
        if (!h.hit || is_black(h.le)) continue;
        float nee = 0.0f;
        float w = bdpt_emission_weight(s, ps, bs, st, i, l, h.t, h.n, &nee);
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
        float nee = 0.0f;
        float w = bdpt_emission_weight(s, ps, bs, st, i, l, kInf, vec3(0.0f), &nee);
        Vec3 le = l.type == kLightWorld ? world_radiance(s, l, d) : l.radiance;
        Vec3 c = ps.throughput[i] * le * w;
        if (st.moments) c = bdpt_moment(c, c, bdpt_pt_factor(1.0f / w, 1.0f, nee));
        add_radiance(ps, i, c);
    }
}

// On a GPU thread a connection resolves the cache vertex's material into the camera vertex's
// scratch (one MaterialScratch on the shade kernel's stack, not two: 600 B of its frame) and
// then the camera vertex's again (the same inputs, so the same material). The CPU keeps both.
#ifdef __CUDA_ARCH__
constexpr bool kOneScratch = true;
#else
constexpr bool kOneScratch = false;
#endif

// A camera vertex: what next-event estimation and connections read.
struct CameraVertex {
    SurfaceHit h;
    Frame frame;
    Vec3 wo;      // local
    Vec3 beta;
    float dvcm, dvc;
    const Material* m;
    int depth;    // segments from the camera
    Vec3 n_pick;  // the normal the light tree sees here (light_pick_normal)
    Vec3 ng_l;    // the geometric normal in frame (what a bumped Lambert reads)
    // kOneScratch: where m may live, and what resolves it again (the hit's triangle, its
    // barycentrics and the direction towards the previous vertex)
    MaterialScratch* scratch;
    int tri;
    Vec2 uv;
    Vec3 wo_w;
};

// The camera vertex's material, resolved (again) into its scratch: shade_point as the shade
// stage built it.
LANTERN_HD inline const Material& camera_vertex_material(const SceneView& s,
                                                         const CameraVertex& z) {
    return material_at_point(
        s, s.tri_material[z.tri], [&] { return shade_point(z.h, z.tri, z.uv, z.wo_w); },
        *z.scratch);
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

// s = 1: one light sample; the shadow ray waits in the slot's shadow fields.
LANTERN_HD inline void bdpt_camera_nee(const SceneView& s, const PathState& ps,
                                       const BdptSettings& st, const CameraVertex& z, int i,
                                       Rng& rng) {
    Vec2 u_pick = rng.uniform2();
    Vec2 u_light = rng.uniform2();
    const LightPick pick = light_pick(s, z.h.p, z.n_pick, u_pick.x);
    if (!(pick.pmf > 0.0f)) return;
    const Light& l = s.lights[pick.light];
    LightSample ls = sample_light(s, l, z.h.p, u_light);
    if (!ls.valid || is_black(ls.le) || !light_side_agrees(*z.m, ls.wi, z.h.ng, z.h.ns)) return;
    BsdfEval e = material_eval(*z.m, z.h.front, z.wo, z.frame.to_local(ls.wi), Transport::Radiance,
                               z.h.coat_n, z.ng_l);
    float pdf_light_w = pick.pmf * ls.pdf_w;
    if (is_black(e.f) || !(pdf_light_w > 0.0f)) return;
    const bool infinite = !(ls.dist < kInf);
    const float cos_z = fabsf(dot(ls.wi, z.h.ng));
    // densities of the light point: by next-event estimation, by the light sub-path (s = 2)
    float cos_l = is_black(ls.n_light) ? 1.0f : fabsf(dot(ls.wi, ls.n_light));
    float pdf_nee, pdf_lp;
    float pdf_emit = l.emit_pick_pdf * emission_pdf(s, l, ls.n_light, -ls.wi).pdf_emit;
    if (infinite) {
        pdf_nee = pdf_light_w;
        pdf_lp = pdf_emit * cos_z;
    } else {
        float d2 = ls.dist * ls.dist;
        pdf_nee = ls.delta ? pick.pmf : pdf_light_w * cos_l / d2;
        pdf_lp = pdf_emit * cos_z / d2;
    }
    float w_light = ls.delta ? 0.0f : mis(e.pdf_fwd_w / pdf_light_w);
    // (the first vertex: z.dvcm is light tracing's term alone, BdptSettings::lt_direct)
    const float dvcm_z = z.depth == 1 ? z.dvcm * bdpt_direct_lt(st) : z.dvcm;
    float w_camera = mis(st.r * pdf_lp / pdf_nee) * (dvcm_z + z.dvc * mis(e.pdf_rev_w));
    float w = 1.0f / (w_light + 1.0f + w_camera);
    float cos_i = fabsf(dot(ls.wi, z.h.ns));
    Vec3 c = z.beta * e.f * ls.le * (cos_i * w / pdf_light_w);
    if (st.moments) c = bdpt_moment(c, c, bdpt_pt_factor(w_light + 1.0f + w_camera, w_light, 1.0f));
    if (!is_finite(c)) {
        ps.dropped[i] = 1;
        return;
    }
    Vec3 target_n = ls.dist < kInf ? ls.n_light : vec3(0.0f);
    if (ls.dist < kInf) {
        shadow_segment(z.h.p, z.h.ng, ls.p_light, target_n, ls.wi, s.offset_scale, &ps.shadow_o[i],
                       &ps.shadow_d[i], &ps.shadow_tmax[i]);
    } else {
        ps.shadow_o[i] = offset_ray_origin(z.h.p, z.h.ng, ls.wi, s.offset_scale);
        ps.shadow_d[i] = ls.wi;
        ps.shadow_tmax[i] = kInf;
    }
    ps.shadow_contrib[i] = c;
    ps.shadow_valid[i] = 1;
}

// s >= 2: the unshadowed, MIS-weighted contribution of connecting z to cache vertex y (per unit
// estimator weight), and the BSDF-product target. Zero when the path would be too long.
struct Connection {
    Vec3 c;
    Vec3 dir;      // unit, z -> y
    float dist;
    float bsdf_target;
    float pt_factor;  // BdptSettings::moments: bdpt_pt_factor
};

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
    if (!(material_corrects_view(*z.m) ? dz_ng > 0.0f : dz_ng * wi_z.z > 0.0f)) return r;
    const float dy_ns = dot(-dir, y.ns);
    const bool y_geometric = material_view_geometric(s.materials[y.material]);
    if (!(y_geometric ? dy_ng > 0.0f : dy_ng * dy_ns > 0.0f)) return r;
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
    BsdfEval ey = bdpt_eval(my, y.front != 0, wo_y, wi_y, Transport::Importance, coat_y, fy, y.ng);
    if (is_black(ey.f)) return r;
    const float cos_z_ng = fabsf(dz_ng), cos_y_ng = fabsf(dy_ng);
    const float cos_z_ns = fabsf(wi_z.z);
    const float cos_yo_ns = fabsf(wo_y.z), cos_yo_ng = fabsf(dot(y.wo, y.ng));
    if (!(cos_yo_ng > 0.0f)) return r;
    // light side: f |dir.ns| with the adjoint shading-normal factor
    const float cos_y = cos_yo_ns * cos_y_ng / cos_yo_ng;
    const float inv_d2 = 1.0f / d2;
    float pdf_cam_a = ez.pdf_fwd_w * cos_y_ng * inv_d2;   // camera BSDF samples y
    float pdf_light_a = ey.pdf_fwd_w * cos_z_ng * inv_d2; // light BSDF samples z
    float w_light = mis(pdf_cam_a) * (y.dvcm + y.dvc * mis(ey.pdf_rev_w));
    float w_camera = mis(pdf_light_a) * (z.dvcm + z.dvc * mis(ez.pdf_rev_w));
    float w = 1.0f / (w_light + 1.0f + w_camera);
    r.c = z.beta * ez.f * y.beta * ey.f * (cos_z_ns * cos_y * inv_d2 * w);
    if (!is_finite(r.c)) r.c = vec3(0.0f);
    r.dir = dir;
    r.dist = dist;
    r.bsdf_target = luminance(ez.f) * luminance(ey.f);
    if (st.moments) {  // pt's techniques: dpt0, dpt1 as dvc's parts (dvcm itself for y1)
        const float rev = mis(ey.pdf_rev_w), x = mis(pdf_cam_a);
        r.pt_factor = bdpt_pt_factor(w_light + 1.0f + w_camera, x * y.dpt0 * rev,
                                     x * (y.length == 1 ? y.dvcm : y.dpt1 * rev));
    }
    return r;
}

LANTERN_HD inline Connection bdpt_connect(const SceneView& s, const BdptSettings& st,
                                          const CameraVertex& z, const LightVertex& y) {
    bool clobbered = false;  // the cache vertex's material took z's scratch (kOneScratch)
    const Connection r = bdpt_connect_in(s, st, z, y, &clobbered);
    if (kOneScratch && clobbered && z.m == &z.scratch->m) camera_vertex_material(s, z);
    return r;
}

LANTERN_HD inline void bdpt_queue_connection(const BdptState& bs, int i, const CameraVertex& z,
                                             const LightVertex& y, const Connection& c,
                                             Vec3 contrib, float offset_scale) {
    int j = bs.conn_n[i];
    if (j >= bs.conn_cap || is_black(contrib) || !is_finite(contrib)) return;
    int e = i * bs.conn_cap + j;
    shadow_segment(z.h.p, z.h.ng, y.p, y.ng, c.dir, offset_scale, &bs.conn_o[e], &bs.conn_d[e],
                   &bs.conn_tmax[e]);
    bs.conn_c[e] = contrib;
    bs.conn_n[i] = j + 1;
}

// A candidate the CPU keeps for its picks: what bdpt_queue_connection reads of its Connection.
struct KeptCandidate {
    float cx, cy, cz, dx, dy, dz, pt_factor;
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
// (resampled). Each queued shadow ray carries its estimator weight.
LANTERN_HD inline void bdpt_camera_connect(const SceneView& s, const BdptState& bs,
                                           const BdptSettings& st, const LightCache& cache,
                                           const CameraVertex& z, int i, int64_t path) {
    bs.conn_n[i] = 0;
    // every cache vertex is at least one segment from its light: past max_depth from here
    if (cache.size <= 0 || z.depth + 2 > st.max_depth) return;
    if (st.mode == kBdptOwnPath) {
        for (int k = cache.path_offset[path]; k < cache.path_offset[path + 1]; ++k) {
            const LightVertex& y = cache.v[cache.path_vertex[k]];
            Connection c = bdpt_connect(s, st, z, y);
            const Vec3 contrib = st.moments ? bdpt_moment(c.c, c.c, c.pt_factor) : c.c;
            bdpt_queue_connection(bs, i, z, y, c, contrib, s.offset_scale);
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
            if (st.moments) contrib = bdpt_moment(contrib, contrib, c.pt_factor);
            bdpt_queue_connection(bs, i, z, y, c, contrib, s.offset_scale);
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
            cand[j] = KeptCandidate{c.c.x, c.c.y, c.c.z, c.dir.x, c.dir.y, c.dir.z, c.pt_factor};
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
        } else {
            c = bdpt_connect(s, st, z, y);
        }
        Vec3 contrib = c.c * weight;
        // (moments: the unit contribution is the uniform pick's, size / (N L))
        if (st.moments) {
            const float uniform = size / float(st.connections) * st.inv_light_paths;
            contrib = bdpt_moment(contrib, c.c * uniform, c.pt_factor);
        }
        bdpt_queue_connection(bs, i, z, y, c, contrib, s.offset_scale);
    }
}

// Camera-path shading: emission (s = 0), then at a surface NEE (s = 1), connections (s >= 2) and
// the next direction. The three parts are separate functions so a GPU can launch them apart.
LANTERN_HD inline void bdpt_camera_shade(const SceneView& s, const PathState& ps,
                                         const BdptState& bs, const BdptSettings& st,
                                         const LightCache& cache, int i, int64_t path) {
    ps.shadow_valid[i] = 0;
    ps.alive[i] = 0;
    bs.conn_n[i] = 0;
    const int tri = ps.hit_prim[i];
    const Vec3 d = ps.ray_d[i];
    const float t_hit = ps.hit_t[i];
    bdpt_camera_emission(s, ps, bs, st, i, tri >= 0 ? t_hit : ps.ray_tmax[i], tri < 0);
    if (tri < 0) return;
    CameraVertex z;
    MaterialScratch scratch;  // z.m points here when the material is resolved
    z.h = pt_surface(s, tri, ps.hit_uv[i], d);
    z.scratch = &scratch;
    z.tri = tri;
    z.uv = ps.hit_uv[i];
    z.wo_w = -d;
    z.m = &camera_vertex_material(s, z);
    z.depth = ps.depth[i];
    const float cos_in = fabsf(dot(d, z.h.ng));
    if (!(cos_in > 0.0f) || !(t_hit > 0.0f)) return;
    // MIS update for the new vertex (an orthographic camera's first vertex has no distance term)
    float dvcm = bs.dvcm[i], dvc = bs.dvc[i];
    if (!(z.depth == 1 && s.camera.orthographic)) dvcm *= mis(t_hit * t_hit);
    dvcm /= mis(cos_in);
    dvc /= mis(cos_in);
    // emission of a mesh light at the hit
    const Material& m = *z.m;
    if (!is_black(m.emission)) {
        float w = 1.0f, nee = 0.0f;
        int li = s.tri_light ? s.tri_light[tri] : -1;
        if (z.depth > 1 && li >= 0) {
            const Light& l = s.lights[li];
            const float pick = s.light_tree_on ? light_pick_pmf(s, li, ps.prev_p[i], ps.prev_n[i])
                                               : l.nee_pdf;  // at the previous vertex
            float pdf_direct = pick * light_pdf_w(l, ps.ray_o[i], d, t_hit, z.h.ng) *
                               cos_in / (t_hit * t_hit);
            float pdf_emit = l.emit_pick_pdf * emission_pdf(s, l, z.h.ng, -d).pdf_emit;
            const float dvc_e = z.depth == 2 ? dvc * bdpt_direct_lt(st) : dvc;  // (lt_direct)
            w = 1.0f / (1.0f + mis(pdf_direct) * dvcm + mis(st.r * pdf_emit) * dvc_e);
            nee = mis(pdf_direct) * dvcm;
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
    z.frame = z.h.frame();
    z.wo = z.frame.to_local(-d);
    z.ng_l = z.frame.to_local(z.h.ng);
    z.beta = ps.throughput[i];
    z.dvcm = dvcm;
    z.dvc = dvc;
    z.n_pick = light_pick_normal(s, tri, z.h.ng);
    Rng rng = ps.rng[i];
    if (!material_is_delta(m)) {
        bdpt_camera_nee(s, ps, st, z, i, rng);
        bdpt_camera_connect(s, bs, st, cache, z, i, path);
    } else {
        rng.uniform2();
        rng.uniform2();
    }
    // continue
    Vec2 u_dir = rng.uniform2();
    BsdfSample b = material_sample(m, z.h.front, z.wo, Vec3{u_dir.x, u_dir.y, rng.uniform()},
                                   Transport::Radiance, z.h.coat_n, z.ng_l);
    Vec3 wi = z.frame.to_world(b.wi);
    if (b.valid && light_side_agrees(m, wi, z.h.ng, z.h.ns) && (b.delta || b.pdf_fwd_w > 0.0f)) {
        Vec3 beta = z.beta * b.weight;
        if (russian_roulette(beta, z.depth, st.rr_depth, rng) && max_component(beta) > 0.0f &&
            is_finite(beta)) {
            bdpt_scatter_update(dvcm, dvc, b, fabsf(dot(wi, z.h.ng)));
            ps.throughput[i] = beta;
            ps.depth[i] = z.depth + 1;
            bs.dvcm[i] = dvcm;
            bs.dvc[i] = dvc;
            set_next_ray(ps, i, z.h.p, z.h.ng, wi, b.delta ? 0.0f : b.pdf_fwd_w,
                         s.offset_scale);
            if (s.light_tree_on) {
                ps.prev_p[i] = z.h.p;
                ps.prev_n[i] = z.n_pick;
            }
        }
    }
    ps.rng[i] = rng;
}

}  // namespace lantern
