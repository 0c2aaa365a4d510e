// Interval rules of Voronoi, Magic, Brick, Vector Math, Mapping, Mix's blend modes, Curves,
// Hue/Saturation/Value and Separate / Combine HSV / HSL (scene/program_bound_rules.h),
// each from its formula in material_program_tex.h / _math.h / _ops.h: every value the op gives
// for inputs in its input intervals lies in the rule's output interval.
#include <algorithm>
#include <cmath>

#include "scene/program_bound_rules.h"

namespace lantern {
namespace bound {

namespace {

// A Voronoi distance over per-axis offsets of at most e[0..D) (D 1: |a - b|, whatever the
// metric), as voronoi_distance computes it (increasing in each offset); unknown for a
// Minkowski exponent that is not a positive constant.
Reg voronoi_reach(int D, const float* e, int metric, Reg exponent) {
    if (D == 1) return make(0.0f, e[0]);
    double acc = 0.0;
    for (int i = 0; i < D; ++i) {
        switch (metric) {
        case 1: acc += e[i]; break;
        case 2: acc = std::max(acc, double(e[i])); break;
        case 3:
            if (!constant(exponent) || !(exponent.lo > 0.0f)) return unknown();
            acc += std::pow(double(e[i]), double(exponent.lo));
            break;
        default: acc += double(e[i]) * e[i]; break;
        }
    }
    if (metric == 3) acc = std::pow(acc, 1.0 / double(exponent.lo));
    if (metric == 0) acc = std::sqrt(acc);
    return widen(make(0.0f, float(acc)), 1e-4f, 1e-6f);
}

}  // namespace

// kOpVoronoi: in vector(3) w scale smoothness exponent randomness; mode feature (0 F1, 1 F2,
// 2 smooth F1), aux metric; out distance colour(3) position(3) w. A cell's feature point lies
// in the cell (randomness is clamped to [0, 1]) and the point's local coordinates in [0, 1)^D:
// F1 <= the own cell's reach (1 per axis); F2 <= the larger of the own cell's and the
// neighbour's along axis 0 on the nearer side (1.5 on that axis); smooth F1 blends cells
// within 2 (3 per axis) with lerps (within the distances seen) less corr = s h (1 - h) >= 0,
// which by induction stays >= -s (s the clamped smoothness, > 0 required: at 0 the blend
// divides by 0). Colours are hashes in [0, 1] (smooth: lerps less s h (1 - h) / (1 + 3 s), so
// >= -s / (1 + 3 s)); positions within the cells searched: floor(p) - 1 .. floor(p) + 2
// (smooth: - 2 - s / (1 + 3 s) .. + 3), divided by the scale (a constant).
void voronoi_rule(const NodeInstr& n, const Reg* a, Reg* t) {
    for (int k = 0; k < 8; ++k) t[k] = unknown();
    const int feature = n.mode, metric = n.aux;
    const int D = (n.dim == 1 || n.dim == 2 || n.dim == 4) ? n.dim : 3;
    if (feature < 0 || feature > 2) return;
    float s = 0.0f;  // the smoothness's largest value, clamped as the op does
    if (feature == 2) {
        if (!a[5].known) return;
        const float slo = std::min(std::max(a[5].lo * 0.5f, 0.0f), 0.5f);
        if (!(slo > 0.0f)) return;
        s = std::min(std::max(a[5].hi * 0.5f, 0.0f), 0.5f);
    }
    // the point's coordinates finite (an infinite one has no cell)
    for (int j = 0; j < D; ++j)
        if (!mul(a[D == 1 ? 3 : j], a[4]).known) return;
    const float reach[4] = {feature == 2 ? 3.0f : feature == 1 ? 1.5f : 1.0f,
                            feature == 2 ? 3.0f : 1.0f, feature == 2 ? 3.0f : 1.0f,
                            feature == 2 ? 3.0f : 1.0f};
    const Reg dist = voronoi_reach(D, reach, metric, a[6]);
    t[0] = feature == 2 && dist.known ? make(-s, dist.hi) : dist;
    const float cs = s / (1.0f + 3.0f * s);
    for (int k = 1; k <= 3; ++k) t[k] = widen(make(-cs, 1.0f), 1e-6f, 1e-7f);
    // positions: the cells of the scaled point's box
    for (int k = 4; k < 8; ++k) t[k] = point(0.0f);
    if (!constant(a[4])) {
        for (int k = 4; k < 8; ++k) t[k] = unknown();
        return;
    }
    const float sc = a[4].lo;
    if (sc == 0.0f) return;  // safe_div: 0
    const int axes[4] = {D == 1 ? 3 : 0, 1, 2, 3};
    for (int j = 0; j < D; ++j) {
        const int c = axes[j];
        const Reg p = mul(a[c], a[4]);
        if (!p.known) {
            t[4 + c] = unknown();
            continue;
        }
        const float lo = std::floor(p.lo) - (feature == 2 ? 2.0f + cs : 1.0f);
        const float hi = std::floor(p.hi) + (feature == 2 ? 3.0f : 2.0f);
        t[4 + c] = widen(mul(make(lo, hi), point(1.0f / sc)), 1e-5f, 1e-6f);
    }
}

// kOpMagic: in vector(3) scale distortion; aux depth; out colour(3) fac. With depth > 0 every
// one of node_magic's x, y, z is a sine or cosine times d when it is last written, so |x| <= |d|
// and 0.5 - x / 2d lies in [0, 1] (d = 0: all 0, the colour 0.5). Depth 0: 0.5 - sin / 2d,
// within 0.5 +- 1 / 2 min |d| (d = 0: the sines undivided, [-0.5, 1.5]).
void magic_rule(const NodeInstr& n, const Reg* a, Reg* t) {
    for (int k = 0; k < 4; ++k) t[k] = unknown();
    // the sines' arguments finite (an infinite one gives NaN), and the distortion's sums
    Reg sum = point(0.0f);
    for (int k = 0; k < 3; ++k) {
        const Reg p = mul(a[k], a[3]);
        if (!p.known) return;
        sum = add(sum, abs_of(p));
    }
    if (!mul(sum, point(5.0f)).known || !a[4].known ||
        !(std::max(std::fabs(a[4].lo), std::fabs(a[4].hi)) < 1e37f))
        return;
    Reg c;
    if (n.aux > 0) {
        c = make(0.0f, 1.0f);
    } else if (a[4].lo == 0.0f && a[4].hi == 0.0f) {
        c = make(-0.5f, 1.5f);
    } else if (a[4].lo > 0.0f || a[4].hi < 0.0f) {
        const float dmin = std::min(std::fabs(a[4].lo), std::fabs(a[4].hi));
        c = make(0.5f - 0.5f / dmin, 0.5f + 0.5f / dmin);
    } else {
        return;  // a distortion that may be 0 or near it: unbounded
    }
    c = widen(c, 1e-6f, 1e-7f);
    for (int k = 0; k < 4; ++k) t[k] = c;
}

// kOpBrick: in vector(3) colour1(3) colour2(3) mortar(3) ...; out colour(3) fac. node_brick's
// factor and tint are in [0, 1] whatever its inputs (clamped, or 0 / 1 where they are not
// finite), and the colour is a convex combination of the three colours.
void brick_rule(const NodeInstr&, const Reg* a, Reg* t) {
    for (int k = 0; k < 3; ++k)
        t[k] = widen(hull(hull(a[3 + k], a[6 + k]), a[9 + k]), 1e-6f, 1e-30f);
    t[3] = make(0.0f, 1.0f);
}

// kOpVectorMath: in a(3) b(3) c(3) scale; out vector(3) value. Per component where the
// operation is per component; cross, dot, distance and length from products and sums.
// Project, reflect, refract, snap, modulo, wrap, tangent, power and floored modulo have none.
void vector_math_rule(const NodeInstr& n, const Reg* a, Reg* t) {
    for (int k = 0; k < 4; ++k) t[k] = unknown();
    const Reg* A = a;
    const Reg* B = a + 3;
    const Reg* C = a + 6;
    const Reg zero = point(0.0f);
    auto each = [&](auto f) {
        for (int k = 0; k < 3; ++k) t[k] = f(k);
        t[3] = zero;
    };
    switch (n.mode) {
    case 0: each([&](int k) { return add(A[k], B[k]); }); break;
    case 1: each([&](int k) { return sub(A[k], B[k]); }); break;
    case 2: each([&](int k) { return mul(A[k], B[k]); }); break;
    case 3:
        each([&](int k) {
            if (B[k].known && B[k].lo == 0.0f && B[k].hi == 0.0f) return zero;
            if (B[k].lo > 0.0f || B[k].hi < 0.0f)
                return mul(A[k], make(1.0f / B[k].lo, 1.0f / B[k].hi));
            return unknown();
        });
        break;
    case 4: each([&](int k) { return add(mul(A[k], B[k]), C[k]); }); break;
    case 5:
        each([&](int k) {
            const int i = (k + 1) % 3, j = (k + 2) % 3;
            return sub(mul(A[i], B[j]), mul(A[j], B[i]));
        });
        break;
    case 9: each([&](int k) { return hull(A[k], make(-A[k].hi, -A[k].lo)); }); break;
    case 6:    // project: |b (a.b) / (b.b)| <= |a| per component (0 where b = 0)
    case 7:    // reflect about normalize(b) (0: a): |a| per component
    case 8: {  // refract: |s a - n (s d + sqrt k)| <= 2 |s| |a| + sqrt(max(1, 1 + s^2 (|a|^2 - 1)))
        Reg len2 = zero;
        for (int k = 0; k < 3; ++k) len2 = A[k].known ? add(len2, square(A[k])) : unknown();
        if (!len2.known) return;
        float m = std::sqrt(len2.hi);
        if (n.mode == 8) {
            if (!a[9].known) return;
            const float sm = std::max(std::fabs(a[9].lo), std::fabs(a[9].hi));
            m = 2.0f * sm * m + std::sqrt(std::max(1.0f, 1.0f + sm * sm * (len2.hi - 1.0f)));
        }
        m = m * (1.0f + 1e-5f) + 1e-7f;
        each([&](int) { return make(-m, m); });
        if (n.mode == 6 && B[0].known && B[1].known && B[2].known && constant(B[0]) &&
            constant(B[1]) && constant(B[2])) {
            // a constant b: linear in a, b (b . a) / (b . b) by interval arithmetic too
            const float bb = B[0].lo * B[0].lo + B[1].lo * B[1].lo + B[2].lo * B[2].lo;
            if (!(bb > 0.0f)) {
                each([&](int) { return zero; });
                break;
            }
            Reg d = zero;
            for (int k = 0; k < 3; ++k) d = add(d, mul(A[k], B[k]));
            for (int k = 0; k < 3; ++k) {
                const Reg q = widen(mul(d, point(B[k].lo / bb)), 1e-5f, 1e-7f);
                if (q.known) t[k] = make(std::max(q.lo, t[k].lo), std::min(q.hi, t[k].hi));
            }
        }
        break;
    }
    case 10:
    case 11:
    case 12: {
        Reg v = zero;
        for (int k = 0; k < 3; ++k)
            v = add(v, n.mode == 10   ? mul(A[k], B[k])
                       : n.mode == 11 ? square(sub(A[k], B[k]))
                                      : square(A[k]));
        if (n.mode != 10 && v.known) v = make(std::sqrt(v.lo), std::sqrt(v.hi));
        for (int k = 0; k < 3; ++k) t[k] = zero;
        t[3] = v;
        break;
    }
    case 13: each([&](int k) { return mul(A[k], a[9]); }); break;
    case 14: case 20: case 24: case 25:  // unit vector or 0, fraction, sine, cosine
        if (!A[0].known || !A[1].known || !A[2].known) return;  // of finite values
        each([&](int) { return n.mode == 20 ? make(0.0f, 1.0f) : make(-1.0f, 1.0f); });
        break;
    case 16: each([&](int k) { return monotone(A[k], [](float x) { return floorf(x); }); }); break;
    case 17: each([&](int k) { return monotone(A[k], [](float x) { return ceilf(x); }); }); break;
    case 21: each([&](int k) { return A[k].known ? abs_of(A[k]) : unknown(); }); break;
    case 22:
        each([&](int k) {
            return make(std::fmin(A[k].lo, B[k].lo), std::fmin(A[k].hi, B[k].hi));
        });
        break;
    case 23:
        each([&](int k) {
            return make(std::fmax(A[k].lo, B[k].lo), std::fmax(A[k].hi, B[k].hi));
        });
        break;
    case 28:
        each([&](int k) {
            return monotone(A[k], [](float x) { return x > 0.0f ? 1.0f : x < 0.0f ? -1.0f : 0.0f; });
        });
        break;
    default: return;
    }
    // float rounding in the op's own sums and products
    for (int k = 0; k < 4; ++k) t[k] = widen(t[k], 2e-6f, 1e-30f);
}

// kOpMapping: in vector(3) location(3) rotation(3) scale(3); mode type (0 point, 1 texture, 2
// vector, 3 normal). With constant location, rotation and scale the first three are affine
// maps of the vector, M v + b (node_mapping's formulas in double); a normal is a unit vector.
void mapping_rule(const NodeInstr& n, const Reg* a, Reg* t) {
    for (int k = 0; k < 3; ++k) t[k] = unknown();
    if (n.mode == 3) {
        if (a[0].known && a[1].known && a[2].known)
            for (int k = 0; k < 3; ++k) t[k] = make(-1.0000011f, 1.0000011f);
        return;
    }
    for (int k = 3; k < 12; ++k)
        if (!constant(a[k])) return;
    for (int k = 0; k < 3; ++k)
        if (!a[k].known) return;
    const double cx = std::cos(double(a[6].lo)), sx = std::sin(double(a[6].lo));
    const double cy = std::cos(double(a[7].lo)), sy = std::sin(double(a[7].lo));
    const double cz = std::cos(double(a[8].lo)), sz = std::sin(double(a[8].lo));
    const double R[3][3] = {{cy * cz, sy * sx * cz - cx * sz, sy * cx * cz + sx * sz},
                            {cy * sz, sy * sx * sz + cx * cz, sy * cx * sz - sx * cz},
                            {-sy, cy * sx, cy * cx}};
    const double loc[3] = {a[3].lo, a[4].lo, a[5].lo}, sc[3] = {a[9].lo, a[10].lo, a[11].lo};
    double M[3][3], b[3], extra[3];
    for (int r = 0; r < 3; ++r) {
        const double inv = sc[r] != 0.0 ? 1.0 / sc[r] : 0.0;
        b[r] = n.mode == 0 ? loc[r] : 0.0;
        extra[r] = 0.0;
        for (int j = 0; j < 3; ++j) {
            M[r][j] = n.mode == 1 ? inv * R[j][r] : R[r][j] * sc[j];
            if (n.mode == 1) {
                b[r] -= M[r][j] * loc[j];
                extra[r] += std::fabs(M[r][j] * loc[j]);
            }
        }
    }
    for (int r = 0; r < 3; ++r) {
        double lo = b[r], hi = b[r], mag = std::fabs(b[r]) + extra[r];
        for (int j = 0; j < 3; ++j) {
            const double u = M[r][j] * a[j].lo, v = M[r][j] * a[j].hi;
            lo += std::min(u, v);
            hi += std::max(u, v);
            mag += std::max(std::fabs(u), std::fabs(v));
        }
        const double m = 1e-5 * mag + 1e-30;  // float rounding in node_mapping
        t[r] = make(float(lo - m), float(hi + m));
        if (t[r].known) t[r] = make(std::nextafter(t[r].lo, -kInfBound),
                                    std::nextafter(t[r].hi, kInfBound));
    }
}

namespace {

// One channel of node_blend(mode, f, a, b) over intervals (f the factor as the op passes it);
// unknown for Divide and the HSV modes (hue, saturation, value, colour).
Reg blend_channel(int mode, Reg f, Reg a, Reg b) {
    const Reg one = point(1.0f), two = point(2.0f), tm = sub(one, f);
    auto lerp = [&](Reg x, Reg y) { return add(mul(x, tm), mul(y, f)); };
    switch (mode) {
    case 1: return lerp(a, make(std::fmin(a.lo, b.lo), std::fmin(a.hi, b.hi)));  // darken
    case 2: return mul(a, add(tm, mul(b, f)));                                   // multiply
    case 3: return make(0.0f, 1.0f);                                             // burn
    case 4: return lerp(a, make(std::fmax(a.lo, b.lo), std::fmax(a.hi, b.hi)));  // lighten
    case 5: return sub(one, mul(add(tm, mul(sub(one, b), f)), sub(one, a)));     // screen
    case 6: return a.known && a.lo >= 0.0f ? make(0.0f, 1.0f) : unknown();      // dodge
    case 7: return add(a, mul(b, f));                                            // add
    case 8: {  // overlay: each branch over the whole of a, where a can take it
        Reg r{0.0f, 0.0f, false};
        bool any = false;
        if (a.lo < 0.5f) {
            r = mul(a, add(tm, mul(mul(two, f), b)));
            any = true;
        }
        if (a.hi >= 0.5f) {
            const Reg q = sub(one, mul(add(tm, mul(mul(two, f), sub(one, b))), sub(one, a)));
            r = any ? hull(r, q) : q;
        }
        return r;
    }
    case 9: return sub(a, mul(b, f));                                            // subtract
    case 11: return a.known && b.known ? lerp(a, abs_of(sub(a, b))) : unknown();  // difference
    case 12: {                                                                   // exclusion
        const Reg e = lerp(a, sub(add(a, b), mul(mul(a, b), two)));
        return e.known ? make(std::fmax(e.lo, 0.0f), std::fmax(e.hi, 0.0f)) : e;
    }
    case 13: {                                                                   // soft light
        const Reg scr = sub(one, mul(sub(one, b), sub(one, a)));
        return add(mul(a, tm), mul(add(mul(mul(sub(one, a), b), a), mul(a, scr)), f));
    }
    case 14: return add(a, mul(sub(mul(b, two), one), f));                       // linear light
    case 10:                                                                     // divide
        if (constant(b) && b.lo == 0.0f) return a;   // b = 0: a unchanged
        if (!(b.lo > 0.0f || b.hi < 0.0f)) return unknown();
        return lerp(a, mul(a, make(1.0f / b.lo, 1.0f / b.hi)));
    default: return unknown();
    }
}

// a piecewise linear curve's range over x: its ends' values and the knots between them
Reg curve_range(const float* tab, int n, int ch, float lo, float hi, Reg x) {
    if (!x.known || n < 2) return unknown();
    const float range = hi - lo;
    if (range == 0.0f) return point(tab[ch]);
    const float f1 = (x.lo - lo) / range, f2 = (x.hi - lo) / range;
    if (!(std::isfinite(f1) && std::isfinite(f2))) return unknown();
    Reg r = make(curve_lookup(tab, n, ch, lo, hi, x.lo), curve_lookup(tab, n, ch, lo, hi, x.hi));
    const float fa = std::min(f1, f2) - 1e-6f, fb = std::max(f1, f2) + 1e-6f;
    for (int k = 0; k < n && r.known; ++k) {
        const float fk = float(k) / float(n - 1);
        if (fk >= fa && fk <= fb) r = hull(r, point(tab[4 * k + ch]));
    }
    return widen(r, 1e-5f, 1e-6f);
}

// Mix's hue, saturation, value and colour blends (node_blend, modes 15-18): hsv_to_rgb(h, s, v)
// has every component between v and v (1 - s) (v (1 - s f) for f in [0, 1]), whatever h; the
// value v the largest component, the saturation in [0, 1] for components >= 0 (a's; b's where
// its saturation is read). Hue and colour mix the result with a by the factor, saturation and
// value take it as it is (or a where a has no saturation).
void hsv_blend_rule(const NodeInstr& n, const Reg* a, Reg* t) {
    for (int k = 0; k < 9; ++k)
        if (!a[k].known) return;
    const Reg* A = a + 3;
    const Reg* B = a + 6;
    auto vmax = [](const Reg* c) {
        return make(std::max({c[0].lo, c[1].lo, c[2].lo}), std::max({c[0].hi, c[1].hi, c[2].hi}));
    };
    auto nonneg = [](const Reg* c) { return c[0].lo >= 0.0f && c[1].lo >= 0.0f && c[2].lo >= 0.0f; };
    if (!nonneg(A) || ((n.mode == 16 || n.mode == 18) && !nonneg(B))) return;
    const Reg one = point(1.0f), unit = make(0.0f, 1.0f);
    Reg f = a[0];
    if (n.flags & 1) f = clamp01(f);
    const Reg tm = sub(one, f);
    Reg v = vmax(A), sat = unit;
    if (n.mode == 16) sat = add(mul(tm, unit), mul(f, unit));   // mix of two saturations
    if (n.mode == 17) v = add(mul(tm, v), mul(f, vmax(B)));      // mix of two values
    const Reg x = hull(v, mul(v, sub(one, sat)));
    for (int k = 0; k < 3; ++k) {
        Reg r = n.mode == 15 || n.mode == 18 ? add(mul(A[k], tm), mul(x, f)) : x;
        r = hull(r, A[k]);   // a itself where the saturation read is 0
        r = widen(r, 4e-6f, 1e-7f);
        if (n.flags & 2) r = r.known ? clamp01(r) : make(0.0f, 1.0f);
        t[k] = r;
    }
}

}  // namespace

// kOpMix: a lerp per component (Mix mode, the float and vector mixes: as before), else
// node_blend's formula per channel by interval arithmetic (blend_channel), the factor and the
// result clamped as the op clamps them.
void mix_rule(const NodeInstr& n, const Reg* a, Reg* t) {
    const bool lerp = n.mode == 255 || n.mode == 0 || (n.flags & 4);
    if (!lerp && n.mode >= 15 && n.mode <= 18) {
        hsv_blend_rule(n, a, t);
        return;
    }
    for (int k = 0; k < 3; ++k) {
        Reg f = (n.flags & 4) ? a[k] : a[0];
        if (n.flags & 1) f = f.known ? clamp01(f) : make(0.0f, 1.0f);
        t[k] = lerp ? add(mul(a[3 + k], sub(point(1.0f), f)), mul(a[6 + k], f))
                    : widen(blend_channel(n.mode, f, a[3 + k], a[6 + k]), 4e-6f, 1e-7f);
        if (n.flags & 2) t[k] = t[k].known ? clamp01(t[k]) : make(0.0f, 1.0f);
    }
}

// kOpCurves: in fac colour(3) (mode 1: fac value); the table's curve over each input's
// interval (curve_range), mixed with the input by the factor. Mode 1 writes out[0] alone
// (the caller keeps the other two registers' intervals).
void curves_rule(const NodeInstr& n, const Reg* a, Reg* t, const float* tab) {
    const int rows = n.aux2;
    const float lo = tab[4 * rows], hi = tab[4 * rows + 1];
    const Reg fac = a[0], tm = sub(point(1.0f), a[0]);
    if (n.mode == 1) {
        t[0] = widen(add(mul(a[1], tm), mul(curve_range(tab, rows, 0, lo, hi, a[1]), fac)), 2e-6f);
        return;
    }
    for (int k = 0; k < 3; ++k)
        t[k] = widen(add(mul(a[1 + k], tm), mul(curve_range(tab, rows, k, lo, hi, a[1 + k]), fac)),
                     2e-6f);
}

// kOpHsv: in hue sat val fac colour(3). hsv_to_rgb of a saturation clamped to [0, 1] gives
// components between v (1 - s) and v: within hull(0, v x val), v the colour's largest
// component; mixed with the colour by the factor, then >= 0.
void hsv_rule(const NodeInstr&, const Reg* a, Reg* t) {
    for (int k = 0; k < 7; ++k)
        if (!a[k].known) return;
    const Reg cmax = make(std::max({a[4].lo, a[5].lo, a[6].lo}), std::max({a[4].hi, a[5].hi, a[6].hi}));
    const Reg x = hull(point(0.0f), mul(cmax, a[2]));
    for (int k = 0; k < 3; ++k) {
        const Reg v = widen(add(mul(a[4 + k], sub(point(1.0f), a[3])), mul(x, a[3])), 4e-6f, 1e-7f);
        if (v.known) t[k] = make(std::fmax(v.lo, 0.0f), std::fmax(v.hi, 0.0f));
    }
}

// kOpSeparate / kOpCombine in HSV (mode 1) and HSL (mode 2); mode 0 is the identity.
// Separate: hue in [0, 1]; HSV's value the largest component, its saturation in [0, 1] for
// components >= 0; HSL's lightness min(1, (max + min) / 2), its saturation in [0, 1] for
// components in [0, 1]. Combine: HSV's components between v and v (1 - s); HSL's l +- chroma / 2,
// chroma (1 - |2 l - 1|) s.
void hsx_rule(const NodeInstr& n, const Reg* a, Reg* t) {
    if (n.mode == 0) {
        for (int k = 0; k < 3; ++k) t[k] = a[k];
        return;
    }
    if (n.mode != 1 && n.mode != 2) return;
    for (int k = 0; k < 3; ++k)
        if (!a[k].known) return;
    const Reg one = point(1.0f);
    if (n.op == kOpSeparate) {
        const Reg cmax = make(std::max({a[0].lo, a[1].lo, a[2].lo}), std::max({a[0].hi, a[1].hi, a[2].hi}));
        const Reg cmin = make(std::min({a[0].lo, a[1].lo, a[2].lo}), std::min({a[0].hi, a[1].hi, a[2].hi}));
        t[0] = make(0.0f, 1.0f);
        if (n.mode == 1) {
            if (cmin.lo >= 0.0f) t[1] = make(0.0f, 1.0f);
            t[2] = cmax;
        } else {
            if (cmin.lo >= 0.0f && cmax.hi <= 1.0f) t[1] = widen(make(0.0f, 1.0f), 1e-6f);
            const Reg l = widen(mul(add(cmax, cmin), point(0.5f)), 1e-6f);
            t[2] = make(std::fmin(l.lo, 1.0f), std::fmin(l.hi, 1.0f));
        }
        return;
    }
    if (n.mode == 1) {
        const Reg x = widen(mul(a[2], hull(one, sub(one, a[1]))), 4e-6f, 1e-7f);
        for (int k = 0; k < 3; ++k) t[k] = x;
    } else {
        const Reg chroma = mul(sub(one, abs_of(sub(mul(a[2], point(2.0f)), one))), a[1]);
        const Reg x = widen(add(mul(make(-0.5f, 0.5f), chroma), a[2]), 4e-6f, 1e-7f);
        for (int k = 0; k < 3; ++k) t[k] = x;
    }
}

}  // namespace bound
}  // namespace lantern
