// GGX (Trowbridge-Reitz) microfacet distribution in a local frame with +Z the macro normal:
// D, Smith Lambda/G1 and the height-correlated G2, and visible-normal sampling (Heitz 2018,
// "Sampling the GGX distribution of visible normals") with its density.
#pragma once

#include "core/math.h"

namespace lantern {

// A lobe is treated as smooth (a delta lobe) by its owner when ax * ay <= kGgxSingularAlpha2:
// Cycles' rule for its microfacet closures, with the constant bpy 5.0.1 renders (bisected on a
// metal under a point light, tests/cycles/test_sharp_glossy.py: glossy at ax ay = 2.03e-10,
// singular at 1.98e-10; the Cycles sources read say 1e-7 or 5e-7, not what 5.0.1 does).
// Isotropic: alpha <= 1.41e-5, Roughness <= 0.00376. A threshold of alpha < 1e-3 (Roughness
// 0.0316) left Roughness 0.004-0.03 lobes black under point lights (difftest seed 628). D stays
// finite down to kGgxMinAlpha, the clamp every lobe applies to its alphas: below the threshold
// (an anisotropic alpha_y of the smallest glossy lobe is 4.5e-6), so that it clamps only delta
// lobes; at the threshold D peaks at 1 / (pi 2e-10) = 1.6e9, far inside float.
constexpr float kGgxMinAlpha = 1e-6f;
constexpr float kGgxSingularAlpha2 = 2e-10f;

// Blender's convention: alpha = roughness^2, clamped.
LANTERN_HD inline float ggx_alpha_from_roughness(float roughness) {
    return fmaxf(sqr(clampf(roughness, 0.0f, 1.0f)), kGgxMinAlpha);
}

struct Ggx;
LANTERN_HD inline Ggx ggx_from_roughness(float roughness, float anisotropy);

struct Ggx {
    float ax, ay;  // anisotropic alphas along local X and Y, each >= kGgxMinAlpha

    LANTERN_HD static Ggx isotropic(float alpha) {
        float a = clampf(alpha, kGgxMinAlpha, 1.0f);
        return {a, a};
    }
    LANTERN_HD bool effectively_smooth() const { return ax * ay <= kGgxSingularAlpha2; }

    // D(m) = 1 / (pi ax ay ((mx/ax)^2 + (my/ay)^2 + mz^2)^2); this form keeps full precision
    // at m = +Z for tiny alphas (the 1 - mz^2 (1 - a^2) form rounds to zero there).
    LANTERN_HD float d(Vec3 m) const {
        if (m.z <= 0.0f) return 0.0f;
        float t = sqr(m.x / ax) + sqr(m.y / ay) + sqr(m.z);
        return 1.0f / (kPi * ax * ay * t * t);
    }
    // Smith Lambda(w) = (sqrt(1 + a(w)^2 tan^2 theta) - 1) / 2, symmetric in w.z's sign.
    LANTERN_HD float lambda(Vec3 w) const {
        float z2 = w.z * w.z;
        if (z2 <= 0.0f) return kInf;
        float a2tan2 = (sqr(w.x * ax) + sqr(w.y * ay)) / z2;
        return 0.5f * (sqrtf(1.0f + a2tan2) - 1.0f);
    }
    LANTERN_HD float g1(Vec3 w) const { return 1.0f / (1.0f + lambda(w)); }
    // Height-correlated masking-shadowing (Heitz 2014, eq. 99).
    LANTERN_HD float g2(Vec3 wo, Vec3 wi) const {
        float lo = lambda(wo), li = lambda(wi);
        if (!(lo < kInf) || !(li < kInf)) return 0.0f;
        return 1.0f / (1.0f + lo + li);
    }

    // Density of visible normals D_wo(m) = G1(wo) max(0, wo.m) D(m) / |wo.z|  [Heitz 2018 (1)].
    LANTERN_HD float pdf_visible(Vec3 wo, Vec3 m) const {
        float cos_o = fabsf(wo.z);
        if (cos_o <= 0.0f) return 0.0f;
        float wo_m = dot(wo, m) * copysignf(1.0f, wo.z);
        if (wo_m <= 0.0f) return 0.0f;
        return g1(wo) * wo_m * d(m) / cos_o;
    }

    // A visible normal for wo (wo mirrored to +Z first, so m.z >= 0 always) [Heitz 2018, listing].
    LANTERN_HD Vec3 sample_visible(Vec3 wo, Vec2 u) const {
        Vec3 w = wo.z < 0.0f ? -wo : wo;
        Vec3 vh = normalize(vec3(ax * w.x, ay * w.y, w.z));  // stretch to the hemisphere config
        float len2 = vh.x * vh.x + vh.y * vh.y;
        Vec3 t1 = len2 > 0.0f ? vec3(-vh.y, vh.x, 0.0f) * (1.0f / sqrtf(len2)) : vec3(1, 0, 0);
        Vec3 t2 = cross(vh, t1);
        float r = sqrtf(u.x);
        float phi = 2.0f * kPi * u.y;
        float p1 = r * cosf(phi), p2 = r * sinf(phi);
        float s = 0.5f * (1.0f + vh.z);
        p2 = (1.0f - s) * safe_sqrt(1.0f - p1 * p1) + s * p2;
        Vec3 nh = t1 * p1 + t2 * p2 + vh * safe_sqrt(1.0f - p1 * p1 - p2 * p2);
        return normalize(vec3(ax * nh.x, ay * nh.y, fmaxf(1e-6f, nh.z)));  // unstretch
    }
};

// Blender's roughness and Anisotropic (Burley 2012: aspect = sqrt(1 - 0.9 anisotropy), alpha_x =
// alpha / aspect, alpha_y = alpha aspect; local X is the tangent).
LANTERN_HD inline Ggx ggx_from_roughness(float roughness, float anisotropy) {
    const float a = ggx_alpha_from_roughness(roughness);
    if (!(anisotropy > 0.0f)) return Ggx::isotropic(a);
    const float aspect = sqrtf(1.0f - 0.9f * fminf(anisotropy, 1.0f));
    return Ggx{clampf(a / aspect, kGgxMinAlpha, 1.0f), clampf(a * aspect, kGgxMinAlpha, 1.0f)};
}

// Beckmann distribution of isotropic alpha (Walter et al. 2007): D and Smith's Lambda with
// Walter's rational approximation. Lobes that use it sample with GGX's visible normals of the
// same alpha (longer tails: a safe proposal) and divide by that pdf.
LANTERN_HD inline float beckmann_d(float alpha, Vec3 m) {
    if (m.z <= 0.0f) return 0.0f;
    float c2 = m.z * m.z;
    float tan2 = fmaxf(0.0f, 1.0f - c2) / c2;
    float a2 = alpha * alpha;
    return expf(-tan2 / a2) / (kPi * a2 * c2 * c2);
}
LANTERN_HD inline float beckmann_lambda(float alpha, Vec3 w) {
    float z2 = w.z * w.z;
    if (z2 <= 0.0f) return kInf;
    float tan = sqrtf(fmaxf(0.0f, 1.0f - z2) / z2);
    if (tan <= 0.0f) return 0.0f;
    float a = 1.0f / (alpha * tan);
    if (a >= 1.6f) return 0.0f;
    return (1.0f - 1.259f * a + 0.396f * a * a) / (3.535f * a + 2.181f * a * a);
}
LANTERN_HD inline float beckmann_g2(float alpha, Vec3 wo, Vec3 wi) {
    float lo = beckmann_lambda(alpha, wo), li = beckmann_lambda(alpha, wi);
    if (!(lo < kInf) || !(li < kInf)) return 0.0f;
    return 1.0f / (1.0f + lo + li);
}

LANTERN_HD inline Vec3 reflect(Vec3 w, Vec3 m) { return m * (2.0f * dot(w, m)) - w; }

// Refracts w (pointing away from the surface, on m's side) through m with eta = n_t / n_i.
// Returns false on total internal reflection.
LANTERN_HD inline bool refract(Vec3 w, Vec3 m, float eta, Vec3* wt) {
    float cos_i = dot(w, m);
    float sin2_t = fmaxf(0.0f, 1.0f - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0f) return false;
    float cos_t = sqrtf(1.0f - sin2_t);
    *wt = -w / eta + m * (cos_i / eta - copysignf(cos_t, cos_i));
    return true;
}

}  // namespace lantern
