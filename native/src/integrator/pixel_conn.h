// Per-pixel connection counts of lvc and cis (issue 27, item 2): BdptSettings::conn_map holds
// per pixel (N, M), fixed for an iteration (SessionSettings::connection_map). A path's counts
// are those of the pixel its raster position falls in, the camera sample's (its filter offset
// included) or the light-tracing splat's centre: a function of the path, so every technique
// of a path weighs its alternatives with one N and the weights stay a partition of unity.
//
// MIS with a per-pixel count (bdpt.h's table, r -> r_p = q r, q = N(p) / N):
// - the camera sub-path's quantities are normalised to r_p (camera_settings: its r); where
//   N(p) = 0 to count 1 (r = 1) with the connection terms left out: a vertex's dVCM enters the
//   next dVC only at the first vertex (light tracing's term there), next-event estimation's
//   dVCM term likewise (camera_conn_dvcm);
// - a cache vertex's quantities were normalised to the global r: their parts that end on the
//   light (s = 0, s = 1; dVC's = dpt0 + dpt1, dVCM's at y1 only) scale by 1 / q^2
//   (light_vertex_mis), a light-tracing splat's weight by q^2 for the rest (lt_weight_mapped).
#pragma once

#include "integrator/bdpt_common.h"
#include "integrator/camera.h"

namespace lantern {

struct PixelConn {
    int32_t n, m;  // connections N and candidates M (cis) of the pixel
    float q;       // N / BdptSettings::connections: the pixel's r is q r
};

// The counts at raster position (rx, ry) (clamped to the film).
LANTERN_HD inline PixelConn pixel_conn_at(const BdptSettings& st, const CameraView& c, float rx,
                                          float ry) {
    if (!st.conn_map) return PixelConn{st.connections, st.candidates, 1.0f};
    const int x = rx >= 0.0f ? int(fminf(rx, float(c.width - 1))) : 0;
    const int y = ry >= 0.0f ? int(fminf(ry, float(c.height - 1))) : 0;
    const uint8_t* e = st.conn_map + 2 * (size_t(y) * size_t(c.width) + size_t(x));
    return PixelConn{int32_t(e[0]), int32_t(e[1]), float(e[0]) / float(st.connections)};
}

// ... of camera path `path`: its raster sample, as pt_generate draws it (camera_raster_sample).
LANTERN_HD inline PixelConn pixel_conn_of_path(const SceneView& s, const BdptSettings& st,
                                               int64_t path) {
    if (!st.conn_map) return PixelConn{st.connections, st.candidates, 1.0f};
    Rng rng = Rng::for_camera(st.seed, st.iteration, st.spp_per_iteration, path);
    const Vec2 r = camera_raster_sample(s.camera, int(path / st.spp_per_iteration), rng.uniform2());
    return pixel_conn_at(st, s.camera, r.x, r.y);
}

// A path's counts in one int (the map's two bytes; q follows from N), kept in its slot by the
// camera pass's generation (BdptState::cam_conn) for its later stages: the same counts as
// pixel_conn_of_path's, without drawing the raster sample again.
LANTERN_HD inline int32_t pixel_conn_pack(const PixelConn& pc) { return pc.n | (pc.m << 8); }
LANTERN_HD inline PixelConn pixel_conn_of_slot(const BdptSettings& st, const BdptState& bs,
                                               int i) {
    if (!st.conn_map) return PixelConn{st.connections, st.candidates, 1.0f};
    const int32_t n = bs.cam_conn[i] & 0xff, m = bs.cam_conn[i] >> 8;
    return PixelConn{n, m, float(n) / float(st.connections)};
}

// The camera pass's settings for a path of counts pc: r, N and M the pixel's (N = 0: r = 1,
// the camera quantities' count-1 normalisation); st itself where there is no map.
LANTERN_HD inline BdptSettings camera_settings(const BdptSettings& st, const PixelConn& pc) {
    BdptSettings c = st;
    if (!st.conn_map || !(st.r > 0.0f)) return c;  // (no light paths: pt's weights anyway)
    c.connections = pc.n;
    c.candidates = pc.n > 0 ? pc.m : 0;
    if (st.naive_map) return c;  // (test only: weights for the uniform N, biased)
    c.r = pc.n > 0 ? st.r * pc.q : 1.0f;
    c.conn_q = pc.q;
    return c;
}
// Whether a camera path makes no connections although there are light paths (N(p) = 0).
LANTERN_HD inline bool camera_no_conn(const BdptSettings& cst) {
    return cst.conn_map && cst.conn_q == 0.0f;
}
// A camera vertex's dVCM as the next dVC or next-event estimation reads it: beyond the first
// vertex it is a connection's term, absent where N(p) = 0.
LANTERN_HD inline float camera_conn_dvcm(const BdptSettings& cst, float dvcm, int depth) {
    return depth > 1 && camera_no_conn(cst) ? 0.0f : dvcm;
}

// A cache vertex's (dVCM, dVC) for a camera path of ratio q > 0 (cst.conn_q).
LANTERN_HD inline void light_vertex_mis(const BdptSettings& cst, const LightVertex& y,
                                        float* dvcm, float* dvc) {
    *dvcm = y.dvcm;
    *dvc = y.dvc;
    if (!cst.conn_map || cst.conn_q == 1.0f) return;
    const float inv_q2 = 1.0f / mis(cst.conn_q);
    const float dvc_b = y.dpt0 + y.dpt1;  // dVC's parts that end on the light
    *dvc = fmaxf(0.0f, y.dvc - dvc_b) + dvc_b * inv_q2;
    if (y.length == 1) *dvcm = y.dvcm * inv_q2;  // (beyond y1 dVCM is a connection's term)
}

// Light tracing's weight (bdpt_light_tracing_weight) for a splat into a pixel of ratio q:
// w_light = mis(camera_pdf_a r / n_lt) (q^2 (connections' terms) + (terms ending on the light)).
LANTERN_HD inline float lt_weight_mapped(const BdptSettings& st, float q, float dvcm, float dvc,
                                         float dpt0, float dpt1, float camera_pdf_a,
                                         float pdf_rev, int k) {
    const float n_lt = k == 1 ? st.n_lt * st.lt_direct : st.n_lt;
    const float rev = mis(pdf_rev), dvc_b = dpt0 + dpt1;
    const float dvcm_b = k == 1 ? dvcm : 0.0f;
    const float conn = (dvcm - dvcm_b) + fmaxf(0.0f, dvc - dvc_b) * rev;
    const float ends = dvcm_b + dvc_b * rev;
    if (st.naive_map) q = 1.0f;  // (test only)
    const float w_light = mis(camera_pdf_a * st.r / n_lt) * (mis(q) * conn + ends);
    return 1.0f / (1.0f + w_light);
}

}  // namespace lantern
