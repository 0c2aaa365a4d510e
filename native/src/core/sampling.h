// Sample warps with their densities. Solid-angle pdfs end in _w, area pdfs in _a; every warp
// maps [0,1)^2 and its pdf integrates to one over its domain (checked in tests/cpp).
#pragma once

#include "core/math.h"

namespace lantern {

LANTERN_HD inline Vec3 sample_cosine_hemisphere(Vec2 u, float* pdf_w) {
    // Concentric disk (Shirley & Chiu 1997) lifted to the hemisphere (Malley's method).
    float a = 2.0f * u.x - 1.0f, b = 2.0f * u.y - 1.0f;
    float r, phi;
    if (a == 0.0f && b == 0.0f) {
        r = 0.0f;
        phi = 0.0f;
    } else if (fabsf(a) > fabsf(b)) {
        r = a;
        phi = (kPi / 4.0f) * (b / a);
    } else {
        r = b;
        phi = (kPi / 2.0f) - (kPi / 4.0f) * (a / b);
    }
    float x = r * cosf(phi), y = r * sinf(phi);
    float z = safe_sqrt(1.0f - x * x - y * y);
    if (pdf_w) *pdf_w = z * kInvPi;
    return {x, y, z};
}
LANTERN_HD inline float pdf_cosine_hemisphere(float cos_theta) {
    return fmaxf(cos_theta, 0.0f) * kInvPi;
}

LANTERN_HD inline Vec2 sample_concentric_disk(Vec2 u) {
    Vec3 h = sample_cosine_hemisphere(u, nullptr);
    return {h.x, h.y};
}

LANTERN_HD inline Vec3 sample_uniform_sphere(Vec2 u, float* pdf_w) {
    float z = 1.0f - 2.0f * u.x;
    float r = safe_sqrt(1.0f - z * z);
    float phi = 2.0f * kPi * u.y;
    if (pdf_w) *pdf_w = 0.25f * kInvPi;
    return {r * cosf(phi), r * sinf(phi), z};
}

// Uniform over the cone of directions within acos(cos_max) of +Z.
LANTERN_HD inline Vec3 sample_uniform_cone(Vec2 u, float cos_max, float* pdf_w) {
    float cos_t = 1.0f - u.x * (1.0f - cos_max);
    float sin_t = safe_sqrt(1.0f - cos_t * cos_t);
    float phi = 2.0f * kPi * u.y;
    if (pdf_w) *pdf_w = 1.0f / (2.0f * kPi * (1.0f - cos_max));
    return {sin_t * cosf(phi), sin_t * sinf(phi), cos_t};
}
LANTERN_HD inline float pdf_uniform_cone(float cos_max) {
    return 1.0f / (2.0f * kPi * (1.0f - cos_max));
}

// Directions from a point at squared distance dist2 from a sphere's centre towards the sphere of
// the given radius, uniform in the solid angle it subtends; +Z points at the centre. A point on
// or inside the sphere gets pdf 0 (the caller treats it as no sample).
LANTERN_HD inline Vec3 sample_sphere_solid_angle(Vec2 u, float dist2, float radius, float* pdf_w) {
    float sin2_max = radius * radius / dist2;
    if (!(sin2_max < 1.0f)) {
        if (pdf_w) *pdf_w = 0.0f;
        return {0.0f, 0.0f, 1.0f};
    }
    return sample_uniform_cone(u, safe_sqrt(1.0f - sin2_max), pdf_w);
}

// Barycentrics uniform over a triangle (Heitz 2019, "A low-distortion map between triangle
// and square").
LANTERN_HD inline Vec2 sample_triangle(Vec2 u) {
    float b0, b1;
    if (u.y > u.x) {
        b0 = u.x * 0.5f;
        b1 = u.y - b0;
    } else {
        b1 = u.y * 0.5f;
        b0 = u.x - b1;
    }
    return {b0, b1};
}

LANTERN_HD inline float pdf_a_to_w(float pdf_a, float dist2, float cos_at_light) {
    return cos_at_light > 0.0f ? pdf_a * dist2 / cos_at_light : 0.0f;
}

LANTERN_HD inline float power_heuristic(float pdf_a, float pdf_b) {
    float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
    return a + b > 0.0f ? a / (a + b) : 0.0f;
}

// Index into a discrete distribution given by its normalised CDF (cdf[n-1] == 1).
LANTERN_HD inline int sample_cdf(const float* cdf, int n, float u) {
    int lo = 0, hi = n - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (cdf[mid] <= u) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

}  // namespace lantern
