// Shared by the bidirectional stages (bdpt.h): their contract below, the MIS helpers, the
// cache vertex, the settings and the per-slot state. The light pass is bdpt_light.h, the
// camera pass bdpt_camera.h.
//
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
    // the triangle and (bary16) its barycentrics, 2 x 16-bit unorm: textured and node-graph
    // materials are resolved at connection (shade_point_lv). A strand vertex (docs/curves.md):
    // tri the segment's primitive (>= num_triangles), bary16 its u, ng = ns the cross-section
    // normal, tangent_angle the turn that makes the frame's X the strand's tangent, and h, the
    // offset of the ray that found it, is read again from wo in that frame (hair_lobe_params).
    int32_t tri;
    uint32_t bary16;
    float tangent_angle;  // anisotropic materials: the frame's turn about ns (SurfaceHit)
    int32_t path;   // light path index (bdpt pairs camera path i with light path i)
    int16_t length; // segments from the light to this vertex (y1 has 1; max_depth <= 1024)
    int16_t front;  // bit 0; subsurface (CPU): bit 1 a walk's exit, bits 2.. its split's code
    uint32_t coat_n;  // kCoatNormal, material_keeps_unbent_normal: SurfaceHit::coat_n (oct_encode)
    float dpt0, dpt1; // BdptSettings::moments: path tracing's techniques (BdptState::dpt0)
};

static_assert(sizeof(LightVertex) == 104, "update the cache size in docs/lvc_notes.md");

// LightVertex::front's bit 0 (bits 1.., subsurface on the CPU: bdpt_sss_light.h; the device's
// light paths do not walk, its vertices have no other bit)
LANTERN_HD inline bool lv_front(const LightVertex& y) {
#ifdef __CUDACC__
    return y.front != 0;
#else
    return (y.front & 1) != 0;
#endif
}

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
    sp.bary = bary16_decode(y.bary16);
    const bool strand = y.tri >= s.num_triangles;  // a strand's point: no triangle (pt_curve.h)
    sp.tri = strand ? -1 : y.tri;
    sp.st = strand ? Vec2{sp.bary.x, 0.0f} : triangle_uv(s, y.tri, sp.bary);
    sp.backfacing = !lv_front(y);
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
    // lvc, cis: per pixel (N, M), 2 bytes, row-major, or null: N and M above everywhere
    // (integrator/pixel_conn.h); conn_q: a camera path's N / connections (camera_settings)
    const uint8_t* conn_map;
    float conn_q;
    int32_t naive_map;  // test only: the map's counts with the uniform weights (biased)
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

struct CameraVertex;  // bdpt_camera.h

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
    // ---- scenes with media only (bdpt_medium.h; null otherwise) ----
    float* seg_fwd = nullptr;     // the traced segment's distance factors so far (MediumSegmentPdf)
    float* seg_rev = nullptr;
    int32_t* seg_flags = nullptr;
    float* shadow_wn = nullptr;   // the slot's shadow ray (next event; the light pass: its camera
    float* shadow_wf = nullptr;   // segment): its weight's parts for the near / far end's factor
    int32_t* shadow_kind = nullptr;  // kConnNearMedium | kConnFarMedium
    float* conn_wn = nullptr;     // per connection: the same
    float* conn_wf = nullptr;
    int32_t* conn_kind = nullptr;
    int32_t* conn_medium = nullptr;  // the medium the connection starts in
    Vec3* shadow_mom = nullptr;   // BdptSettings::moments: pt's squared ratios (a, b, u) of the
    Vec3* conn_mom = nullptr;     // shadow ray / connection (bdpt_medium_finish_c)
    // camera pass: the last vertex's geometric normal (soft-falloff lights' weights,
    // soft_light_path.h); the light pass's power slots, which the camera pass does not use
    Vec3* prev_ng = nullptr;
    // camera pass: the vertex whose next event and connections the events stage makes
    // (bdpt_camera_events.h), its random stream there, and whether it has one this bounce
    CameraVertex* cam_z = nullptr;
    Rng* cam_rng = nullptr;
    uint8_t* cam_on = nullptr;
    // camera pass with a connection map: the path's pixel counts (pixel_conn_of_slot), in the
    // light pass's light slots
    int32_t* cam_conn = nullptr;
};

// The camera pass: the stream as the events stage's two uniform2 (its next event's) leave it,
// without making their numbers (each moves to the next even dimension, then past its pair:
// core/rng.h), for the shade, which queued a copy of it (bdpt_queue_camera_events).
LANTERN_HD inline void bdpt_skip_camera_events(Rng& rng) {
#ifdef LANTERN_RNG_PCG
    rng.uniform2();
    rng.uniform2();
#else
    rng.dim = rng.dim + (rng.dim & 1u) + 4u;
#endif
}

// What the camera pass reads of the cache.
struct LightCache {
    const LightVertex* v;
    int32_t size;
    const int32_t* path_offset;  // bdpt: vertices of light path j are path_vertex[off[j] .. off[j+1])
    const int32_t* path_vertex;
};

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

}  // namespace lantern
