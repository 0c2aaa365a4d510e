// Heterogeneous media (docs/volumes.md): a medium's coefficients per unit of density times a
// density that a node program gives at each point inside (kTargetDensity; Generated and Object
// coordinates read as affine maps of the world position, SceneView::medium_maps), plus a
// constant part (the world's volume). Sampled by null-collision tracking against majorants
// constant along pieces of the ray (scene/medium_majorant.h: a Volume object's bricks, else one
// per medium): distances by spectral tracking, transmittance by ratio tracking; both unbiased for
// any majorant > 0 (where the density exceeds it the null weights turn negative). Host+device,
// no state; the random numbers come from a hashed stream (medium_tracking_rng).
#pragma once

#include "core/rng.h"
#include "scene/material_program.h"
#include "scene/medium.h"
#include "scene/medium_fire.h"
#include "scene/medium_majorant.h"

namespace lantern {

// Tentative collisions per tracked segment at most: a segment that needs more (an enormous
// density over a long way) ends there with weight 0, where its transmittance is about 0 anyway.
constexpr int kMaxTrackingSteps = 4096;

// The stream a tracking draws from: the path's stream hashed, in a block of its own for each
// (dimension the path's stream is at, slot): slot 0 the segment's distance, 1 and 2 its shadow
// rays (pt_volume.h), so no two trackings of a path share numbers.
LANTERN_HD inline Rng medium_tracking_rng(const Rng& path, uint32_t slot) {
    Rng r = path;
#ifdef LANTERN_RNG_PCG
    // (bench/qmc_noise.py's PCG build: a stream of its own from the path's state and the slot)
    r.state = mix64(path.state ^ (0x545241434Bull + slot));
    r.next();
#else
    r.dim = kQmcDims + ((path.dim * 4u + slot) << 14);
#endif
    return r;
}

// The point p inside medium med as a program sees it: no triangle (tri -2 - med, so that
// attributes read the medium's maps), no normal, the viewer back along d.
LANTERN_HD inline ShadePoint medium_shade_point(int32_t med, Vec3 p, Vec3 d) {
    ShadePoint sp;
    sp.p = p;
    sp.n = vec3(0.0f);
    sp.ng = vec3(0.0f);
    sp.wo = -d;
    sp.st = Vec2{};
    sp.tri = -2 - med;
    sp.bary = Vec2{};
    sp.backfacing = false;
    return sp;
}

// The density at p: the density program's value, else the Volume object's density grid's (1
// where the medium has neither). A Volume object's medium with a program (a node graph on its
// Density, which reads the object's grids by kOpGrid) keeps its density grid for its box and
// bricks only: the program alone is the density (it multiplies by the Density Attribute's grid
// itself where Cycles does). (>= 0: Cycles takes a negative density as none; NaN is 0 in
// program_run; at most 1e9, as homogeneous coefficients are clamped.)
LANTERN_HD inline float medium_density(const SceneView& s, const Medium& m, int32_t med, Vec3 p,
                                       Vec3 d) {
    float v = 1.0f;
    if (m.density_prog >= 0)
        v = program_run(s, s.programs[m.density_prog], medium_shade_point(med, p, d)).x;
    else if (m.density_grid >= 0 && m.density_grid < s.num_grids)  // (a zero Medium{}: none)
        v = grid_lookup(s.grids[m.density_grid], s.grid_voxels, p);
    return v > 0.0f ? fminf(v, 1e9f) : 0.0f;
}

// A colour grid scales m's coefficients (a zero Medium{} has none: its grid 0 is not a colour).
LANTERN_HD inline bool medium_has_color(const SceneView& s, const Medium& m) {
    return m.color_grid >= 0 && m.color_grid < s.num_grids && s.grids[m.color_grid].channels == 3;
}

struct MediumCoeffs {
    Vec3 sigma_a, sigma_s;
};
LANTERN_HD inline MediumCoeffs medium_coeffs_at(const SceneView& s, const Medium& m, int32_t med,
                                                Vec3 p, Vec3 d) {
    const float den = medium_density(s, m, med, p, d);
    if ((m.color_prog >= 0 || m.absorb_prog >= 0) && den > 0.0f) {
        // graphs on the Color (kTargetVolumeColor: c per point, else color_base) and on
        // Principled Volume's Absorption Color (kTargetVolumeAbsorptionColor: a per point),
        // as Cycles sets up the closures: c scatters, max(1 - c, 0) x max(1 - sqrt(a), 0)
        // absorbs (c, a < 0 are 0: Cycles would scatter negatively; NaN is 0 in program_run;
        // at most 1e9)
        const ShadePoint sp = medium_shade_point(med, p, d);
        const Vec3 c = m.color_prog >= 0 ? medium_color_at(s, m.color_prog, sp) : m.color_base;
        Vec3 ab = Vec3{fmaxf(1.0f - c.x, 0.0f), fmaxf(1.0f - c.y, 0.0f), fmaxf(1.0f - c.z, 0.0f)};
        Vec3 alone = vec3(0.0f);
        if (m.absorb_prog >= 0) {
            // the Absorption Color's factor: of the same shader's colour, or (absorb_alone, a
            // Color graph on another shader) of its own constant colour's absorption
            const Vec3 a = medium_color_at(s, m.absorb_prog, sp);
            const Vec3 ka{fmaxf(1.0f - sqrtf(a.x), 0.0f), fmaxf(1.0f - sqrtf(a.y), 0.0f),
                          fmaxf(1.0f - sqrtf(a.z), 0.0f)};
            alone = m.absorb_alone * ka;
            if (!(max_component(m.absorb_alone) > 0.0f)) ab = ab * ka;
        }
        return MediumCoeffs{m.sigma_a0 + (m.sigma_a + m.color_absorb * ab + alone) * den,
                            m.sigma_s0 + (m.sigma_s + m.color_scatter * c) * den};
    }
    if (medium_has_color(s, m)) {
        // the colour grid (Cycles' Principled Volume: Color x the attribute's colour scatters,
        // max(1 - that, 0) x (1 - sqrt(Absorption Color)) absorbs)
        const GridColor c = grid_color(s.grids[m.color_grid], s.grid_voxels, m.color_base, p);
        return MediumCoeffs{m.sigma_a0 + (m.sigma_a + m.color_absorb * c.absorb) * den,
                            m.sigma_s0 + (m.sigma_s + m.color_scatter * c.color) * den};
    }
    return MediumCoeffs{m.sigma_a0 + m.sigma_a * den, m.sigma_s0 + m.sigma_s * den};
}

LANTERN_HD inline float mean_abs(Vec3 v) { return (fabsf(v.x) + fabsf(v.y) + fabsf(v.z)) / 3.0f; }

// The walk of pieces of constant majorant along o + d t, t in [0, t_end], that the trackings
// below follow: the medium's bricks (scene/medium_majorant.h) or its one majorant.
LANTERN_HD inline MajorantWalk medium_majorant_walk(const SceneView& s, const Medium& m, Vec3 o,
                                                    Vec3 d, float t_end) {
    if (m.majorant_grid >= 0 && m.majorant_grid < s.num_majorant_grids)
        return majorant_walk_grid(s.majorant_grids[m.majorant_grid], s.majorant_values, o, d,
                                  t_end);
    return majorant_walk_constant(m.majorant, t_end);
}

// ---- Ratio tracking [Novak, Selle, Jarosz 2014]: an unbiased estimate of the transmittance
// over [0, t] from o along d, the product over tentative collisions (rate mu, the piece's
// majorant) of 1 - sigma_t(x) / mu; Russian roulette once it is small ----
LANTERN_HD inline Vec3 medium_ratio_tracking(const SceneView& s, const Medium& m, int32_t med,
                                             Vec3 o, Vec3 d, float t, Rng& rng) {
    Vec3 tr = vec3(1.0f);
    MajorantWalk walk = medium_majorant_walk(s, m, o, d, t);
    MajorantSeg seg;
    if (!majorant_next(walk, &seg)) return tr;
    float x = 0.0f, tau = -1.0f;  // tau: the exponential left to spend (< 0: draw one)
    for (int k = 0; k < kMaxTrackingSteps;) {
        if (!(seg.mu > 0.0f)) {  // nothing collides here
            x = seg.t1;
            if (!majorant_next(walk, &seg)) return tr;
            continue;
        }
        if (tau < 0.0f) tau = -log1pf(-rng.uniform());
        const float xn = x + tau / seg.mu;
        if (!(xn < seg.t1)) {  // past this piece: spend its share, go on in the next
            tau = fmaxf(tau - (seg.t1 - x) * seg.mu, 0.0f);
            x = seg.t1;
            if (!majorant_next(walk, &seg)) return tr;
            continue;
        }
        tau = -1.0f;
        x = xn;
        const MediumCoeffs c = medium_coeffs_at(s, m, med, o + d * x, d);
        tr = tr * (vec3(1.0f) - (c.sigma_a + c.sigma_s) / seg.mu);
        const float a = fmaxf(fabsf(tr.x), fmaxf(fabsf(tr.y), fabsf(tr.z)));
        if (a < 0.1f) {  // roulette: survive with probability 1/2, twice the weight
            if (!(a > 0.0f) || rng.uniform() >= 0.5f) return vec3(0.0f);
            tr = tr * 2.0f;
        }
        ++k;
    }
    return vec3(0.0f);
}

// ---- Spectral tracking [Kutz, Habel, Li, Novak 2017]: the distance to a real scattering event
// over [0, t_end] from o along d, for a path of throughput beta. At each tentative collision
// (rate mu) the path scatters with probability P_s or goes on (null) with P_n, proportional to
// the mean over channels of |beta W sigma_s| and |beta W sigma_n| (W the weight so far,
// sigma_n = mu - sigma_t, mu the majorant of the piece the collision falls in); the weight takes
// sigma_s / (mu P_s) or sigma_n / (mu P_n). Absorption is in the weight (sigma_s + sigma_n =
// mu - sigma_a), not an event. on_collision(t, W, mu) is called at each tentative collision
// before its event (for the emission, whose estimate is W e / mu),
// on_interval(a, b, W) for each stretch [a, b) the path passes with weight W (lights crossed
// there). ----
struct HeteroStep {
    float t;         // where it scatters, or t_end
    bool scattered;
    Vec3 weight;     // the throughput factor W (the pass weight when not scattered)
};

template <class OnCollision, class OnInterval>
LANTERN_HD inline HeteroStep medium_track(const SceneView& s, const Medium& m, int32_t med,
                                          Vec3 o, Vec3 d, float t_end, Vec3 beta, Rng& rng,
                                          OnCollision on_collision, OnInterval on_interval) {
    HeteroStep r{t_end, false, vec3(1.0f)};
    MajorantWalk walk = medium_majorant_walk(s, m, o, d, t_end);
    MajorantSeg seg;
    if (!majorant_next(walk, &seg)) return r;
    float x = 0.0f, tau = -1.0f;  // tau: the exponential left to spend (< 0: draw one)
    for (int k = 0; k < kMaxTrackingSteps;) {
        if (!(seg.mu > 0.0f)) {  // nothing collides here: passed with the weight so far
            on_interval(x, seg.t1, r.weight);
            x = seg.t1;
            if (!majorant_next(walk, &seg)) return r;
            continue;
        }
        if (tau < 0.0f) tau = -log1pf(-rng.uniform());
        const float mu = seg.mu;
        const float xn = x + tau / mu;
        if (!(xn < seg.t1)) {  // past this piece: spend its share, go on in the next
            tau = fmaxf(tau - (seg.t1 - x) * mu, 0.0f);
            on_interval(x, seg.t1, r.weight);
            x = seg.t1;
            if (!majorant_next(walk, &seg)) return r;
            continue;
        }
        tau = -1.0f;
        on_interval(x, xn, r.weight);
        x = xn;
        on_collision(x, r.weight, mu);
        const MediumCoeffs c = medium_coeffs_at(s, m, med, o + d * x, d);
        const Vec3 sigma_n = vec3(mu) - c.sigma_a - c.sigma_s;
        const Vec3 h = beta * r.weight;
        const float ws = mean_abs(h * c.sigma_s), wn = mean_abs(h * sigma_n);
        if (!(ws + wn > 0.0f)) break;  // all absorbed (or a zero throughput): nothing goes on
        const float ps = ws / (ws + wn);
        if (rng.uniform() < ps) {
            r.weight = r.weight * c.sigma_s / (mu * ps);
            r.t = x;
            r.scattered = true;
            return r;
        }
        r.weight = r.weight * sigma_n / (mu * (1.0f - ps));
        ++k;
    }
    r.t = t_end;
    r.scattered = false;
    r.weight = vec3(0.0f);
    return r;
}

}  // namespace lantern
