// Thin-film interference (Principled Thin Film): a film of index eta_film and thickness d (nm)
// between the outside (index 1) and a dielectric or metal substrate, after Belcour & Barla 2017, "A
// Practical Extension to Microfacet Theory for the Modeling of Varying Iridescence": the film's
// multiple reflections summed as an Airy series (per polarisation, amplitudes at the two
// interfaces), each order's phase term integrated against the colour matching functions in
// Fourier space. Returns RGB reflectance (linear Rec.709) at the cosine cos_i on the outside.
#pragma once

#include "bsdf/fresnel.h"

namespace lantern {

// Amplitude reflection coefficients (s and p, real: dielectrics) of the interface from index
// eta_i to eta_t at incident cosine cos_i, and the cosine inside; false on total internal
// reflection. One sign convention for both interfaces, so the relative phases the Airy sum
// needs (0 or pi from the signs) are consistent.
LANTERN_HD inline bool film_interface(float cos_i, float eta_i, float eta_t, float* r_s,
                                      float* r_p, float* cos_t) {
    const float sin2_t = sqr(eta_i / eta_t) * fmaxf(1.0f - cos_i * cos_i, 0.0f);
    if (sin2_t >= 1.0f) return false;
    const float ct = sqrtf(1.0f - sin2_t);
    *r_s = (eta_i * cos_i - eta_t * ct) / (eta_i * cos_i + eta_t * ct);
    *r_p = (eta_t * cos_i - eta_i * ct) / (eta_t * cos_i + eta_i * ct);
    *cos_t = ct;
    return true;
}

// Integral of the CIE 1931 XYZ matching functions (illuminant E, each normalised to 1) against
// cos(2 pi nu x + shift) over the frequency nu = 1 / lambda, for optical path x (nm): Gaussians
// fitted in frequency, whose Fourier transforms are closed-form (the fit is the paper's, from its
// supplemental code; x has a second lobe for its blue bump).
LANTERN_HD inline Vec3 film_sensitivity(float x_nm, float shift) {
    const float w = 2.0f * kPi * x_nm * 1e-9f;  // radians per (1/m)
    const float w2 = w * w;
    const Vec3 amp{5.4856e-13f, 4.4201e-13f, 5.2481e-13f};
    const Vec3 mean{1.6810e+06f, 1.7953e+06f, 2.2084e+06f};
    const Vec3 var{4.3278e+09f, 9.3046e+09f, 6.6121e+09f};
    Vec3 s{amp.x * sqrtf(2.0f * kPi * var.x) * cosf(mean.x * w + shift) * expf(-var.x * w2),
           amp.y * sqrtf(2.0f * kPi * var.y) * cosf(mean.y * w + shift) * expf(-var.y * w2),
           amp.z * sqrtf(2.0f * kPi * var.z) * cosf(mean.z * w + shift) * expf(-var.z * w2)};
    s.x += 1.64408e-8f * cosf(2.2399e+06f * w + shift) * expf(-4.5282e+09f * w2);
    return s * (1.0f / 1.0685e-7f);  // x = 0, shift = 0: (1, 1, 1)
}

// Airy sum of one polarisation, integrated over the spectrum: R12 (top reflectance), R23
// (bottom), the film's optical path difference opd (nm) and the interfaces' phase sum phi.
// R = C0 + 2 sum_m C_m S(m opd, m phi) with C0 = R12 + Rs, Rs = T^2 R23 / (1 - R12 R23),
// C_m = (Rs - T) (R12 R23)^(m/2), T = 1 - R12 (the paper's order-difference form, truncated
// after three orders as Cycles does: the rest is under 2e-3 on dielectrics; on a metal seen at
// grazing angles, where R12 R23 approaches 0.3, up to 3e-2: tests/cpp/test_bsdf_thin_film.cpp).
LANTERN_HD inline Vec3 film_airy(float r12, float r23, float opd, float phi) {
    const float big_r12 = r12 * r12, big_r23 = r23 * r23;
    const float t = 1.0f - big_r12;
    const float denom = 1.0f - big_r12 * big_r23;
    if (!(denom > 1e-7f)) return vec3(1.0f);
    const float rs = t * t * big_r23 / denom;
    Vec3 r = vec3(big_r12 + rs);
    const float ratio = sqrtf(big_r12 * big_r23);
    float c = rs - t;
    for (int m = 1; m <= 3; ++m) {
        c *= ratio;
        r += film_sensitivity(float(m) * opd, float(m) * phi) * (2.0f * c);
    }
    return r;
}

// The film's index, blended towards the outside's (1) under 1 nm so that d -> 0 gives the bare
// interface (Cycles 5.0 does the same).
LANTERN_HD inline float film_index(float eta_film, float thickness) {
    if (thickness >= 1.0f) return eta_film;
    return 1.0f + (eta_film - 1.0f) * thickness * thickness * (3.0f - 2.0f * thickness);
}

// XYZ of illuminant E -> linear Rec.709 (D65): white scaled to D65's XYZ, then the matrix;
// clamped to [0, 1].
LANTERN_HD inline Vec3 film_xyz_to_rgb(Vec3 xyz) {
    const Vec3 w{xyz.x * 0.95047f, xyz.y, xyz.z * 1.08883f};
    Vec3 rgb{3.2404542f * w.x - 1.5371385f * w.y - 0.4985314f * w.z,
             -0.9692660f * w.x + 1.8760108f * w.y + 0.0415560f * w.z,
             0.0556434f * w.x - 0.2040259f * w.y + 1.0572252f * w.z};
    rgb = Vec3{clampf(rgb.x, 0.0f, 1.0f), clampf(rgb.y, 0.0f, 1.0f), clampf(rgb.z, 0.0f, 1.0f)};
    return is_finite(rgb) ? rgb : vec3(0.0f);
}

// Reflectance (linear Rec.709, each channel in [0, 1]) of the film eta_film, d nm thick, on a
// substrate of relative index eta_sub, seen at cosine cos_i from the outside (index 1).
// Out of line on the device (as the conductor's below): one copy per kernel for ptxas to compile
// instead of one per call site, a fifth of each shade kernel's PTX (docs/cuda_backend.md, "Build
// time"); only materials with a film call it.
#ifdef __CUDA_ARCH__
__noinline__
#endif
LANTERN_HD inline Vec3 thin_film_reflectance(float cos_i, float eta_film, float eta_sub,
                                             float thickness) {
    cos_i = clampf(fabsf(cos_i), 0.0f, 1.0f);
    if (!(thickness > 0.0f) || !is_finite(eta_film) || !is_finite(eta_sub)) return vec3(0.0f);
    eta_film = film_index(eta_film, thickness);
    float r12s, r12p, cos2, r23s, r23p, cos3;
    if (!film_interface(cos_i, 1.0f, eta_film, &r12s, &r12p, &cos2)) return vec3(1.0f);
    if (!film_interface(cos2, eta_film, eta_sub, &r23s, &r23p, &cos3)) return vec3(1.0f);
    const float opd = 2.0f * eta_film * thickness * cos2;
    // phase sum: bottom reflection phase + the top's seen from inside (pi - its outside phase)
    auto phase = [](float r) { return r < 0.0f ? kPi : 0.0f; };
    const float phi_s = phase(r23s) + kPi - phase(r12s);
    const float phi_p = phase(r23p) + kPi - phase(r12p);
    return film_xyz_to_rgb(
        (film_airy(r12s, r23s, opd, phi_s) + film_airy(r12p, r23p, opd, phi_p)) * 0.5f);
}

// The same film on a metal of complex index n + i k per channel (relative to the outside): the
// bottom interface's amplitudes are complex, so each channel has its own R23 and phase; each
// channel's Airy sums are integrated and converted, and that channel of the result kept.
#ifdef __CUDA_ARCH__
__noinline__
#endif
LANTERN_HD inline Vec3 thin_film_reflectance_conductor(float cos_i, float eta_film, Vec3 n,
                                                       Vec3 k, float thickness) {
    cos_i = clampf(fabsf(cos_i), 0.0f, 1.0f);
    if (!(thickness > 0.0f) || !is_finite(eta_film) || !is_finite(n) || !is_finite(k))
        return vec3(0.0f);
    eta_film = film_index(eta_film, thickness);
    float r12s, r12p, cos2;
    if (!film_interface(cos_i, 1.0f, eta_film, &r12s, &r12p, &cos2)) return vec3(1.0f);
    const float opd = 2.0f * eta_film * thickness * cos2;
    auto phase = [](float r) { return r < 0.0f ? kPi : 0.0f; };
    float out[3];
    for (int c = 0; c < 3; ++c) {
        const Complex big_n{fmaxf(n[c], 1e-4f), fmaxf(k[c], 0.0f)};
        const Complex ci{cos2, 0.0f}, ef{eta_film, 0.0f};
        // cos_t = sqrt(1 - (eta_f / N)^2 sin^2), complex
        const Complex ratio = c_div(ef, big_n);
        const Complex ct = c_sqrt(c_sub({1.0f, 0.0f},
                                        c_mul(c_mul(ratio, ratio), {1.0f - cos2 * cos2, 0.0f})));
        const Complex rs = c_div(c_sub(c_mul(ef, ci), c_mul(big_n, ct)),
                                 c_add(c_mul(ef, ci), c_mul(big_n, ct)));
        const Complex rp = c_div(c_sub(c_mul(big_n, ci), c_mul(ef, ct)),
                                 c_add(c_mul(big_n, ci), c_mul(ef, ct)));
        const float phi_s = atan2f(rs.im, rs.re) + kPi - phase(r12s);
        const float phi_p = atan2f(rp.im, rp.re) + kPi - phase(r12p);
        const Vec3 rgb = film_xyz_to_rgb((film_airy(r12s, sqrtf(c_norm(rs)), opd, phi_s) +
                                          film_airy(r12p, sqrtf(c_norm(rp)), opd, phi_p)) *
                                         0.5f);
        out[c] = c == 0 ? rgb.x : c == 1 ? rgb.y : rgb.z;
    }
    return Vec3{out[0], out[1], out[2]};
}

// Gulbrandsen 2014 ("Artist Friendly Metallic Fresnel"): the complex index of reflectivity r and
// edge tint g, here r = F0 and g = the F82-tint reflectance at cos 1/7 (how Cycles 5.0 gives an
// F82 metal its film substrate). n between (1 + sqrt r) / (1 - sqrt r) and (1 - r) / (1 + r).
LANTERN_HD inline void f82_to_complex_ior(Vec3 f0, Vec3 tint, Vec3* n_out, Vec3* k_out) {
    const Vec3 g = fresnel_f82_tint(1.0f / 7.0f, f0, tint);
    float n[3], k[3];
    for (int c = 0; c < 3; ++c) {
        const float r = clampf(f0[c], 0.0f, 0.999f), sr = sqrtf(r);
        const float gc = clampf(g[c], 0.0f, 1.0f);
        n[c] = (1.0f - gc) * (1.0f + sr) / (1.0f - sr) + gc * (1.0f - r) / (1.0f + r);
        k[c] = safe_sqrt((r * sqr(n[c] + 1.0f) - sqr(n[c] - 1.0f)) / (1.0f - r));
    }
    *n_out = Vec3{n[0], n[1], n[2]};
    *k_out = Vec3{k[0], k[1], k[2]};
}

}  // namespace lantern
