// Fresnel terms shared by the lobes: exact dielectric, exact conductor (complex IOR eta + i k,
// per RGB channel) and Hoffman's F82-tint model that Blender's Principled BSDF uses for metals.
#pragma once

#include "core/math.h"

namespace lantern {

// Unpolarised reflectance of a dielectric interface; cos_i on the incident side (sign gives the
// side: negative means inside, where the relative index is 1/eta). eta = n_inside / n_outside.
LANTERN_HD inline float fresnel_dielectric(float cos_i, float eta) {
    if (cos_i < 0.0f) {
        eta = 1.0f / eta;
        cos_i = -cos_i;
    }
    cos_i = fminf(cos_i, 1.0f);
    float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0f) return 1.0f;  // total internal reflection
    float cos_t = safe_sqrt(1.0f - sin2_t);
    float r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    float f = 0.5f * (r_par * r_par + r_perp * r_perp);
    return is_finite(f) ? clampf(f, 0.0f, 1.0f) : 1.0f;
}

struct Complex {
    float re, im;
};
LANTERN_HD inline Complex c_add(Complex a, Complex b) { return {a.re + b.re, a.im + b.im}; }
LANTERN_HD inline Complex c_sub(Complex a, Complex b) { return {a.re - b.re, a.im - b.im}; }
LANTERN_HD inline Complex c_mul(Complex a, Complex b) {
    return {a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re};
}
LANTERN_HD inline Complex c_div(Complex a, Complex b) {
    float d = b.re * b.re + b.im * b.im;
    return {(a.re * b.re + a.im * b.im) / d, (a.im * b.re - a.re * b.im) / d};
}
LANTERN_HD inline float c_norm(Complex a) { return a.re * a.re + a.im * a.im; }
LANTERN_HD inline Complex c_sqrt(Complex a) {  // principal root
    float r = sqrtf(sqrtf(c_norm(a)));
    if (r == 0.0f) return {0.0f, 0.0f};
    float t = 0.5f * atan2f(a.im, a.re);
    return {r * cosf(t), r * sinf(t)};
}

// Reflectance of a conductor with complex index eta + i k (relative to the outside medium).
// Out of line on the device: its complex square root (atan2f, cosf, sinf) was inlined three
// times per call of the RGB version below, at every call site (docs/cuda_backend.md, "Build time").
#ifdef __CUDA_ARCH__
__noinline__
#endif
LANTERN_HD inline float fresnel_conductor(float cos_i, float eta, float k) {
    cos_i = clampf(cos_i, 0.0f, 1.0f);
    Complex n{fmaxf(eta, 1e-4f), fmaxf(k, 0.0f)};
    Complex ci{cos_i, 0.0f};
    Complex sin2_t = c_div({1.0f - cos_i * cos_i, 0.0f}, c_mul(n, n));
    Complex ct = c_sqrt(c_sub({1.0f, 0.0f}, sin2_t));
    Complex r_par = c_div(c_sub(c_mul(n, ci), ct), c_add(c_mul(n, ci), ct));
    Complex r_perp = c_div(c_sub(ci, c_mul(n, ct)), c_add(ci, c_mul(n, ct)));
    float f = 0.5f * (c_norm(r_par) + c_norm(r_perp));
    return is_finite(f) ? clampf(f, 0.0f, 1.0f) : 1.0f;
}
LANTERN_HD inline Vec3 fresnel_conductor(float cos_i, Vec3 eta, Vec3 k) {
    return {fresnel_conductor(cos_i, eta.x, k.x), fresnel_conductor(cos_i, eta.y, k.y),
            fresnel_conductor(cos_i, eta.z, k.z)};
}

// Hoffman 2023, "Generalization of Adobe's Fresnel model" (F82-tint): Schlick with base colour F0,
// minus a term a mu (1 - mu)^6 chosen so that F(mu_bar = 1/7) = tint * Schlick(1/7).
LANTERN_HD inline Vec3 fresnel_f82_tint(float cos_i, Vec3 f0, Vec3 tint) {
    float mu = clampf(cos_i, 0.0f, 1.0f);
    const float mu_bar = 1.0f / 7.0f;
    float m5 = powf(1.0f - mu, 5.0f);
    float m5_bar = powf(1.0f - mu_bar, 5.0f);
    float scale = mu * (1.0f - mu) * m5 / (mu_bar * (1.0f - mu_bar) * m5_bar);
    Vec3 r;
    for (int c = 0; c < 3; ++c) {
        float f0c = clampf(f0[c], 0.0f, 1.0f);
        float schlick = f0c + (1.0f - f0c) * m5;
        float schlick_bar = f0c + (1.0f - f0c) * m5_bar;
        float v = schlick - schlick_bar * (1.0f - clampf(tint[c], 0.0f, 1.0f)) * scale;
        (c == 0 ? r.x : c == 1 ? r.y : r.z) = clampf(v, 0.0f, 1.0f);
    }
    return r;
}

}  // namespace lantern
