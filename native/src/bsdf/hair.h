// The Principled Hair BSDF, Chiang model (Chiang, Bitterli, Tappan & Burley 2016, "A Practical
// and Controllable Hair and Fur Model for Production Path Tracing"), with Blender's inputs as
// Cycles' Chiang model reads them. Local frame: +X the fiber's tangent; Y, Z any pair spanning
// the cross-section (only phi_i - phi_o is read). h in [-1, 1]: where the view ray crosses the
// fiber (0 its axis, +-1 its edges). hair_eval returns f_cos, the integrand itself (the
// cosine to the normal plane is inside Mp's normalisation): radiance = integral of L f_cos dw,
// so a caller must NOT multiply a hair lobe by |cos| to a normal, unlike BsdfEval's f.
#pragma once

#include "bsdf/fresnel.h"
#include "core/math.h"

namespace lantern {

constexpr int kHairLobes = 4;  // R, TT, TRT and the rest (TRRT+), Chiang's p = 0..3

struct HairParams {
    Vec3 sigma_a;          // absorption coefficient per unit of fiber radius
    float v[kHairLobes];   // longitudinal variances of the lobes
    float s;               // scale of the azimuthal logistic
    float alpha;           // cuticle tilt (radians)
    float eta;             // index of refraction of the fiber
    float h;               // offset of the view ray across the fiber, in [-1, 1]
};

// ---- Blender's parametrisations of the absorption (Cycles' Principled Hair node) ----

// Roughness scale of the colour -> absorption fit (Chiang et al. eq. 9, in radial roughness).
LANTERN_HD inline float hair_color_fit(float radial_roughness) {
    const float x = radial_roughness;
    return 5.969f + x * (-0.215f + x * (2.532f + x * (-10.73f + x * (5.574f + x * 0.245f))));
}

// Direct Coloring: the absorption that gives roughly this colour after multiple scattering.
LANTERN_HD inline Vec3 hair_sigma_from_color(Vec3 color, float radial_roughness) {
    const float k = 1.0f / hair_color_fit(radial_roughness);
    auto one = [k](float c) { return sqr(logf(fmaxf(c, 1e-5f)) * k); };
    return vec3(one(color.x), one(color.y), one(color.z));
}

// Melanin: the slider (0..1) read as a perceptually linear amount, split by redness into eu-
// and pheomelanin (Bitterli's remapping), each with its absorption spectrum in RGB; plus a tint
// as a Direct Coloring absorption (white: none).
LANTERN_HD inline Vec3 hair_sigma_from_melanin(float melanin, float redness, Vec3 tint,
                                               float radial_roughness) {
    const float amount = -logf(fmaxf(1.0f - melanin, 1e-4f));
    const float eu = amount * (1.0f - redness), pheo = amount * redness;
    const Vec3 sigma = eu * vec3(0.506f, 0.841f, 1.653f) + pheo * vec3(0.343f, 0.733f, 1.924f);
    return sigma + hair_sigma_from_color(tint, radial_roughness);
}

// Chiang et al. eq. 7: the perceptually linear roughness beta_m as a longitudinal variance.
LANTERN_HD inline float hair_variance(float beta_m) {
    const float b = beta_m, b2 = b * b, b4 = b2 * b2, b10 = b4 * b4 * b2, b20 = b10 * b10;
    return sqr(0.726f * b + 0.812f * b2 + 3.7f * b20);
}

// The node's inputs as the lobe's parameters. roughness, radial_roughness, coat in [0, 1]
// (clamped as Cycles does), offset in radians, h from the hit. Coat shrinks R's roughness only.
LANTERN_HD inline HairParams hair_params(Vec3 sigma_a, float roughness, float radial_roughness,
                                         float coat, float offset, float ior, float h) {
    HairParams p;
    p.sigma_a = vec3(fmaxf(sigma_a.x, 0.0f), fmaxf(sigma_a.y, 0.0f), fmaxf(sigma_a.z, 0.0f));
    const float bm = clampf(roughness, 0.001f, 1.0f), bn = clampf(radial_roughness, 0.001f, 1.0f);
    const float bm0 = clampf((1.0f - clampf(coat, 0.0f, 1.0f)) * bm, 0.001f, 1.0f);
    const float v = hair_variance(bm);
    p.v[0] = hair_variance(bm0);
    p.v[1] = 0.25f * v;
    p.v[2] = 4.0f * v;
    p.v[3] = 4.0f * v;
    // Chiang et al. eq. 8 (logistic scale from beta_n), times sqrt(pi / 8)
    const float bn2 = bn * bn, bn4 = bn2 * bn2, bn22 = bn4 * bn4 * bn4 * bn4 * bn4 * bn2;
    p.s = 0.6266570687f * (0.265f * bn + 1.194f * bn2 + 5.372f * bn22);
    p.alpha = offset;
    p.eta = ior > 1.0001f ? ior : 1.0001f;
    p.h = h == h ? clampf(h, -1.0f, 1.0f) : 0.0f;  // NaN: the axis
    return p;
}

// ---- The shading frame on a strand ----
// X the strand's tangent, Y perpendicular to X and to the view, Z = X x Y (so the view lies in
// the XZ plane); h, where the view ray crossed the fiber, is the sine of the angle between the
// hit's normal ng and Z seen along X: h = (ng x X) . Z, +-1 at the silhouettes, 0 head-on. `view`
// points from the hit back to the viewer. A view along the tangent has no such frame: Y is then
// any perpendicular (Frame::from_normal's) and h is 0.
struct HairFrame {
    Vec3 x, y, z;
    float h;
    LANTERN_HD Vec3 to_local(Vec3 v) const { return vec3(dot(v, x), dot(v, y), dot(v, z)); }
    LANTERN_HD Vec3 to_world(Vec3 v) const { return x * v.x + y * v.y + z * v.z; }
};

LANTERN_HD inline HairFrame hair_frame(Vec3 tangent, Vec3 ng, Vec3 view) {
    HairFrame f;
    f.x = normalize(tangent);
    const Vec3 c = cross(f.x, view);
    const float len = length(c);
    if (len > 1e-7f) {
        f.y = c / len;
    } else {
        f.y = Frame::from_normal(f.x).s;
    }
    f.z = cross(f.x, f.y);
    f.h = len > 1e-7f ? clampf(dot(cross(ng, f.x), f.z), -1.0f, 1.0f) : 0.0f;
    return f;
}

// ---- The lobes' factors ----

// I0, the modified Bessel function of the first kind, by its power series (x <= ~12 here) and
// log I0 with the large-argument expansion beyond.
LANTERN_HD inline float hair_bessel_i0(float x) {
    const float q = 0.25f * x * x;
    float term = 1.0f, sum = 1.0f;
    for (int k = 1; k < 24; ++k) {
        term *= q / float(k * k);
        sum += term;
        if (term < sum * 1e-8f) break;
    }
    return sum;
}
LANTERN_HD inline float hair_log_bessel_i0(float x) {
    if (x > 12.0f) {  // e^x / sqrt(2 pi x) (1 + 1/(8x) + 9/(128x^2) + 225/(3072x^3))
        const float r = 1.0f / x;
        return x - 0.5f * logf(2.0f * kPi * x) +
               log1pf(r * (0.125f + r * (0.0703125f + r * 0.0732421875f)));
    }
    return logf(hair_bessel_i0(x));
}

// Longitudinal scattering (d'Eon et al. 2011), normalised over theta_i with the cos theta_i
// measure: csch(1/v) / (2v) exp(-sin_i sin_o / v) I0(cos_i cos_o / v); in logs for small v.
LANTERN_HD inline float hair_mp(float sin_i, float cos_i, float sin_o, float cos_o, float v) {
    const float a = cos_i * cos_o / v, b = sin_i * sin_o / v;
    if (v <= 0.1f) return expf(hair_log_bessel_i0(a) - b - 1.0f / v - logf(v));
    return expf(-b) * hair_bessel_i0(a) / (2.0f * v * sinhf(1.0f / v));
}

LANTERN_HD inline float hair_logistic_cdf(float x, float s) {
    const float e = -x / s;
    return e > 80.0f ? 0.0f : 1.0f / (1.0f + expf(e));
}
// The logistic of scale s, cut to [-pi, pi] and renormalised there.
LANTERN_HD inline float hair_trimmed_logistic(float x, float s) {
    const float e = expf(-fabsf(x) / s);
    const float mass = 1.0f - 2.0f * hair_logistic_cdf(-kPi, s);
    return mass > 0.0f ? e / (s * sqr(1.0f + e)) / mass : 0.0f;
}
LANTERN_HD inline float hair_sample_trimmed_logistic(float u, float s) {
    const float lo = hair_logistic_cdf(-kPi, s);
    const float c = lo + u * (1.0f - 2.0f * lo);
    return clampf(-s * logf(1.0f / c - 1.0f), -kPi, kPi);
}
LANTERN_HD inline float hair_wrap_angle(float a) {  // to [-pi, pi)
    return a - 2.0f * kPi * floorf((a + kPi) / (2.0f * kPi));
}

// ---- What eval and sample share: the view's angles and the attenuations ----
struct HairView {
    float sin_o, cos_o, phi_o;
    float gamma_o, gamma_t;
    Vec3 a[kHairLobes];     // attenuation of each lobe
    float pick[kHairLobes]; // lobe selection probabilities (luminance of a, normalised)
};

LANTERN_HD inline float hair_phi_shift(int p, float gamma_o, float gamma_t) {
    return 2.0f * float(p) * gamma_t - 2.0f * gamma_o + float(p) * kPi;
}

LANTERN_HD inline HairView hair_view(const HairParams& hp, Vec3 wo) {
    HairView w;
    w.sin_o = clampf(wo.x, -1.0f, 1.0f);
    w.cos_o = safe_sqrt(1.0f - w.sin_o * w.sin_o);
    w.phi_o = atan2f(wo.z, wo.y);
    // inside the fiber: the refracted longitudinal angle and the modified index (Bravais)
    const float sin_t = w.sin_o / hp.eta, cos_t = safe_sqrt(1.0f - sin_t * sin_t);
    const float eta_p = safe_sqrt(hp.eta * hp.eta - w.sin_o * w.sin_o) / fmaxf(w.cos_o, 1e-7f);
    const float sin_gt = clampf(hp.h / eta_p, -1.0f, 1.0f);
    const float cos_go = safe_sqrt(1.0f - hp.h * hp.h), cos_gt = safe_sqrt(1.0f - sin_gt * sin_gt);
    w.gamma_o = asinf(hp.h);
    w.gamma_t = asinf(sin_gt);
    // one crossing of the fiber: length 2 cos(gamma_t) / cos(theta_t) radii
    const float len = 2.0f * cos_gt / fmaxf(cos_t, 1e-7f);
    const Vec3 t = vec3(expf(-hp.sigma_a.x * len), expf(-hp.sigma_a.y * len),
                        expf(-hp.sigma_a.z * len));
    const float f = fresnel_dielectric(w.cos_o * cos_go, hp.eta);
    w.a[0] = vec3(f);
    w.a[1] = t * sqr(1.0f - f);
    w.a[2] = w.a[1] * t * f;
    const Vec3 tf = t * f;  // the geometric series of the remaining internal reflections
    auto series = [](float x) { return x < 1.0f ? x / (1.0f - x) : 0.0f; };  // x = 1: a[2] is 0
    w.a[3] = w.a[2] * vec3(series(tf.x), series(tf.y), series(tf.z));
    float total = 0.0f;
    for (int p = 0; p < kHairLobes; ++p) {
        w.pick[p] = fmaxf(luminance(w.a[p]), 0.0f);
        total += w.pick[p];
    }
    for (int p = 0; p < kHairLobes; ++p) w.pick[p] = total > 0.0f ? w.pick[p] / total : 0.0f;
    return w;
}

// theta_i turned by the lobe's cuticle tilt (R: +2 alpha, TT: -alpha, TRT: -4 alpha; the rest:
// none), as Cycles' Chiang model reads it; returns sin, |cos| of the turned angle.
LANTERN_HD inline float hair_tilt(int p, float alpha) {
    return p == 0 ? 2.0f * alpha : (p == 1 ? -alpha : (p == 2 ? -4.0f * alpha : 0.0f));
}

struct HairEval {
    Vec3 f_cos;       // the integrand (cosine included, see the file's head)
    float pdf_fwd_w;  // density of hair_sample producing wi given wo
};

// The sampler's density of lobe p's longitudinal part at theta_i: M_p is sampled in the tilted
// angle theta_m in [-pi/2, pi/2] and theta_i = theta_m - tilt, folded over the pole when it
// leaves [-pi/2, pi/2] (sin kept, |cos|); so theta_i has up to two preimages, theta_i + tilt
// and (the fold) -+pi - theta_i + tilt, each with the Jacobian cos(theta_m) / cos(theta_i).
LANTERN_HD inline float hair_mp_pdf(float theta_i, float cos_i, float tilt, const HairView& w,
                                    float v) {
    if (!(cos_i > 0.0f)) return 0.0f;
    const float half = 0.5f * kPi;
    float pdf = 0.0f;
    const float m1 = theta_i + tilt;
    if (fabsf(m1) <= half) pdf += hair_mp(sinf(m1), cosf(m1), w.sin_o, w.cos_o, v) * cosf(m1);
    const float m2 = (tilt > 0.0f ? -kPi : kPi) - theta_i + tilt;
    if (tilt != 0.0f && fabsf(m2) < half)
        pdf += hair_mp(sinf(m2), cosf(m2), w.sin_o, w.cos_o, v) * cosf(m2);
    return pdf / cos_i;
}

// f_cos = sum_p A_p M_p(theta_i + tilt_p, theta_o) N_p(phi), as Cycles reads the tilt (|cos| of
// the turned angle); the pdf is the sampler's exact density (hair_mp_pdf), not f_cos's
// luminance: the two differ only where a lobe's tilt reaches over a pole.
LANTERN_HD inline HairEval hair_eval_view(const HairParams& hp, const HairView& w, Vec3 wi) {
    HairEval e{vec3(0.0f), 0.0f};
    const float sin_i = clampf(wi.x, -1.0f, 1.0f), cos_i = safe_sqrt(1.0f - sin_i * sin_i);
    const float theta_i = asinf(sin_i);
    const float phi = atan2f(wi.z, wi.y) - w.phi_o;
    for (int p = 0; p < kHairLobes; ++p) {
        const float t = hair_tilt(p, hp.alpha), st = sinf(t), ct = cosf(t);
        const float sin_p = sin_i * ct + cos_i * st, cos_p = fabsf(cos_i * ct - sin_i * st);
        const float mp = hair_mp(sin_p, cos_p, w.sin_o, w.cos_o, hp.v[p]);
        const float np = p < 3 ? hair_trimmed_logistic(
                                     hair_wrap_angle(phi - hair_phi_shift(p, w.gamma_o, w.gamma_t)),
                                     hp.s)
                               : 0.5f * kInvPi;
        e.f_cos += w.a[p] * (mp * np);
        if (w.pick[p] > 0.0f)
            e.pdf_fwd_w += w.pick[p] * np * hair_mp_pdf(theta_i, cos_i, t, w, hp.v[p]);
    }
    return e;
}

// hair_eval and hair_sample: out of line on the device (LANTERN_DEVICE_NOINLINE; four eval
// sites in hair_lobe_eval)
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline HairEval hair_eval(const HairParams& hp, Vec3 wo, Vec3 wi) {
    return hair_eval_view(hp, hair_view(hp, wo), wi);
}

struct HairSample {
    Vec3 wi;
    Vec3 weight;  // f_cos / pdf
    float pdf_fwd_w;
    bool valid;
};

// Pick a lobe by its attenuation's luminance (uc, rescaled, then reused for M_p); M_p about the
// mirror of theta_o (d'Eon's inversion), then un-tilted; N_p by the trimmed logistic about the
// lobe's shift (TRRT+: uniform). u.x: N_p, u.y: M_p's azimuth about the mirror direction.
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline HairSample hair_sample(const HairParams& hp, Vec3 wo, Vec2 u, float uc) {
    HairSample s{vec3(0.0f), vec3(0.0f), 0.0f, false};
    const HairView w = hair_view(hp, wo);
    int p = 0;
    float r = uc;
    for (; p < kHairLobes - 1; ++p) {
        if (r < w.pick[p]) break;
        r -= w.pick[p];
    }
    if (!(w.pick[p] > 0.0f)) return s;
    r = clampf(r / w.pick[p], 1e-5f, 1.0f);
    const float v = hp.v[p];
    // cos of the angle between theta_i and the mirror direction, sampled exactly in logs
    const float c = clampf(1.0f + v * logf(r + (1.0f - r) * expf(-2.0f / v)), -1.0f, 1.0f);
    const float sin_m = -c * w.sin_o + safe_sqrt(1.0f - c * c) * cosf(2.0f * kPi * u.y) * w.cos_o;
    const float cos_m = safe_sqrt(1.0f - sin_m * sin_m);
    const float t = -hair_tilt(p, hp.alpha), st = sinf(t), ct = cosf(t);
    const float sin_i = sin_m * ct + cos_m * st, cos_i = fabsf(cos_m * ct - sin_m * st);
    const float phi = p < 3 ? hair_phi_shift(p, w.gamma_o, w.gamma_t) +
                                  hair_sample_trimmed_logistic(u.x, hp.s)
                            : 2.0f * kPi * u.x;
    const float phi_i = w.phi_o + phi;
    s.wi = vec3(sin_i, cos_i * cosf(phi_i), cos_i * sinf(phi_i));
    const HairEval e = hair_eval_view(hp, w, s.wi);
    if (!(e.pdf_fwd_w > 0.0f)) return s;
    s.pdf_fwd_w = e.pdf_fwd_w;
    s.weight = e.f_cos / e.pdf_fwd_w;
    s.valid = is_finite(s.weight);
    return s;
}

}  // namespace lantern
