// Energy compensation for GGX reflection: the light single-scattering microfacet models lose
// between microfacets, restored as Kulla & Conty ("Revisiting Physically Based Shading at
// Imageworks", 2017) and Cycles' Multiscatter GGX do: the lobe is scaled by
// 1 + F_ms (1 - E(mu)) / E(mu), E the directional albedo of the white (F = 1) lobe of that
// roughness at the camera-side cosine mu, F_ms = F_avg E_avg / (1 - F_avg (1 - E_avg)) the
// Fresnel of the extra bounces (F_avg the cosine-weighted average Fresnel, E_avg of E). A white
// rough metal then reflects 1 at every angle. Tables are per material (scene build).
#pragma once

#include "bsdf/microfacet.h"
#include "scene/scene_view.h"

namespace lantern {

// Linear lookup in any of a material's albedo tables (kPrincipledAlbedoN entries at cosines
// (k / (N - 1))^2; |mu| is used).
LANTERN_HD inline float ms_table(const float* t, float mu) {
    float x = sqrtf(clampf(fabsf(mu), 0.0f, 1.0f)) * (kPrincipledAlbedoN - 1);
    int i = min_int(int(x), kPrincipledAlbedoN - 2);
    float f = x - float(i);
    return t[i] * (1.0f - f) + t[i + 1] * f;
}

// A value of m's roughness rows (MaterialTables::rough_rows) at roughness r: get(row) ->
// float of one row, interpolated cubically (Catmull-Rom) between the rows at j / (kRoughRows -
// 1). The values are smooth in r but for the quadrature's own variation from one roughness to
// the next (up to 1e-3 in E), which no interpolation removes: the rows agree with a constant
// material's own tables within that (tests/cpp/test_bsdf_rough_rows.cpp).
template <class Get>
LANTERN_HD inline float ms_rough(const Material& m, float r, const Get& get) {
    const MaterialTables* rows = m.tables + m.tables->rough_rows;
    const float x = clampf(r, 0.0f, 1.0f) * (kRoughRows - 1);
    const int j = min_int(int(x), kRoughRows - 2);
    const float t = x - float(j);
    const float p1 = get(rows[j]), p2 = get(rows[j + 1]);
    const float p0 = j > 0 ? get(rows[j - 1]) : 2.0f * p1 - p2;
    const float p3 = j + 2 < kRoughRows ? get(rows[j + 2]) : 2.0f * p2 - p1;
    const float t2 = t * t, t3 = t2 * t;
    return 0.5f * (2.0f * p1 + (p2 - p0) * t + (2.0f * p0 - 5.0f * p1 + 4.0f * p2 - p3) * t2 +
                   (3.0f * p1 - p0 - 3.0f * p2 + p3) * t3);
}

// E(mu) of the white GGX lobe at m's roughness: its table, or its rows at a per-hit roughness.
LANTERN_HD inline float ms_white_albedo(const Material& m, float mu) {
    if (!m.tables->rough_rows) return ms_table(m.tables->ms_e, mu);
    return ms_rough(m, m.roughness,
                    [mu](const MaterialTables& t) { return ms_table(t.ms_e, mu); });
}

// The factor for a lobe with multiple-scattering Fresnel fms, seen at camera-side cosine mu.
LANTERN_HD inline Vec3 ms_scale(const Material& m, Vec3 fms, float mu) {
    if (!m.multiscatter) return vec3(1.0f);
    float e = ms_white_albedo(m, mu);
    if (!(e > 1e-3f) || e >= 1.0f) return vec3(1.0f);
    return vec3(1.0f) + fms * ((1.0f - e) / e);
}

// ---- Host: the tables ----

// Directional albedo at cosine mu of GGX reflection with Fresnel fresnel(cos(wo, m)) -> Vec3,
// by stratified visible-normal sampling (f cos / pdf = F G2 / G1(wo)), n x n samples. Fills
// every albedo table of the materials (white GGX, principled specular layer, coat).
// The radial coordinate is u.x = 1 - (1 - t)^2, t on the midpoint grid (weight 2 (1 - t)): GGX's
// long tail (normals past 45 degrees, ~alpha^2 of the mass, so ~0.8 % at roughness 0.3) lies in
// u.x > 1 / (1 + alpha^2), inside the last of 48 uniform strata, whose midpoint missed it: E
// read 0.7 % high at normal incidence and a white rough metal 0.4-0.6 % dark. Warped, the
// table is within 0.04 % of a 512 x 512 reference at every roughness (furnace, docs/materials.md).
template <typename F>
inline Vec3 ggx_reflection_albedo(const Ggx& g, float mu, F fresnel, int n) {
    mu = clampf(mu, 1e-3f, 1.0f);
    Vec3 wo = vec3(safe_sqrt(1.0f - mu * mu), 0.0f, mu);
    double sum[3] = {0.0, 0.0, 0.0};
    for (int i = 0; i < n; ++i) {
        const float om = 1.0f - (i + 0.5f) / n;
        const float ux = 1.0f - om * om, wgt = 2.0f * om;
        for (int j = 0; j < n; ++j) {
            Vec3 h = g.sample_visible(wo, Vec2{ux, (j + 0.5f) / n});
            Vec3 wi = reflect(wo, h);
            if (wi.z <= 0.0f) continue;
            Vec3 v = fresnel(dot(wo, h)) * (wgt * g.g2(wo, wi) / g.g1(wo));
            for (int c = 0; c < 3; ++c) sum[c] += v[c];
        }
    }
    const double inv = 1.0 / (double(n) * n);
    return vec3(float(sum[0] * inv), float(sum[1] * inv), float(sum[2] * inv));
}

// Directional albedo of the white GGX lobe at cosine mu.
inline float ggx_white_albedo(float roughness, float mu, int n = 48) {
    Ggx g = Ggx::isotropic(ggx_alpha_from_roughness(roughness));
    if (g.effectively_smooth()) return 1.0f;
    return ggx_reflection_albedo(g, mu, [](float) { return vec3(1.0f); }, n).x;
}

// Fills t.ms_e and t.e_avg for roughness r and returns E_avg = 2 int E(mu) mu dmu.
inline float ms_fill_table(float r, MaterialTables& t) {
    for (int k = 0; k < kPrincipledAlbedoN; ++k)
        t.ms_e[k] = ggx_white_albedo(r, sqr(float(k) / (kPrincipledAlbedoN - 1)));
    const int n = 256;
    double avg = 0.0;
    for (int i = 0; i < n; ++i) {
        float mu = (i + 0.5f) / n;
        avg += 2.0 * ms_table(t.ms_e, mu) * mu / n;
    }
    t.e_avg = float(avg);
    return t.e_avg;
}
inline float ms_fill_table(const Material& m, MaterialTables& t) {
    return ms_fill_table(m.roughness, t);
}

// The cosine-weighted average 2 int F(mu) mu dmu of a Fresnel function F(mu) -> Vec3.
template <typename F>
inline Vec3 ms_average_fresnel(F fresnel) {
    const int n = 256;
    Vec3 favg = vec3(0.0f);
    for (int i = 0; i < n; ++i) {
        float mu = (i + 0.5f) / n;
        favg += fresnel(mu) * (2.0f * mu / n);
    }
    return favg;
}

// F_ms from the average Fresnel and E_avg (host and device: a textured metal's base colour).
LANTERN_HD inline Vec3 ms_fresnel_from_average(Vec3 favg, float e_avg) {
    Vec3 r;
    for (int c = 0; c < 3; ++c) {
        float f = clampf(favg[c], 0.0f, 1.0f);
        float v = f * e_avg / fmaxf(1.0f - f * (1.0f - e_avg), 1e-6f);
        (c == 0 ? r.x : c == 1 ? r.y : r.z) = v;
    }
    return r;
}

// F_ms from a Fresnel function F(mu) -> Vec3 and E_avg.
template <typename F>
inline Vec3 ms_fresnel(F fresnel, float e_avg) {
    return ms_fresnel_from_average(ms_average_fresnel(fresnel), e_avg);
}

}  // namespace lantern
