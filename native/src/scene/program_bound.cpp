// Interval bounds of node programs over boxes (scene/program_bound.h): one interval per
// register, pushed through the instructions in order. The rules keep every value an op can
// give for inputs inside its input intervals (monotone ops at the interval's ends, products
// at the four corners, tables over the rows the input reaches); an op without a rule, or a
// register read before it is written, makes the bound fail. Procedural textures: Gradient,
// Wave, White Noise, Checker, Noise (every type), Voronoi, Magic and Brick have rules from
// their formulas (material_program_tex.h, material_program_noise.h), the Image Texture from
// its texels' range; the textures' rules in program_bound_noise.cpp, program_bound_tex.cpp
// and program_bound_image.cpp (scene/program_bound_rules.h).
#include "scene/program_bound.h"
#include "scene/program_bound_rules.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace lantern {

namespace {

using namespace bound;

// Math node operation `op` (node_math) over intervals; unknown where no rule is written.
Reg math_bound(int op, Reg a, Reg b, Reg c) {
    switch (op) {
    case 0: return add(a, b);
    case 1: return sub(a, b);
    case 2: return mul(a, b);
    case 3:  // safe_div: b's interval must not hold 0 (there safe_div jumps to 0)
        if (b.lo > 0.0f || b.hi < 0.0f) return mul(a, make(1.0f / b.lo, 1.0f / b.hi));
        return unknown();
    case 4: return add(mul(a, b), c);
    case 5:  // safe_pow with a constant exponent and a base >= 0
        if (!constant(b) || a.lo < 0.0f) return unknown();
        if (b.lo == 0.0f) return point(1.0f);
        if (b.lo > 0.0f)
            return monotone(a, [&](float x) { return powf(x, b.lo); });
        if (a.lo > 0.0f)  // decreasing in the base
            return make(powf(a.hi, b.lo), powf(a.lo, b.lo));
        return unknown();
    case 6:  // safe_log: log a / log b for a, b > 0 (b constant), else 0
        if (!a.known || !constant(b)) return unknown();
        if (a.hi <= 0.0f || !(b.lo > 0.0f) || b.lo == 1.0f) return point(0.0f);
        if (a.lo > 0.0f) return monotone(a, [&](float x) { return safe_log(x, b.lo); });
        return unknown();  // a reaches 0: log is unbounded there
    case 7: return monotone(a, [](float x) { return x > 0.0f ? sqrtf(x) : 0.0f; });
    case 8:  // 1 / sqrt a for a > 0, else 0
        if (a.known && a.hi <= 0.0f) return point(0.0f);
        if (a.lo > 0.0f) return make(1.0f / sqrtf(a.hi), 1.0f / sqrtf(a.lo));
        return unknown();
    case 9:
        if (a.lo >= 0.0f) return a;
        if (a.hi <= 0.0f) return make(-a.hi, -a.lo);
        return make(0.0f, std::max(-a.lo, a.hi));
    case 10: return monotone(a, [](float x) { return expf(x); });
    case 11: return make(std::fmin(a.lo, b.lo), std::fmin(a.hi, b.hi));
    case 12: return make(std::fmax(a.lo, b.lo), std::fmax(a.hi, b.hi));
    case 13: case 14: case 16: return make(0.0f, 1.0f);
    case 15: return monotone(a, [](float x) { return x > 0.0f ? 1.0f : x < 0.0f ? -1.0f : 0.0f; });
    case 17: case 18: {  // smooth min (max): min (max) less (plus) h^3 c / 6, h in [0, 1]
        if (!constant(c)) return unknown();
        const float d = c.lo > 0.0f ? c.lo / 6.0f : 0.0f;
        if (op == 17) return widen(make(std::fmin(a.lo, b.lo) - d, std::fmin(a.hi, b.hi)), 1e-6f);
        return widen(make(std::fmax(a.lo, b.lo), std::fmax(a.hi, b.hi) + d), 1e-6f);
    }
    case 19: return monotone(a, [](float x) { return floorf(x + 0.5f); });
    case 20: return monotone(a, [](float x) { return floorf(x); });
    case 21: return monotone(a, [](float x) { return ceilf(x); });
    case 22: return monotone(a, [](float x) { return truncf(x); });
    case 23: return make(0.0f, 1.0f);
    case 24: {  // fmodf: |result| <= |a| and < |b|, the sign of a (0 where b is 0)
        if (!a.known || !b.known) return unknown();
        const float m = std::max(std::fabs(b.lo), std::fabs(b.hi));
        return make(a.lo < 0.0f ? std::max(a.lo, -m) : 0.0f, a.hi > 0.0f ? std::min(a.hi, m) : 0.0f);
    }
    case 25: case 28: {  // floored modulo within [0, b) or (b, 0]; ping-pong within [0, |b|]
        if (!a.known || !b.known) return unknown();
        const Reg r = op == 28 ? make(0.0f, std::max(std::fabs(b.lo), std::fabs(b.hi)))
                               : make(std::fmin(b.lo, 0.0f), std::fmax(b.hi, 0.0f));
        const float m = std::max(std::fabs(a.lo), std::fabs(a.hi)) + r.hi - r.lo;
        return widen(r, 0.0f, 1e-6f * m);  // a - floor(a / b) b rounds by ulps of a
    }
    case 26: {  // wrap(a, max b, min c): within [c, b) (or (b, c]); c where b = c
        if (!a.known || !b.known || !c.known) return unknown();
        const float m = std::max(std::fabs(a.lo), std::fabs(a.hi)) +
                        std::max({std::fabs(b.lo), std::fabs(b.hi), std::fabs(c.lo), std::fabs(c.hi)});
        return widen(hull(b, c), 0.0f, 4e-6f * m);
    }
    case 27:  // snap: floor(a / b) b, non-decreasing in a for a constant b of either sign
        if (!constant(b)) return unknown();
        if (b.lo == 0.0f) return point(0.0f);
        return monotone(a, [&](float x) { return floorf(safe_div(x, b.lo)) * b.lo; });
    case 29: case 30: return make(-1.0f, 1.0f);
    case 31: {  // tangent: increasing between two poles, the interval kept off them
        if (!a.known) return unknown();
        const double h = 0.5 * double(kPi), k = std::floor((double(a.lo) + h) / double(kPi));
        const double m = 1e-5 * (1.0 + std::max(std::fabs(a.lo), std::fabs(a.hi)));
        if (!(double(a.lo) + h > k * kPi + m && double(a.hi) + h < (k + 1.0) * kPi - m))
            return unknown();
        return widen(make(tanf(a.lo), tanf(a.hi)), 1e-5f);
    }
    case 32: return monotone(a, [](float x) { return asinf(clampf(x, -1.0f, 1.0f)); });
    case 33: return make(acosf(clampf(a.hi, -1.0f, 1.0f)), acosf(clampf(a.lo, -1.0f, 1.0f)));
    case 34: return monotone(a, [](float x) { return atanf(x); });
    case 35: return a.known && b.known ? make(-kPi * 1.000001f, kPi * 1.000001f) : unknown();
    case 36: return monotone(a, [](float x) { return sinhf(x); });
    case 37: {
        if (!a.known) return unknown();
        const Reg m = abs_of(a);
        return make(coshf(m.lo), coshf(m.hi));
    }
    case 38: return monotone(a, [](float x) { return tanhf(x); });
    case 39: return mul(a, point(kPi / 180.0f));
    case 40: return mul(a, point(180.0f / kPi));
    default: return unknown();
    }
}

// The interval of an affine map's value over a box (per output component).
void affine_range(const Transform& t, Vec3 lo, Vec3 hi, Reg out[3]) {
    const Vec3 c = (lo + hi) * 0.5f, h = (hi - lo) * 0.5f;
    const Vec3 m = t.point(c);
    const float mc[3] = {m.x, m.y, m.z};
    for (int r = 0; r < 3; ++r) {
        const float e = std::fabs(t.m[r][0]) * h.x + std::fabs(t.m[r][1]) * h.y +
                        std::fabs(t.m[r][2]) * h.z;
        out[r] = make(mc[r] - e, mc[r] + e);
    }
}

// Registers op n writes (material_program.cpp op_span's output widths).
int out_width(const NodeInstr& n) {
    switch (n.op) {
    case kOpCopy: case kOpMapRange: return n.dim;
    case kOpMath: case kOpClamp: case kOpRgbToBw: case kOpFresnel: return 1;
    case kOpLayerWeight: return 2;
    case kOpInput: case kOpMix: case kOpInvert: case kOpGamma: case kOpBrightContrast:
    case kOpHsv: case kOpSeparate: case kOpCombine: case kOpCurves: case kOpMapping:
    case kOpNormalize:
        return 3;
    case kOpVoronoi: return 8;
    default: return 4;
    }
}

thread_local ProgramBoundCache* t_scope_cache = nullptr;

}  // namespace

ProgramBoundScope::ProgramBoundScope() : outer_(t_scope_cache) { t_scope_cache = &cache; }
ProgramBoundScope::~ProgramBoundScope() { t_scope_cache = outer_; }

void grid_range(const SceneView& s, const DensityGrid& g, Vec3 lo, Vec3 hi, Interval out[3]) {
    Reg q[3];
    affine_range(g.world_to_index, lo, hi, q);
    const int n[3] = {g.nx, g.ny, g.nz};
    int a0[3], a1[3];
    bool outside = false;
    for (int a = 0; a < 3; ++a) {
        if (!q[a].known) {  // a box beyond floats: every voxel, and the outside's 0
            a0[a] = 0;
            a1[a] = n[a] - 1;
            outside = true;
            continue;
        }
        // a lookup at q reads voxels floor(q) and floor(q) + 1; one more each way as margin
        const float f0 = std::floor(q[a].lo) - 1.0f, f1 = std::floor(q[a].hi) + 2.0f;
        if (!(f1 >= 0.0f && f0 <= float(n[a] - 1)) || n[a] <= 0) {
            for (int c = 0; c < 3; ++c) out[c] = Interval{0.0f, 0.0f};  // all outside: 0
            return;
        }
        outside = outside || f0 < 0.0f || f1 > float(n[a] - 1);
        a0[a] = int(std::fmax(f0, 0.0f));
        a1[a] = int(std::fmin(f1, float(n[a] - 1)));
    }
    const int ch = g.channels == 3 ? 3 : 1;
    float vmin[3] = {kInfBound, kInfBound, kInfBound}, vmax[3] = {-kInfBound, -kInfBound,
                                                                  -kInfBound};
    if (outside)
        for (int c = 0; c < 3; ++c) vmin[c] = vmax[c] = 0.0f;
    const float* vox = s.grid_voxels + g.offset;
    for (int k = a0[2]; k <= a1[2]; ++k)
        for (int j = a0[1]; j <= a1[1]; ++j)
            for (int i = a0[0]; i <= a1[0]; ++i) {
                const float* x =
                    vox + size_t(ch) * ((size_t(k) * size_t(g.ny) + size_t(j)) * size_t(g.nx) +
                                        size_t(i));
                for (int c = 0; c < ch; ++c) {
                    vmin[c] = std::fmin(vmin[c], x[c]);
                    vmax[c] = std::fmax(vmax[c], x[c]);
                }
            }
    for (int c = 0; c < 3; ++c) {
        const int cc = ch == 3 ? c : 0;
        out[c] = Interval{vmin[cc], vmax[cc]};
    }
}

bool program_bound(const SceneView& s, const MaterialProgram& p, int32_t med, Vec3 lo, Vec3 hi,
                   Interval out[3], int channels, ProgramBoundCache* cache) {
    ProgramBoundCache own;
    if (!cache) cache = t_scope_cache ? t_scope_cache : &own;
    for (int c = 0; c < 3; ++c) out[c] = Interval{-kInfBound, kInfBound};
    Reg r[kProgramRegs];
    for (Reg& x : r) x = unknown();
    const int nc = std::min(p.num_const, kProgramRegs);
    for (int i = 0; i < nc; ++i) r[i] = point(s.program_consts[p.first_const + i]);
    for (int i = 0; i < p.num_instr; ++i) {
        const NodeInstr& n = s.program_code[p.first_instr + i];
        const Reg* a = r + n.in;
        Reg* o = r + n.out;
        Reg t[8];
        for (Reg& x : t) x = unknown();
        switch (n.op) {
        case kOpCopy:
            for (int k = 0; k < n.dim && k < 4; ++k) t[k] = a[k];
            break;
        case kOpInput:
            if (n.mode == 0) {
                t[0] = make(lo.x, hi.x);
                t[1] = make(lo.y, hi.y);
                t[2] = make(lo.z, hi.z);
            } else if (n.mode == 4) {
                if (med >= 0 && s.medium_maps && n.aux >= 0 && n.aux < s.num_attribute_channels)
                    affine_range(s.medium_maps[size_t(med) * size_t(s.num_attribute_channels) +
                                               size_t(n.aux)],
                                 lo, hi, t);
                else
                    t[0] = t[1] = t[2] = point(0.0f);
            } else if (n.mode == 1 || n.mode == 2 || n.mode == 8 || n.mode == 9) {
                t[0] = t[1] = t[2] = point(0.0f);  // no normal, uv or back side in a medium
            } else if (n.mode == 3) {
                t[0] = t[1] = t[2] = make(-1.0f, 1.0f);  // the direction back along the ray
            }
            break;
        case kOpGrid: {
            Interval g[3] = {{0, 0}, {0, 0}, {0, 0}};
            if (n.aux >= 0 && n.aux < s.num_grids) grid_range(s, s.grids[n.aux], lo, hi, g);
            for (int k = 0; k < 3; ++k) t[k] = make(g[k].lo, g[k].hi);
            t[3] = make((g[0].lo + g[1].lo + g[2].lo) / 3.0f, (g[0].hi + g[1].hi + g[2].hi) / 3.0f);
            break;
        }
        case kOpMath:
            t[0] = math_bound(n.mode, a[0], a[1], a[2]);
            if (n.flags & 1) t[0] = t[0].known ? clamp01(t[0]) : make(0.0f, 1.0f);
            break;
        case kOpMapRange: {
            // monotone in the value for constant ranges (linear, stepped, smooth steps), as
            // node_map_range computes it
            bool ok = true;
            for (int k = 0; k < n.dim && ok; ++k)
                for (int j = 1; j < 6; ++j) ok = ok && constant(a[j * n.dim + k]);
            if (!ok) break;
            for (int k = 0; k < n.dim && k < 3; ++k) {
                const Reg v = a[k];
                if (!v.known) continue;
                auto f = [&](float x) {
                    return node_map_range(n.mode, n.flags & 1, x, a[n.dim + k].lo,
                                          a[2 * n.dim + k].lo, a[3 * n.dim + k].lo,
                                          a[4 * n.dim + k].lo, a[5 * n.dim + k].lo);
                };
                t[k] = make(f(v.lo), f(v.hi));
            }
            break;
        }
        case kOpClamp:
            if (n.mode == 0 && a[0].known && a[1].known && a[2].known)
                t[0] = make(node_clamp(0, a[0].lo, a[1].lo, a[2].lo),
                            node_clamp(0, a[0].hi, a[1].hi, a[2].hi));
            else if (constant(a[1]) && constant(a[2]) && a[0].known)
                t[0] = make(node_clamp(n.mode, a[0].lo, a[1].lo, a[2].lo),
                            node_clamp(n.mode, a[0].hi, a[1].lo, a[2].lo));
            break;
        case kOpRamp: {
            // the rows the clamped input reaches; linear interpolation stays between them
            const float* tab = s.program_consts + n.aux;
            const int rows = n.aux2;
            float f0 = 0.0f, f1 = 1.0f;
            if (a[0].known) {
                f0 = std::fmin(std::fmax(a[0].lo, 0.0f), 1.0f);
                f1 = std::fmin(std::fmax(a[0].hi, 0.0f), 1.0f);
            }
            const int i0 = std::max(int(f0 * float(rows - 1)), 0);
            const int i1 = std::min(int(std::ceil(f1 * float(rows - 1))) + 1, rows - 1);
            for (int c = 0; c < 4; ++c) {
                float mn = kInfBound, mx = -kInfBound;
                for (int k = i0; k <= i1; ++k) {
                    mn = std::fmin(mn, tab[4 * k + c]);
                    mx = std::fmax(mx, tab[4 * k + c]);
                }
                t[c] = make(mn, mx);
            }
            break;
        }
        case kOpMix: mix_rule(n, a, t); break;
        case kOpSeparate:
        case kOpCombine: hsx_rule(n, a, t); break;
        case kOpHsv: hsv_rule(n, a, t); break;
        case kOpCurves:
            curves_rule(n, a, t, s.program_consts + n.aux);
            if (n.mode == 1) t[1] = o[1], t[2] = o[2];  // a float curve writes out[0] alone
            break;
        case kOpRgbToBw:
            if (a[0].known && a[1].known && a[2].known)
                t[0] = make(luminance(Vec3{a[0].lo, a[1].lo, a[2].lo}),
                            luminance(Vec3{a[0].hi, a[1].hi, a[2].hi}));
            break;
        case kOpInvert:  // mix(color, 1 - color, fac)
            for (int k = 0; k < 3; ++k)
                t[k] = add(mul(a[1 + k], sub(point(1.0f), a[0])),
                           mul(sub(point(1.0f), a[1 + k]), a[0]));
            break;
        case kOpGradient: {
            // node_gradient clamps to [0, 1]; Linear (type 0) is monotone in x
            Reg f = make(0.0f, 1.0f);
            if (n.mode == 0 && a[0].known) f = clamp01(a[0]);
            for (int k = 0; k < 4; ++k) t[k] = f;
            break;
        }
        case kOpWave:  // every profile of node_wave lies in [0, 1] (0.5 + 0.5 sin, fract, tri)
        case kOpWhiteNoise:  // hash_to_unit: [0, 1]
            for (int k = 0; k < 4; ++k) t[k] = make(0.0f, 1.0f);
            break;
        case kOpChecker:  // one of the two colours; the factor 0 or 1
            for (int k = 0; k < 3; ++k)
                if (a[3 + k].known && a[6 + k].known)
                    t[k] = make(std::fmin(a[3 + k].lo, a[6 + k].lo),
                                std::fmax(a[3 + k].hi, a[6 + k].hi));
            t[3] = make(0.0f, 1.0f);
            break;
        case kOpFresnel:
        case kOpLayerWeight: {
            // fresnel_dielectric_cos of c = |dot(wo, n)| (wo a unit vector) is a reflectance
            // in [0, 1] for c in [0, 1], any eta > 0; Layer Weight's facing 1 - c^b (b >= 0)
            // too: where the normal's length is at most 1 (in a medium it is 0)
            float nn = 0.0f;
            for (int k = 1; k < 4; ++k)
                nn = a[k].known ? nn + square(a[k]).hi : kInfBound;
            if (nn <= 1.0f + 1e-5f && a[0].known)
                t[0] = t[1] = make(-1e-6f, 1.0f + 1e-6f);
            break;
        }
        case kOpNoise: noise_rule(n, a, t); break;
        case kOpVoronoi: voronoi_rule(n, a, t); break;
        case kOpMagic: magic_rule(n, a, t); break;
        case kOpBrick: brick_rule(n, a, t); break;
        case kOpVectorMath: {
            vector_math_rule(n, a, t);
            // per component as the Math node's snap, modulo, wrap, tangent, power, floored
            // modulo (node_vector_math computes them so)
            const int math_op = n.mode == 15   ? 27
                                : n.mode == 18 ? 24
                                : n.mode == 19 ? 26
                                : n.mode == 26 ? 31
                                : n.mode == 27 ? 5
                                : n.mode == 29 ? 25
                                               : -1;
            if (math_op >= 0 && !(n.flags & kInstrConstant)) {
                for (int k = 0; k < 3; ++k) t[k] = math_bound(math_op, a[k], a[3 + k], a[6 + k]);
                t[3] = point(0.0f);
            }
            break;
        }
        case kOpMapping: mapping_rule(n, a, t); break;
        case kOpImage: image_rule(s, n, a, t, *cache); break;
        case kOpNormalize:  // a unit vector or 0 (of a finite vector)
            if (a[0].known && a[1].known && a[2].known)
                for (int k = 0; k < 3; ++k) t[k] = make(-1.0000011f, 1.0000011f);
            break;
        case kOpGamma:  // a > 0: a^gamma (gamma constant); else a unchanged
            if (!constant(a[3])) break;
            for (int k = 0; k < 3; ++k) {
                const Reg x = a[k];
                const float g = a[3].lo;
                if (!x.known) continue;
                Reg v{0.0f, 0.0f, false};
                if (x.lo <= 0.0f) v = make(x.lo, std::fmin(x.hi, 0.0f));
                if (x.hi > 0.0f) {
                    const float l = std::fmax(x.lo, 0.0f);
                    Reg q = g == 0.0f ? point(1.0f)
                            : g > 0.0f ? make(powf(l, g), powf(x.hi, g))
                            : l > 0.0f ? make(powf(x.hi, g), powf(l, g))
                                       : unknown();
                    q = widen(q, 1e-6f);
                    v = v.known ? hull(v, q) : q;
                }
                t[k] = v;
            }
            break;
        case kOpBrightContrast: {  // max((1 + contrast) a + bright - contrast / 2, 0)
            const Reg ca = add(point(1.0f), a[4]), cb = sub(a[3], mul(a[4], point(0.5f)));
            for (int k = 0; k < 3; ++k) {
                const Reg v = widen(add(mul(ca, a[k]), cb), 1e-6f);
                if (v.known) t[k] = make(std::fmax(v.lo, 0.0f), std::fmax(v.hi, 0.0f));
            }
            break;
        }
        default: break;  // no rule: its outputs are unknown
        }
        // the op's outputs (unknown ones too: a later read then fails the bound)
        const int width = out_width(n);
        for (int k = 0; k < width && int(n.out) + k < kProgramRegs; ++k)
            o[k] = k < 8 ? t[k] : unknown();
    }
    if (p.result < 0 || p.result + 3 > kProgramRegs) {
        for (int c = 0; c < 3; ++c) out[c] = Interval{0.0f, 0.0f};
        return true;
    }
    bool ok = true;
    for (int c = 0; c < 3; ++c) {
        if (c >= channels) {
            out[c] = Interval{-kInfBound, kInfBound};
            continue;
        }
        const Reg v = r[p.result + c];
        if (!v.known || !std::isfinite(v.lo) || !std::isfinite(v.hi)) {
            ok = false;
            continue;
        }
        // program_run turns NaN and infinities into 0: keep 0 inside the interval then? A
        // finite interval came from finite inputs, so the value is finite: no
        const float m = 1e-5f * std::max(std::fabs(v.lo), std::fabs(v.hi)) + 1e-30f;
        out[c] = Interval{v.lo - m, v.hi + m};
    }
    if (!ok)
        for (int c = 0; c < 3; ++c) out[c] = Interval{-kInfBound, kInfBound};
    return ok;
}

std::string unbounded_density_warning(const std::string& medium) {
    return "medium '" + medium + "': its density's node graph has no bound Lantern can compute "
           "(a node without an interval rule, or an unbounded value); its majorant is the "
           "largest density on a lattice x 1.5, which may miss peaks (biased there)";
}

}  // namespace lantern
