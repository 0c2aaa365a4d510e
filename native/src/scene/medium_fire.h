// Fire in Volume objects (docs/volumes.md): a medium's emission per point from its temperature
// grid (Principled Volume's blackbody, as Cycles: T = the Temperature socket x a voxel's value,
// Blackbody Tint x sigma x mix(1, T^4, Blackbody Intensity) x the blackbody colour of T,
// interpolated between voxels) and its
// flame grid (flame_emission x flame: an Attribute node on Emission Strength), added to the
// constant emission. Host+device; the blackbody colours are a table in the view.
#pragma once

#include "scene/material_program.h"
#include "scene/medium.h"
#include "scene/medium_grid.h"
#include "scene/scene_view.h"

namespace lantern {

// Stefan-Boltzmann per steradian with Cycles' 1e-6 scale (docs/volumes.md), and its cutoff
constexpr float kBlackbodySigma = 5.670373e-8f * 1e-6f / kPi;
constexpr float kBlackbodyCutoff = 1e-5f;
// The blackbody colour table (scene/blackbody_table.cpp): kBlackbodyKnots RGB rows of luminance
// 1, uniform in 1/T from kBlackbodyTMin to kBlackbodyTMax (clamped outside), not clamped at 0
constexpr int kBlackbodyKnots = 256;
constexpr float kBlackbodyTMin = 800.0f, kBlackbodyTMax = 12000.0f;
// Host: the table's rows (3 floats each), for SceneView::blackbody_table.
const float* blackbody_table_host();

// The blackbody colour of T (linear Rec.709, luminance 1), addon/export/node_spectral.py's
// table, linear between knots, not clamped: Principled Volume's blackbody in Cycles is not
// (blue is negative below about 1900 K, and that emission takes blue away; the Blackbody node
// clamps at 0). Measured: clamped, a fire at 1800-3600 K read 1.3 % brighter in blue than
// Cycles in a block of its cool edge.
LANTERN_HD inline Vec3 blackbody_color(const float* table, float t) {
    const float a = 1.0f / kBlackbodyTMin, b = 1.0f / kBlackbodyTMax;
    const float inv = 1.0f / fmaxf(t, 1.0f);
    float u = (inv - a) / (b - a) * float(kBlackbodyKnots - 1);
    u = fminf(fmaxf(u, 0.0f), float(kBlackbodyKnots - 1));
    const int i = u >= float(kBlackbodyKnots - 1) ? kBlackbodyKnots - 2 : int(u);
    const float f = u - float(i);
    const float* r0 = table + 3 * i;
    const float* r1 = r0 + 3;
    return Vec3{r0[0] + (r1[0] - r0[0]) * f, r0[1] + (r1[1] - r0[1]) * f,
                r0[2] + (r1[2] - r0[2]) * f};
}

// The blackbody radiance per metre at temperature t (kelvin) for Blackbody Intensity bb; t is
// taken within [0, 1e6] K (NaN: 0), where T^4 stays finite in floats.
constexpr float kBlackbodyTMaxClamp = 1e6f;
LANTERN_HD inline Vec3 blackbody_emission(const float* table, float bb, Vec3 tint, float t) {
    t = t > 0.0f ? fminf(t, kBlackbodyTMaxClamp) : 0.0f;
    const float t2 = t * t;
    const float intensity = kBlackbodySigma * ((1.0f - bb) + bb * t2 * t2);
    if (!(intensity > kBlackbodyCutoff)) return vec3(0.0f);
    return tint * blackbody_color(table, t) * intensity;
}

// The blackbody of the temperature grid at p: the blackbody of each of the 8 voxels around p,
// interpolated trilinearly (the expectation of Cycles' stochastic lookup, which draws one voxel
// with the trilinear weights; interpolating T first gives less where T varies, T^4 being
// convex: measured 10 % darker than Cycles on a fire whose temperature steps at its edge).
LANTERN_HD inline Vec3 grid_blackbody(const SceneView& s, const Medium& m, Vec3 p) {
    const DensityGrid& g = s.grids[m.temperature_grid];
    const Vec3 q = g.world_to_index.point(p);
    if (!(q.x > -1.0f && q.y > -1.0f && q.z > -1.0f && q.x < float(g.nx) &&
          q.y < float(g.ny) && q.z < float(g.nz)))
        return blackbody_emission(s.blackbody_table, m.bb_intensity, m.bb_tint, 0.0f);
    const float fx = floorf(q.x), fy = floorf(q.y), fz = floorf(q.z);
    const int i = int(fx), j = int(fy), k = int(fz);
    const float tx = q.x - fx, ty = q.y - fy, tz = q.z - fz;
    Vec3 e = vec3(0.0f);
    for (int c = 0; c < 8; ++c) {
        const int di = c & 1, dj = (c >> 1) & 1, dk = c >> 2;
        const float w = (di ? tx : 1.0f - tx) * (dj ? ty : 1.0f - ty) * (dk ? tz : 1.0f - tz);
        if (!(w > 0.0f)) continue;
        const float t = m.bb_temperature * grid_voxel(g, s.grid_voxels, i + di, j + dj, k + dk);
        e = e + blackbody_emission(s.blackbody_table, m.bb_intensity, m.bb_tint, t) * w;
    }
    return e;
}

// A colour program's value at shading point sp inside a medium (kTargetVolumeColor,
// kTargetVolumeEmissionColor), each channel within [0, 1e9] (NaN is 0 in program_run; a
// negative colour is 0, where Cycles would scatter or emit negatively).
LANTERN_HD inline Vec3 medium_color_at(const SceneView& s, int32_t prog, const ShadePoint& sp) {
    const Vec3 c = program_run(s, s.programs[prog], sp);
    return Vec3{fminf(fmaxf(c.x, 0.0f), 1e9f), fminf(fmaxf(c.y, 0.0f), 1e9f),
                fminf(fmaxf(c.z, 0.0f), 1e9f)};
}

// The medium's emission at p (radiance per metre): the constant part and its grids' parts
// (the flame grid's, or a graph's on Emission Strength: flame_emission x max(its value, 0);
// med the medium's index, for the program's shading point).
LANTERN_HD inline Vec3 medium_emission_at(const SceneView& s, const Medium& m, int32_t med,
                                          Vec3 p) {
    Vec3 e = m.emission;
    if (!m.hetero) return e;
    ShadePoint sp;
    sp.p = p;
    sp.n = sp.ng = sp.wo = vec3(0.0f);
    sp.st = sp.bary = Vec2{};
    sp.tri = -2 - med;
    sp.backfacing = false;
    if (m.emission_color_prog >= 0) {
        // a graph on the Emission Color: flame_emission (the weight x the strength) x its
        // colour, x the flame grid's or the strength program's value where there is one
        float k = 1.0f;
        if (m.flame_grid >= 0 && m.flame_grid < s.num_grids)
            k = grid_lookup(s.grids[m.flame_grid], s.grid_voxels, p);
        else if (m.emission_prog >= 0)
            k = fminf(fmaxf(program_run(s, s.programs[m.emission_prog], sp).x, 0.0f), 1e9f);
        if (k > 0.0f)
            e = e + m.flame_emission * medium_color_at(s, m.emission_color_prog, sp) * k;
    } else {
        if (m.flame_grid >= 0 && m.flame_grid < s.num_grids)
            e = e + m.flame_emission * grid_lookup(s.grids[m.flame_grid], s.grid_voxels, p);
        if (m.emission_prog >= 0)
            e = e + m.flame_emission *
                        fminf(fmaxf(program_run(s, s.programs[m.emission_prog], sp).x, 0.0f),
                              1e9f);
    }
    if (m.temperature_grid >= 0 && m.temperature_grid < s.num_grids && s.blackbody_table)
        e = e + grid_blackbody(s, m, p);
    return e;
}

}  // namespace lantern
