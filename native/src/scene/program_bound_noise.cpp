// The Noise Texture's interval rule (scene/program_bound_rules.h): a proven bound of Perlin's
// noise, its range over a box of noise space, and the five fractal types over those ranges.
//
// The global bound. snoise (material_program_noise.h) is K_D x F(x), F Perlin's gradient noise
// in a unit cell of dimension D: F(x) = sum over the cell's 2^D corners c of W_c(x) f_c(x),
// W_c = prod_i (u(x_i) or 1 - u(x_i)) >= 0 (the nested lerps, u = fade5 in [0, 1], so
// sum_c W_c = 1), f_c = g_c . (x - c) with g_c the corner's hashed gradient: 1D +-1..8; 2D one
// component +-1 and the other +-2; 3D two of +-1 and a 0; 4D three of +-1 and a 0. For fixed
// x, the hash can pick any gradient at each corner, so |F(x)| <= G(x) = sum_c W_c(x) m(x - c),
// m(d) = max over the gradient set of |g . d| = 8 |d| (1D), max(|a| + 2 |b|, 2 |a| + |b|)
// (2D), the sum of the two (3D) or three (4D) largest |d_i|. G does not depend on the hash: a
// bound of every cell. Its supremum, by a lattice and a bound of its curvature: along axis i,
// with the corners paired by c_i (the pair shares R = prod_{j != i} >= 0, sum R = 1),
//   d2G/dx_i2 = sum_pairs R [u'' (m_1 - m_0) + 2 u' (dm_1 - dm_0)] + sum_c W_c d2m_c/dx_i2,
// the last term >= 0 (m is a maximum of linear functions: convex, its kinks bend up); m is
// kappa-Lipschitz in |d_i| (kappa 8, 2, 1, 1) and |d_i| is t or 1 - t, so |m_1 - m_0| <=
// kappa |1 - 2t| and |dm_1 - dm_0| <= 2 kappa: d2G/dx_i2 >= -kappa sup_t (|u''| |1 - 2t| +
// 4 u') = -7.5 kappa. A function with second derivative >= -M along a segment of length h lies
// below its chord plus M h^2 / 8 (f - chord - M (x - a)(b - x) / 2 is convex and 0 at the
// ends), so over a lattice of spacing h, tensor-product interpolation (convex weights) gives
// sup G <= max over the lattice + D x 7.5 kappa h^2 / 8. Lattices of 4096 (1D), 1024^2,
// 128^3, 40^4 points: sup G <= 4.0000, 1.51118, 1.03649, 1.53850, times K_D (0.25, 0.6616,
// 0.9820, 0.8344): 1.0000, 0.99980, 1.01784, 1.28372 (tests/cpp/test_program_bound_rules.cpp
// runs this proof). kSnoiseSup adds 5e-4 for float rounding in snoise. The old bound (each
// gradient product at its largest, 2, 1.985, 1.964, 2.503) was about twice these.
//
// The range over a box. F is C2 (quintic fades), with |d2F/dx_i2| <= sup_t (|u''| B + 2 u'
// Dg) from the same pairing, B >= |f_1 - f_0| (8, 5, 4, 6: |f_c| <= m(x - c), the other
// components of x - c within [-1, 1]) and Dg >= |g_1i - g_0i| (16, 4, 2, 2): 83.06, 36.59,
// 26.76, 38.19, times K_D: kSnoiseCurv. On a lattice over the box (the box's ends included)
// with spacings h_i, every value in the box is within the lattice's [min, max] widened by
// sum_i kSnoiseCurv h_i^2 / 8 (the chord argument per axis, in both directions), plus the
// float evaluation's error on both sides (kSnoiseEval). The box must not cross snoise's wrap
// (|p| < 1e5, where fmodf changes nothing).
#include <algorithm>
#include <cmath>

#include "scene/program_bound_rules.h"

namespace lantern {
namespace bound {

namespace {

constexpr float kSnoiseSup[4] = {1.0005f, 1.0003f, 1.0184f, 1.2843f};
constexpr float kSnoiseCurv[4] = {20.77f, 24.21f, 26.28f, 31.87f};
constexpr float kSnoiseEval = 5e-5f;
// lattice points per noise cell (the error then at most 0.04 in 3D) and per box at most (a
// box larger than the budget allows at that spacing takes a coarser lattice, and the global
// bound where that is no tighter). The lattice is the bound's cost: a mesh volume's majorant
// bounds its program over 16^3 boxes (issue 29's smoke: 3.5 M noise values, 20 ms of CPU)
constexpr float kPerCell = 16.0f;
constexpr int kLatticeBudget = 729;
constexpr int kCornerCache = 256;
// lattice points per Noise op per bound (its octaves and colours in order; those past it take
// the global bound): a Volume object's program is bounded per brick (a 512^3 grid: 262,144
// bricks), so one op's cost per box stays about that of issue 29's smoke (854 points)
constexpr int kNoiseBudget = 1024;

// The smallest and largest snoise over the lattice x[j][0..n_j] (j < D), |x| < 1e5 (snoise's
// fmodf changes nothing there). By rows along axis 0: within one cell, for fixed other
// coordinates, Perlin's noise is (1 - u(f)) A(f) + u(f) B(f) with A, B linear in the fraction
// f (the lerps over the other axes of the gradients' products), so a row's segment in a cell
// costs two line fits and then a few products per point. The corners' gradients (grad1..4 of
// their hashes, as vectors) are computed once per box. The same real function as snoise, its
// float rounding in another order (within kSnoiseEval).
template <int D>
void lattice_range(const float (*x)[kLatticeBudget], const int* n, float* vmin, float* vmax) {
    int cell[D][kLatticeBudget];
    float fr[D][kLatticeBudget], fu[D][kLatticeBudget];
    int c0[D], span[D], stride[D], corners = 1;
    for (int j = 0; j < D; ++j) {
        for (int k = 0; k <= n[j]; ++k) {
            cell[j][k] = floor_frac(x[j][k], &fr[j][k]);
            fu[j][k] = fade5(fr[j][k]);
        }
        c0[j] = cell[j][0];
        span[j] = cell[j][n[j]] - c0[j] + 2;
        stride[j] = corners;
        corners *= span[j];
    }
    int idx[D] = {};
    if (corners > kCornerCache) {  // a box over many cells: snoise point by point
        for (;;) {
            float p[D];
            for (int j = 0; j < D; ++j) p[j] = x[j][idx[j]];
            const float v = snoise(p, D);
            *vmin = std::min(*vmin, v);
            *vmax = std::max(*vmax, v);
            int j = 0;
            while (j < D && idx[j] == n[j]) idx[j++] = 0;
            if (j == D) break;
            ++idx[j];
        }
        return;
    }
    float grads[4 * kCornerCache];
    for (int k = 0; k < corners; ++k) {
        int v[4] = {0, 0, 0, 0}, rest = k;
        for (int j = 0; j < D; ++j) {
            v[j] = c0[j] + rest % span[j];
            rest /= span[j];
        }
        const uint32_t h = D == 1   ? hash_u1(uint32_t(v[0]))
                           : D == 2 ? hash_u2(uint32_t(v[0]), uint32_t(v[1]))
                           : D == 3 ? hash_u3(uint32_t(v[0]), uint32_t(v[1]), uint32_t(v[2]))
                                    : hash_u4(uint32_t(v[0]), uint32_t(v[1]), uint32_t(v[2]),
                                              uint32_t(v[3]));
        for (int i = 0; i < 4; ++i) {  // the gradient: grad of the unit vectors (linear in d)
            const float e[4] = {float(i == 0), float(i == 1), float(i == 2), float(i == 3)};
            grads[4 * k + i] = D == 1   ? grad1(h, e[0])
                               : D == 2 ? grad2(h, e[0], e[1])
                               : D == 3 ? grad3(h, e[0], e[1], e[2])
                                        : grad4(h, e[0], e[1], e[2], e[3]);
        }
    }
    constexpr float K[4] = {0.2500f, 0.6616f, 0.9820f, 0.8344f};
    for (;;) {  // rows: idx[1..D)
        int base = 0;
        for (int j = 1; j < D; ++j) base += (cell[j][idx[j]] - c0[j]) * stride[j];
        for (int k = 0; k <= n[0];) {
            const int X = cell[0][k];
            float slope[2] = {0.0f, 0.0f}, icpt[2] = {0.0f, 0.0f};
            for (int b0 = 0; b0 < 2; ++b0)
                for (int r = 0; r < (1 << (D - 1)); ++r) {
                    float W = 1.0f, rest = 0.0f;
                    int at = base + (X - c0[0] + b0) * stride[0];
                    for (int j = 1; j < D; ++j) {
                        const int bit = (r >> (j - 1)) & 1;
                        const float u = fu[j][idx[j]];
                        W *= bit ? u : 1.0f - u;
                        at += bit * stride[j];
                    }
                    for (int j = 1; j < D; ++j)
                        rest += grads[4 * at + j] * (fr[j][idx[j]] - float((r >> (j - 1)) & 1));
                    slope[b0] += W * grads[4 * at];
                    icpt[b0] += W * rest;
                }
            for (; k <= n[0] && cell[0][k] == X; ++k) {
                const float f = fr[0][k], u = fu[0][k];
                const float A = slope[0] * f + icpt[0], B = slope[1] * (f - 1.0f) + icpt[1];
                const float v = K[D - 1] * ((1.0f - u) * A + u * B);
                *vmin = std::min(*vmin, v);
                *vmax = std::max(*vmax, v);
            }
        }
        int j = 1;
        while (j < D && idx[j] == n[j]) idx[j++] = 0;
        if (j == D) break;
        ++idx[j];
    }
}

}  // namespace

float snoise_sup(int dim) { return kSnoiseSup[std::min(std::max(dim, 1), 4) - 1]; }

Reg snoise_range(int dim, const float* lo, const float* hi, int* budget) {
    const float S = snoise_sup(dim);
    const Reg global = make(-S, S);
    float l[4], h[4];
    for (int j = 0; j < dim; ++j) {
        if (!(std::isfinite(lo[j]) && std::isfinite(hi[j]))) return global;
        // the rounding of the point's own arithmetic (scale, distortion, offsets, octaves)
        const float m = 1e-6f * std::max(std::fabs(lo[j]), std::fabs(hi[j])) + 1e-6f;
        l[j] = std::min(lo[j], hi[j]) - m;
        h[j] = std::max(lo[j], hi[j]) + m;
        if (std::max(std::fabs(l[j]), std::fabs(h[j])) >= 99990.0f) return global;
    }
    int n[4] = {1, 1, 1, 1};
    for (float per = kPerCell;; per *= 0.75f) {
        if (per < 1.0f) return global;
        int total = 1;
        for (int j = 0; j < dim; ++j) {
            n[j] = std::max(1, int(std::ceil((h[j] - l[j]) * per)));
            total *= std::min(n[j] + 1, kLatticeBudget + 1);
            total = std::min(total, kLatticeBudget + 1);
        }
        if (total <= kLatticeBudget) break;
    }
    if (budget) {  // the noise op's share of lattice points in this bound
        int total = 1;
        for (int j = 0; j < dim; ++j) total *= n[j] + 1;
        if (total > *budget) return global;
        *budget -= total;
    }
    // the lattice's coordinates, the ends exact; the error from its largest float gap
    float x[4][kLatticeBudget];
    double err = 0.0;
    for (int j = 0; j < dim; ++j) {
        double gap = 0.0;
        for (int k = 0; k <= n[j]; ++k) {
            x[j][k] = k == n[j] ? h[j] : l[j] + (h[j] - l[j]) * (float(k) / float(n[j]));
            if (k > 0) gap = std::max(gap, double(x[j][k]) - double(x[j][k - 1]));
        }
        err += double(kSnoiseCurv[dim - 1]) * gap * gap / 8.0;
    }
    if (!(err < double(S))) return global;
    float vmin = kInfBound, vmax = -kInfBound;
    switch (dim) {
    case 1: lattice_range<1>(x, n, &vmin, &vmax); break;
    case 2: lattice_range<2>(x, n, &vmin, &vmax); break;
    case 3: lattice_range<3>(x, n, &vmin, &vmax); break;
    default: lattice_range<4>(x, n, &vmin, &vmax); break;
    }
    const float e = float(err) * 1.0001f + 2.0f * kSnoiseEval;
    return make(std::max(vmin - e, -S), std::min(vmax + e, S));
}

namespace {

// One fractal of the Noise Texture (noise_fractal) over the box [lo, hi] of noise space (dim
// coordinates; box false: any point), parameters np: the octaves' intervals from
// snoise_range at the octave's scale, combined as each type combines them (the same float
// steps for the octaves' scales and powers). Unknown where a type has no rule here.
Reg fractal_bound(int dim, bool box, const float* lo, const float* hi, const NoiseParams& np,
                  int* budget) {
    const float S = snoise_sup(dim);
    const int octaves = int(np.detail);
    const float rmd = np.detail - std::floor(np.detail);
    float scales[17];
    for (int i = 0; i <= octaves + 1; ++i)
        scales[i] = i == 0 ? 1.0f : scales[i - 1] * np.lacunarity;
    auto octave = [&](int i) {
        if (!box) return make(-S, S);
        float a[4], b[4];
        for (int j = 0; j < dim; ++j) {
            a[j] = lo[j] * scales[i];
            b[j] = hi[j] * scales[i];
        }
        return snoise_range(dim, a, b, budget);
    };
    const float r = np.roughness, off = np.offset;
    Reg v = unknown();
    switch (np.type) {
    case kNoiseFbm: {
        float amp = 1.0f, maxamp = 0.0f, amps[17];
        for (int i = 0; i <= octaves; ++i) {
            amps[i] = amp;
            maxamp += amp;
            amp *= r;
        }
        amps[octaves + 1] = amp;
        const float m2 = maxamp + amp;
        // normalised: 0.5 + sum_i n_i amp_i ((1 - rmd) / 2 maxamp + rmd / 2 (maxamp + amp))
        // (the lerp of the two normalised sums); raw: sum_i n_i amp_i + rmd amp n_(octaves+1)
        v = np.normalize ? point(0.5f) : point(0.0f);
        for (int i = 0; i <= octaves + (rmd != 0.0f ? 1 : 0); ++i) {
            float c;
            if (np.normalize)
                c = i <= octaves ? amps[i] * (0.5f * (1.0f - rmd) / maxamp + 0.5f * rmd / m2)
                                 : amps[i] * 0.5f * rmd / m2;
            else
                c = i <= octaves ? amps[i] : amps[i] * rmd;
            v = add(v, mul(point(c), octave(i)));
        }
        break;
    }
    case kNoiseMultifractal: {
        v = point(1.0f);
        float pwr = 1.0f;
        for (int i = 0; i <= octaves; ++i) {
            v = mul(v, add(mul(point(pwr), octave(i)), point(1.0f)));
            pwr *= r;
        }
        if (rmd != 0.0f) v = mul(v, add(mul(point(rmd * pwr), octave(octaves + 1)), point(1.0f)));
        break;
    }
    case kNoiseHetero: {
        // value += (n + offset) pwr value: value x (1 + (n + offset) pwr)
        v = add(point(off), octave(0));
        float pwr = r;
        for (int i = 1; i <= octaves; ++i) {
            v = mul(v, add(point(1.0f), mul(add(octave(i), point(off)), point(pwr))));
            pwr *= r;
        }
        if (rmd != 0.0f)
            v = mul(v, add(point(1.0f),
                           mul(add(octave(octaves + 1), point(off)), point(rmd * pwr))));
        break;
    }
    case kNoiseHybrid: {
        // the loop runs while weight > 0.001: every place it can stop joins the hull
        Reg value = point(0.0f), weight = point(1.0f), out = unknown();
        bool any = false;
        auto stop = [&](Reg x) {
            out = any ? hull(out, x) : x;
            any = true;
        };
        float pwr = 1.0f;
        bool running = true;
        for (int i = 0; i <= octaves && running; ++i) {
            if (!value.known || !weight.known) return unknown();
            if (weight.lo <= 0.001f) stop(value);
            if (weight.hi <= 0.001f) {
                running = false;
                break;
            }
            weight = make(std::min(std::max(weight.lo, 0.001f), 1.0f), std::min(weight.hi, 1.0f));
            const Reg signal = mul(add(octave(i), point(off)), point(pwr));
            pwr *= r;
            value = add(value, mul(weight, signal));
            weight = mul(weight, mul(point(np.gain), signal));
        }
        if (running) {
            if (!value.known || !weight.known) return unknown();
            if (rmd == 0.0f || weight.lo <= 0.001f) stop(value);
            if (rmd != 0.0f && weight.hi > 0.001f) {
                const Reg w = make(std::min(std::max(weight.lo, 0.001f), 1.0f),
                                   std::min(weight.hi, 1.0f));
                stop(add(value, mul(mul(point(rmd), w),
                                    mul(add(octave(octaves + 1), point(off)), point(pwr)))));
            }
        }
        v = out;
        break;
    }
    case kNoiseRidged: {
        Reg signal = square(sub(point(off), abs_of(octave(0))));
        v = signal;
        float pwr = r;
        for (int i = 1; i <= octaves; ++i) {
            const Reg weight = clamp01(mul(signal, point(np.gain)));
            signal = mul(square(sub(point(off), abs_of(octave(i)))), weight);
            v = add(v, mul(signal, point(pwr)));
            pwr *= r;
        }
        break;
    }
    default: return unknown();
    }
    return widen(v, 1e-5f * float(octaves + 2), 1e-6f);
}

}  // namespace

// kOpNoise: in vector(3) w scale detail roughness lacunarity offset gain distortion; out fac
// colour(3). The point p = (vector, w) x scale (1D: w alone), moved by the distortion (each
// coordinate by at most |distortion| x snoise_sup); the colour's green and blue are the same
// fractal at p plus Blender's fixed offsets. Parameters not constant: fBm keeps a bound that
// holds whatever the point and octaves (normalised: 0.5 +- 0.5 S; raw: S x the amplitudes'
// sum over detail + 1 octaves); the other types have none.
void noise_rule(const NodeInstr& n, const Reg* a, Reg* t) {
    for (int k = 0; k < 4; ++k) t[k] = unknown();
    const int dim = n.dim;
    if (dim < 1 || dim > 4) return;
    const float S = snoise_sup(dim);
    const bool fbm = n.mode == kNoiseFbm;
    bool params = constant(a[5]) && constant(a[6]) && constant(a[7]);
    if (n.mode == kNoiseMultifractal || n.mode == kNoiseHybrid || n.mode == kNoiseHetero ||
        n.mode == kNoiseRidged)
        params = params && constant(a[8]) && (constant(a[9]) || n.mode == kNoiseMultifractal ||
                                              n.mode == kNoiseHetero);
    if (!params) {
        if (!fbm) return;
        Reg f;
        if (n.flags & 1) {
            f = make(0.5f - 0.5f * S, 0.5f + 0.5f * S);
        } else {
            if (!a[5].known || !a[6].known) return;
            const int octaves = int(std::fmin(std::fmax(a[5].hi, 0.0f), 15.0f));
            const float r = std::fmax(a[6].hi, 0.0f);
            float amp = 1.0f, sum = 0.0f;
            for (int i = 0; i <= octaves + 1; ++i) {  // + 1: the fractional detail's octave
                sum += amp;
                amp *= r;
            }
            f = make(-S * sum * 1.001f, S * sum * 1.001f);
        }
        t[0] = f;
        for (int k = 1; k < 4; ++k) t[k] = (n.flags & 2) ? point(0.0f) : f;
        return;
    }
    const NoiseParams np{std::fmin(std::fmax(a[5].lo, 0.0f), 15.0f), std::fmax(a[6].lo, 0.0f),
                         a[7].lo, a[8].lo, a[9].lo, n.mode, n.flags & 1};
    // the box of noise space, when the point's inputs are known
    float lo[4] = {0, 0, 0, 0}, hi[4] = {0, 0, 0, 0};
    bool box = a[4].known && a[10].known;
    for (int j = 0; j < dim && box; ++j) {
        const int src = dim == 1 ? 3 : j;  // 1D reads w; 4D x, y, z, w
        const Reg c = mul(a[src], a[4]);
        if (!c.known) {
            box = false;
            break;
        }
        const float d = std::max(std::fabs(a[10].lo), std::fabs(a[10].hi)) * S * 1.0001f;
        lo[j] = c.lo - d;
        hi[j] = c.hi + d;
    }
    int budget = kNoiseBudget;  // the value's octaves first, then the colour's
    t[0] = fractal_bound(dim, box, lo, hi, np, &budget);
    for (int k = 1; k < 4; ++k) t[k] = point(0.0f);
    if (n.flags & 2) return;
    // green and blue: seeds dim and dim + 1 (1D: 1 and 2), offsets 100 + 100 h
    const float s1 = dim == 1 ? 1.0f : float(dim);
    for (int c = 1; c <= 2; ++c) {
        const float seed = s1 + float(c - 1);
        float ol[4], oh[4];
        for (int j = 0; j < dim; ++j) {
            const float o = dim == 1 ? noise_offset1(seed) : noise_offset(seed, float(j));
            ol[j] = lo[j] + o;
            oh[j] = hi[j] + o;
        }
        t[c + 1] = fractal_bound(dim, box, ol, oh, np, &budget);
    }
    t[1] = t[0];
}

}  // namespace bound
}  // namespace lantern
