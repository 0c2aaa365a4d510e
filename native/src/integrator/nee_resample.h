// Resampled next-event estimation (issue 14 item 3, in the spirit of CIS): M candidate light
// samples (tree picks, each with its light sample), the target p-hat = luminance of the
// unshadowed contribution, one chosen with probability proportional to w_j = p-hat(x_j) /
// p_src(x_j), one shadow ray. The chosen sample y carries W = (1 / p-hat(y)) (1/M) sum_j w_j
// (DESIGN.md, resampled connections); the MIS weights stay those of the plain strategy (pick
// pmf times the light's pdf), never the random W. (Soft-falloff disks are
// sampled by solid angle, lights.h, as pt_light_pdf_w's pdf assumes.)
#pragma once

#include "core/rng.h"
#include "scene/light_tree.h"
#include "scene/lights.h"

namespace lantern {

constexpr int kMaxLightCandidates = 8;  // PtSettings::light_candidates at most

// The random numbers one resampled estimate draws beyond the plain one (u_pick, u_light):
// 3 (M - 1) for the candidates past the first, always, so that the count per bounce is fixed.
LANTERN_HD inline int nee_resample_extra_draws(int m) { return m > 1 ? 3 * (m - 1) : 0; }

// Moves stream r past n numbers, as n uniform() draws would: Rng's draws are a function of
// their dimension, so it skips them (Pcg32, bench/qmc_noise.py's -DLANTERN_RNG_PCG, draws).
LANTERN_HD inline void nee_resample_skip(Rng& r, int n) {
#ifndef LANTERN_RNG_PCG
    r.dim += uint32_t(n);
#else
    for (int k = 0; k < n; ++k) r.next();
#endif
}

// Candidates j = 0 .. m-1 at p (pick normal n_pick): candidate 0 takes u0 (the pick, then the
// point on the light), candidate j > 0 the three numbers of `rest` (the caller's stream at its
// first draw past the plain estimate's) from dimension 3 (j - 1) on, in the same order;
// `target` maps a light sample to p-hat (zero where the contribution is zero, positive where
// it is not). Sets *pick and *ls to the chosen candidate and returns W p_src(y) = (1/M) sum_j
// w_j / w_y, the factor that turns the plain estimate f Le cos / p_src(y) into the resampled
// one; 0 when no candidate has weight (then *pick has pmf 0). Only the weights are kept and
// the numbers are drawn where they are used: the chosen candidate is drawn again from its
// numbers (the same pick and sample), so that a GPU thread holds no M light samples and no
// 3 M numbers. The caller's stream moves past nee_resample_extra_draws(m) numbers itself.
// Always inlined on the device, with pt_shade's target (LANTERN_DEVICE_INLINE on its lambda):
// then the values the target reads (the surface, its frame, the material pointer) and the
// chosen pick and sample stay in registers; an outlined call kept them in the shade kernel's
// local memory, on its deepest call chain (docs/cuda_backend.md "Kernel resources"). The
// host inlines as it chooses.
#ifdef __CUDA_ARCH__
#define LANTERN_DEVICE_INLINE __attribute__((always_inline))
#else
#define LANTERN_DEVICE_INLINE
#endif
template <class Target>
LANTERN_DEVICE_INLINE LANTERN_HD inline float nee_resample(const SceneView& s, Vec3 p,
                                                           Vec3 n_pick, int m, Vec3 u0, Rng rest,
                                                           float u_choose, Target target,
                                                           LightPick* pick, LightSample* ls,
                                                           float time) {
    float w[kMaxLightCandidates];
    float sum = 0.0f;
    m = m < kMaxLightCandidates ? m : kMaxLightCandidates;
    Rng r = rest;
    for (int j = 0; j < m; ++j) {
        w[j] = 0.0f;
        const Vec3 u = j == 0 ? u0 : Vec3{r.uniform(), r.uniform(), r.uniform()};
        const LightPick cp = light_pick(s, p, n_pick, u.x);
        if (!(cp.pmf > 0.0f)) continue;
        const LightSample cs = sample_light(s, s.lights[cp.light], p, Vec2{u.y, u.z}, time);
        if (!cs.valid) continue;
        const float src = cp.pmf * cs.pdf_w;  // a delta light's pdf_w is 1: its pmf
        const float ph = target(cs);
        if (src > 0.0f && ph > 0.0f) w[j] = ph / src;
        if (!(w[j] < 1e37f)) w[j] = 0.0f;  // overflow or NaN: never chosen, never summed
        sum += w[j];
    }
    pick->light = -1;
    pick->pmf = 0.0f;
    if (!(sum > 0.0f) || !(sum < 1e38f)) return 0.0f;
    float x = u_choose * sum;
    int c = -1;
    for (int j = 0; j < m; ++j) {
        if (!(w[j] > 0.0f)) continue;
        c = j;  // the last candidate with weight takes what rounding leaves
        if (x < w[j]) break;
        x -= w[j];
    }
    Vec3 u = u0;
    if (c > 0) {  // its numbers again: the stream's draws are a function of their dimension
        r = rest;
        nee_resample_skip(r, 3 * (c - 1));
        u = Vec3{r.uniform(), r.uniform(), r.uniform()};
    }
    *pick = light_pick(s, p, n_pick, u.x);
    *ls = sample_light(s, s.lights[pick->light], p, Vec2{u.y, u.z}, time);
    return sum / (float(m) * w[c]);
}

}  // namespace lantern
