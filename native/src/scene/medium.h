// Homogeneous participating media (docs/volumes.md): coefficients per RGB channel, the
// Henyey-Greenstein phase function, transmittance, the emission integral along a segment and
// free-flight distance sampling with one-sample MIS over the three channels. Host+device, no state.
#pragma once

#include "core/math.h"

namespace lantern {

// A medium as stages see it (SceneView::media); coefficients in 1/m, Blender's units. Emission
// is radiance added per metre travelled (Cycles' volume Emission), before attenuation.
struct Medium {
    Vec3 sigma_a;    // absorption
    Vec3 sigma_s;    // scattering
    Vec3 sigma_t;    // sigma_a + sigma_s
    Vec3 emission;
    float g;         // Henyey-Greenstein anisotropy, |g| <= 0.999 (the host clamps it)
    uint32_t scatters;  // 1: some channel's sigma_s > 0 (else transmittance is deterministic)
    uint32_t emits;     // 1: emission > 0 in some channel
    uint32_t hetero;    // 1: heterogeneous (scene/medium_hetero.h): the coefficients above are
                        // per unit of density, the density a node program's (density_prog)
    // ---- heterogeneous media only (hetero 1) ----
    int32_t density_prog;  // index into SceneView::programs (kTargetDensity), -1: none (1)
    int32_t density_grid;  // a Volume object's: index into SceneView::grids, -1: none (1); the
                           // density is the program's value times the grid's
    Vec3 sigma_a0;         // a constant part added to density x sigma_a (the world's volume)
    Vec3 sigma_s0;
    float majorant;        // >= the extinction's largest channel wherever the medium is (1/m)
    float density_max;     // the bound on the density the majorant was built from
    int32_t outside;       // the medium around this one's mesh (a path leaving it enters it):
                           // the enclosing mesh medium's, or the world's (-1: vacuum)
    // ---- Volume objects' fire (scene/medium_fire.h); each -1: none ----
    int32_t majorant_grid;     // index into SceneView::majorant_grids; -1: the constant majorant
    int32_t temperature_grid;  // SceneView::grids: blackbody emission per point
    int32_t flame_grid;        // SceneView::grids: emission flame_emission x flame per point
    float bb_intensity;        // Principled Volume's Blackbody Intensity (with a temperature grid)
    float bb_temperature;      // its Temperature socket: T = socket x the grid's value
    // ---- a Volume object's colour grid (Principled Volume's Color Attribute; -1: none): per
    // unit of density, scattering sigma_s + color_scatter c and absorption
    // sigma_a + color_absorb max(1 - color_base c, 0), c the grid's colour at the point
    // (scene/medium_hetero.h: medium_coeffs_at) ----
    int32_t color_grid;
    int32_t emission_prog;     // SceneView::programs (kTargetVolumeEmission): emission
                               // flame_emission x max(program, 0) per point; -1: none
    Vec3 bb_tint;              // Blackbody Tint x the shader's mix weight
    Vec3 flame_emission;       // radiance per metre per unit of the flame grid
    Vec3 color_scatter;        // Principled Volume's Color x Density (x weight, object scale)
    Vec3 color_absorb;         // max(1 - sqrt(Absorption Color), 0) x Density (the same)
    Vec3 color_base;           // the Color socket (the colour grid multiplies it)
    // ---- colour programs (-1: none; scene/medium_hetero.h, scene/medium_fire.h) ----
    int32_t color_prog;           // SceneView::programs (kTargetVolumeColor): the colour c per
                                  // point, as the colour grid's, in its place (-1 with an
                                  // absorption program: c is color_base)
    int32_t absorb_prog;          // kTargetVolumeAbsorptionColor: Principled Volume's
                                  // Absorption Color a per point (factor max(1 - sqrt(a), 0))
    int32_t emission_color_prog;  // kTargetVolumeEmissionColor: emission flame_emission x
                                  // max(c, 0) (x the flame grid's or the strength program's value)
    Vec3 absorb_alone;  // absorption per unit density that the absorption program's factor
                        // max(1 - sqrt(a), 0) multiplies alone (a Principled Volume's beside
                        // another shader's Color graph: its max(1 - Color, 0) x Density); not 0:
                        // color_absorb then takes max(1 - c, 0) alone
    int32_t shadow_as;  // the medium a shadow ray takes here (read where
                        // SceneView::no_shadow_objects is not 0): this one, or where its mesh casts
                        // no shadow the enclosing medium's (Cycles skips such a volume on
                        // shadow rays, from inside too: pt_volume.h shadow_medium)
};

// ---- Henyey-Greenstein: cos_theta between the direction travelled and the scattered one ----
LANTERN_HD inline float hg_phase(float g, float cos_theta) {
    const float denom = 1.0f + g * g - 2.0f * g * cos_theta;
    return (1.0f - g * g) / (4.0f * kPi * denom * sqrtf(fmaxf(denom, 1e-12f)));
}

// A direction drawn from the phase function about `d` (the direction travelled, unit), with
// its solid-angle pdf (which equals the phase function's value: the weight is 1).
LANTERN_HD inline Vec3 hg_sample(float g, Vec3 d, Vec2 u, float* pdf_w) {
    float cos_theta;
    if (fabsf(g) < 1e-3f) {
        cos_theta = 1.0f - 2.0f * u.x;
    } else {
        const float k = (1.0f - g * g) / (1.0f - g + 2.0f * g * u.x);
        cos_theta = (1.0f + g * g - k * k) / (2.0f * g);
    }
    cos_theta = fminf(fmaxf(cos_theta, -1.0f), 1.0f);
    const float sin_theta = sqrtf(fmaxf(0.0f, 1.0f - cos_theta * cos_theta));
    const float phi = 2.0f * kPi * u.y;
    const Frame f = Frame::from_normal(d);
    *pdf_w = hg_phase(g, cos_theta);
    return normalize(f.to_world(Vec3{sin_theta * cosf(phi), sin_theta * sinf(phi), cos_theta}));
}

// ---- Along a segment of length t (kInf: to infinity) ----
LANTERN_HD inline float medium_channel_tr(float sigma, float t) {
    return sigma > 0.0f ? expf(-sigma * t) : 1.0f;
}
// Whether the medium's extinction is the same in the three channels (a grey fog): its
// transmittance is then one exponential, not three of the same value (the same bits).
LANTERN_HD inline bool medium_grey(const Medium& m) {
    return m.sigma_t.x == m.sigma_t.y && m.sigma_t.x == m.sigma_t.z;
}
LANTERN_HD inline Vec3 medium_transmittance(const Medium& m, float t) {
    if (medium_grey(m)) return vec3(medium_channel_tr(m.sigma_t.x, t));
    return Vec3{medium_channel_tr(m.sigma_t.x, t), medium_channel_tr(m.sigma_t.y, t),
                medium_channel_tr(m.sigma_t.z, t)};
}
// The emission the segment adds, attenuated on its way: emission x integral of T over [0, t].
LANTERN_HD inline float medium_channel_emit(float sigma, float t) {
    return sigma > 0.0f ? -expm1f(-sigma * t) / sigma : t;
}
LANTERN_HD inline Vec3 medium_emission_integral(const Medium& m, float t) {
    return m.emission * Vec3{medium_channel_emit(m.sigma_t.x, t),
                             medium_channel_emit(m.sigma_t.y, t),
                             medium_channel_emit(m.sigma_t.z, t)};
}

// ---- Free-flight sampling: a channel drawn with probabilities pmf (from the path's
// throughput), a distance from that channel's exponential; the pdf is the pmf-weighted mean of
// the three (one-sample MIS, balance heuristic). ----
LANTERN_HD inline Vec3 medium_channel_pmf(Vec3 beta) {
    const Vec3 b{fmaxf(beta.x, 0.0f), fmaxf(beta.y, 0.0f), fmaxf(beta.z, 0.0f)};
    const float sum = b.x + b.y + b.z;
    if (!(sum > 0.0f) || !(sum <= kInf)) return vec3(1.0f / 3.0f);
    return b / sum;
}

struct MediumStep {
    float t;         // where it scatters (scattered) or the segment's end
    bool scattered;  // an event inside the segment: a medium vertex at t
    Vec3 weight;     // throughput factor: sigma_s T(t) / pdf(t), or T(end) / P(t >= end)
};

// The probability that a flight passes t (the pass weight's denominator), for light found
// along the segment before its end.
// (tr: the medium's transmittance over t, medium_transmittance)
LANTERN_HD inline float medium_pass_pdf(Vec3 pmf, Vec3 tr) {
    return pmf.x * tr.x + pmf.y * tr.y + pmf.z * tr.z;
}
LANTERN_HD inline float medium_pass_pdf(const Medium& m, Vec3 pmf, float t) {
    return medium_pass_pdf(pmf, medium_transmittance(m, t));
}
// The throughput factor of a flight that passes t: T(t) / P(passes t); T(t) alone in a medium
// that does not scatter (no distance is sampled there).
LANTERN_HD inline Vec3 medium_pass_weight(const Medium& m, Vec3 pmf, float t) {
    const Vec3 tr = medium_transmittance(m, t);
    if (!m.scatters) return tr;
    const float p = medium_pass_pdf(pmf, tr);
    return p > 0.0f ? tr / p : vec3(0.0f);
}

LANTERN_HD inline MediumStep medium_sample_distance(const Medium& m, float t_end, Vec3 pmf,
                                                    float u_channel, float u_dist) {
    MediumStep r{t_end, false, vec3(0.0f)};
    if (!m.scatters) {  // absorption only: nothing to sample
        r.weight = medium_transmittance(m, t_end);
        return r;
    }
    const float sigma = u_channel < pmf.x             ? m.sigma_t.x
                        : u_channel < pmf.x + pmf.y   ? m.sigma_t.y
                                                      : m.sigma_t.z;
    const float t = sigma > 0.0f ? -log1pf(-u_dist) / sigma : kInf;
    if (t < t_end) {
        const Vec3 tr = medium_transmittance(m, t);
        const float pdf = pmf.x * m.sigma_t.x * tr.x + pmf.y * m.sigma_t.y * tr.y +
                          pmf.z * m.sigma_t.z * tr.z;
        r.t = t;
        r.scattered = true;
        r.weight = pdf > 0.0f ? m.sigma_s * tr / pdf : vec3(0.0f);
        return r;
    }
    r.weight = medium_pass_weight(m, pmf, t_end);
    return r;
}

}  // namespace lantern
