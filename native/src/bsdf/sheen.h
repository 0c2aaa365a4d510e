// Sheen: the microfiber sheen of Zeltner, Burley & Chiang, "Practical Multiple-Scattering Sheen
// Using Linearly Transformed Cosines" (SIGGRAPH Talks 2022), the Principled sheen of Cycles 4.x
// and 5.0. A volumetric layer of fibres standing on the surface, fitted per view cosine mu_v and
// roughness by a linearly transformed cosine (LTC) and an albedo R:
//
//   f(v, l) cos_l = R(mu_v) D_v(l),   D_v(l) = l.z / pi * (a / |M^-1 l|^2)^2,
//   M^-1 = [[a, 0, b], [0, a, 0], [0, 0, 1]]
//
// in the frame whose x axis is v's projection on the surface (a, b from the fit at mu_v). M keeps
// z, so D_v is a normalized density on the upper hemisphere: the lobe reflects exactly R(mu_v),
// and sampling D_v (a cosine-distributed disk point mapped by M) has weight R exactly.
// v is the camera side (wo for radiance, wi for importance), l the light side; D_v(l) / l.z is
// not symmetric, so eval() takes the transport mode and importance evaluates f(wi, wo): the
// adjoint, the same function for camera and light sub-paths. Sampling draws from the lobe of
// wo in both modes; pdf_fwd_w = D_wo(wi), pdf_rev_w = D_wi(wo).
// The fit's numbers (a, b, R on a 32 x 32 grid) are in sheen_ltc.cpp; a material holds its
// roughness's three rows (MaterialTables::sheen_ltc, filled at scene build by sheen_ltc_rows).
#pragma once

#include "bsdf/cosine_lobe.h"
#include "bsdf/dielectric.h"
#include "scene/scene_view.h"

namespace lantern {

// Cycles clamps the sheen roughness to [1e-3, 1] (below, the fit has no lobe: a = R = 0).
constexpr float kSheenMinRoughness = 1e-3f;

// Host: the fit's rows at `roughness`, linear between the grid's rows: out[0 .. N) = a,
// out[N .. 2N) = b, out[2N .. 3N) = R, at cosines i / (N - 1), N = kSheenLtcN (sheen_ltc.cpp).
void sheen_ltc_rows(float roughness, float* out);

struct SheenParams {
    Vec3 color;         // Sheen Weight x Sheen Tint
    const float* ltc;   // 3 x kSheenLtcN: a material's rows (sheen_ltc_rows)
};

struct SheenLtc {
    float a, b, r;
};

// The fit at cosine mu: linear between the grid's cosines, as Cycles reads its table.
LANTERN_HD inline SheenLtc sheen_ltc_at(const float* t, float mu) {
    const float x = clampf(mu, 0.0f, 1.0f) * (kSheenLtcN - 1);
    const int i = min_int(int(x), kSheenLtcN - 2);
    const float s = x - float(i);
    auto lerp = [t, i, s](int row) {
        const float* p = t + row * kSheenLtcN + i;
        return (1.0f - s) * p[0] + s * p[1];
    };
    return {lerp(0), lerp(1), lerp(2)};
}

// The frame of the lobe of v: x along v's projection on the surface (any, if v is the normal).
struct SheenFrame {
    float cx, cy;
};
LANTERN_HD inline SheenFrame sheen_frame(Vec3 v) {
    const float len = sqrtf(v.x * v.x + v.y * v.y);
    if (!(len > 1e-12f)) return {1.0f, 0.0f};
    return {v.x / len, v.y / len};
}

// D_v(w): the density over solid angle of the lobe of the view v (fit l) at direction w.
LANTERN_HD inline float sheen_ltc_d(const SheenLtc& l, Vec3 v, Vec3 w) {
    if (!(w.z > 0.0f) || !(l.a > 0.0f)) return 0.0f;
    const SheenFrame fr = sheen_frame(v);
    const float x = fr.cx * w.x + fr.cy * w.y, y = fr.cx * w.y - fr.cy * w.x;
    const float p = l.a * x + l.b * w.z, q = l.a * y;
    const float len2 = p * p + q * q + w.z * w.z;
    return kInvPi * w.z * sqr(l.a / len2);
}

LANTERN_HD inline BsdfEval sheen_eval(const SheenParams& p, Vec3 wo, Vec3 wi, Transport mode) {
    BsdfEval e{vec3(0.0f), 0.0f, 0.0f};
    if (!(wo.z > 0.0f) || !(wi.z > 0.0f)) return e;
    const SheenLtc lo = sheen_ltc_at(p.ltc, wo.z), li = sheen_ltc_at(p.ltc, wi.z);
    const float d_o = sheen_ltc_d(lo, wo, wi), d_i = sheen_ltc_d(li, wi, wo);
    e.pdf_fwd_w = d_o;
    e.pdf_rev_w = d_i;
    // R(mu_v) D_v(l) / l.z: the camera side v is wo for radiance, wi for importance
    const float f = mode == Transport::Radiance ? lo.r * d_o / wi.z : li.r * d_i / wo.z;
    e.f = p.color * f;
    if (!is_finite(e.f) || !is_finite(e.pdf_fwd_w) || !is_finite(e.pdf_rev_w))
        return BsdfEval{vec3(0.0f), 0.0f, 0.0f};
    return e;
}

// A direction from the lobe of wo: a cosine-distributed point of the disk, mapped by M.
LANTERN_HD inline bool sheen_sample_dir(const SheenParams& p, Vec3 wo, Vec2 u, Vec3* wi) {
    if (!(wo.z > 0.0f)) return false;
    const SheenLtc l = sheen_ltc_at(p.ltc, wo.z);
    if (!(l.a > 0.0f) || !(l.r > 0.0f)) return false;
    const Vec2 d = sample_concentric_disk(u);
    const float dz = safe_sqrt(1.0f - d.x * d.x - d.y * d.y);
    const Vec3 o = normalize(vec3((d.x - dz * l.b) / l.a, d.y / l.a, dz));
    const SheenFrame fr = sheen_frame(wo);
    *wi = vec3(fr.cx * o.x - fr.cy * o.y, fr.cy * o.x + fr.cx * o.y, o.z);
    return wi->z > 0.0f && is_finite(*wi);
}

LANTERN_HD inline BsdfSample sheen_sample(const SheenParams& p, Vec3 wo, Vec2 u, Transport mode) {
    Vec3 wi;
    if (!sheen_sample_dir(p, wo, u, &wi)) return BsdfSample{vec3(0.0f), vec3(0.0f), 0.0f, false};
    return mixture_sample(wi, sheen_eval(p, wo, wi, mode));
}

}  // namespace lantern
