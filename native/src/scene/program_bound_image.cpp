// The Image Texture's interval rule (scene/program_bound_rules.h; issue 29, volleft). A lookup
// (scene/texture.h texture_lookup) reads one texel (Closest) or blends four with weights >= 0
// summing to 1 (Linear; Cubic and Smart render as Linear, the add-on warns), in the values it
// filters in (an 8-bit sRGB texture's encoded bytes / 255, decoded after the blend: the decode
// is increasing, so the decoded ends bound it); Clip reads transparent black (0 in all four
// channels) outside the image, as does a coordinate that is not finite. So every value lies
// within the smallest and largest texel the coordinates' box can reach (the texel index range
// of its uv interval, widened against float rounding, folded by the extension mode), with 0
// where Clip can leave the image. Box projection blends up to three sides with weights >= 0
// summing to 1: the hull of the three sides' ranges. A missing image reads magenta.
// The texel ranges per block of texels are scanned once per texture per cache
// (ProgramBoundCache, program_bound.h), so a bound over a small uv box reads few blocks.
#include "scene/program_bound.h"
#include "scene/program_bound_rules.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "scene/material_program_tex.h"
#include "scene/texture.h"

namespace lantern {
namespace bound {

namespace {

constexpr int kMaxBlocks = 256;  // blocks per axis at most (a block a power of two of texels)

// A texel's four channels in the space the lookup blends in (8-bit: byte / 255).
void filter_texel(const Texture& t, const uint8_t* pool, size_t idx, float v[4]) {
    if (t.format == kTexRgba32F) {
        const float* p = reinterpret_cast<const float*>(pool + t.offset) + 4 * idx;
        for (int c = 0; c < 4; ++c) v[c] = p[c];
        return;
    }
    const uint8_t* p = pool + t.offset + 4 * idx;
    for (int c = 0; c < 4; ++c) v[c] = float(p[c]) * (1.0f / 255.0f);
}

const TexelBlocks& blocks_of(const SceneView& s, int k, ProgramBoundCache& cache) {
    if (cache.textures.size() < size_t(s.num_textures))
        cache.textures.resize(size_t(s.num_textures));
    TexelBlocks& b = cache.textures[size_t(k)];
    if (b.block > 0) return b;
    const Texture& t = s.textures[k];
    int B = 1;
    while ((t.width + B - 1) / B > kMaxBlocks || (t.height + B - 1) / B > kMaxBlocks) B *= 2;
    b.block = B;
    b.bw = (t.width + B - 1) / B;
    b.bh = (t.height + B - 1) / B;
    b.lo.assign(size_t(b.bw) * size_t(b.bh) * 4, kInfBound);
    b.hi.assign(b.lo.size(), -kInfBound);
    b.finite = true;
    for (int c = 0; c < 4; ++c) b.all_lo[c] = kInfBound, b.all_hi[c] = -kInfBound;
    for (int y = 0; y < t.height; ++y)
        for (int x = 0; x < t.width; ++x) {
            float v[4];
            filter_texel(t, s.texels, size_t(y) * size_t(t.width) + size_t(x), v);
            float* lo = &b.lo[(size_t(y / B) * size_t(b.bw) + size_t(x / B)) * 4];
            float* hi = &b.hi[(size_t(y / B) * size_t(b.bw) + size_t(x / B)) * 4];
            for (int c = 0; c < 4; ++c) {
                b.finite = b.finite && std::isfinite(v[c]);
                lo[c] = std::fmin(lo[c], v[c]);
                hi[c] = std::fmax(hi[c], v[c]);
                b.all_lo[c] = std::fmin(b.all_lo[c], v[c]);
                b.all_hi[c] = std::fmax(b.all_hi[c], v[c]);
            }
        }
    return b;
}

// The texels along one axis (size n) that lookups at coordinates in [lo, hi] (uv, before the
// size) can read: up to four index ranges, `outside` where Clip can read past the image.
struct Span {
    int count = 0;
    int64_t r[4][2];
    bool all = false, outside = false;
};

Span texel_span(int wrap, bool linear, double lo, double hi, double m, int n) {
    Span s;
    // texture_lookup folds a coordinate past 1e6 (periodic modes) or clamps it (the others)
    // before it reads; a coordinate that is not finite reads transparent black
    if (!(std::isfinite(lo) && std::isfinite(hi)) || std::fabs(lo) > 1e6 || std::fabs(hi) > 1e6) {
        s.all = true;
        s.outside = true;
        return s;
    }
    // m: the float rounding of u (its affine map's terms) and of u x size, in u
    const double shift = linear ? 0.5 : 0.0;
    const int64_t i0 = int64_t(std::floor((lo - m) * n - shift));
    const int64_t i1 = int64_t(std::floor((hi + m) * n - shift)) + (linear ? 1 : 0);
    const int64_t len = i1 - i0 + 1;
    auto add = [&s](int64_t a, int64_t b) {
        if (a <= b && s.count < 4) s.r[s.count][0] = a, s.r[s.count][1] = b, ++s.count;
    };
    auto mod = [](int64_t a, int64_t p) { return ((a % p) + p) % p; };
    switch (wrap) {
    case kWrapExtend:
        add(std::clamp<int64_t>(i0, 0, n - 1), std::clamp<int64_t>(i1, 0, n - 1));
        break;
    case kWrapClip:
        s.outside = i0 < 0 || i1 > n - 1;
        add(std::max<int64_t>(i0, 0), std::min<int64_t>(i1, n - 1));
        break;
    case kWrapMirror: {
        if (len >= 2 * n) {
            s.all = true;
            break;
        }
        const int64_t k0 = mod(i0, 2 * n), k1 = k0 + len - 1;  // k1 < 4n
        for (int q = 0; q < 4; ++q) {  // quarter-periods: forward, mirrored, forward, mirrored
            const int64_t a = std::max(k0, q * int64_t(n)),
                          b = std::min(k1, (q + 1) * int64_t(n) - 1);
            if (a > b) continue;
            const int64_t base = (q / 2) * 2 * int64_t(n);
            if (q % 2 == 0)
                add(a - base, b - base);
            else
                add(2 * n - 1 - (b - base), 2 * n - 1 - (a - base));
        }
        break;
    }
    default: {  // repeat
        if (len >= n) {
            s.all = true;
            break;
        }
        const int64_t k0 = mod(i0, n), k1 = k0 + len - 1;
        add(k0, std::min<int64_t>(k1, n - 1));
        if (k1 >= n) add(0, k1 - n);
        break;
    }
    }
    return s;
}

// The blocks along one axis that a span reaches (a mask of nb blocks of B texels).
void block_mask(const Span& s, int B, int nb, std::vector<uint8_t>& mask) {
    mask.assign(size_t(nb), s.all ? 1 : 0);
    if (s.all) return;
    for (int k = 0; k < s.count; ++k)
        for (int64_t b = s.r[k][0] / B; b <= s.r[k][1] / B && b < nb; ++b) mask[size_t(b)] = 1;
}

// The range of one lookup of texture k at uv in [u] x [v] (filter space; each channel), the
// flag `zero` set where it can read transparent black.
void lookup_range(const SceneView& s, int k, ProgramBoundCache& cache, Reg u, Reg v, float lo[4],
                  float hi[4], bool* zero) {
    const Texture& t = s.textures[k];
    const TexelBlocks& b = blocks_of(s, k, cache);
    // the texture's own uv transform (u' = uv0 u + uv1 v + uv2, ...), in double
    // and a margin against its float rounding (1e-6 of its terms' size: float's is 6e-8 per
    // operation)
    double ul = 0, uh = 0, vl = 0, vh = 0, um = 0, vm = 0;
    const bool known = u.known && v.known;
    if (known) {
        auto affine = [&](double a, double bb, double c, double* l, double* h, double* mg) {
            const double cu = 0.5 * (double(u.lo) + u.hi), hu = 0.5 * (double(u.hi) - u.lo);
            const double cv = 0.5 * (double(v.lo) + v.hi), hv = 0.5 * (double(v.hi) - v.lo);
            const double m = a * cu + bb * cv + c, e = std::fabs(a) * hu + std::fabs(bb) * hv;
            *l = m - e;
            *h = m + e;
            const double su = std::max(std::fabs(double(u.lo)), std::fabs(double(u.hi)));
            const double sv = std::max(std::fabs(double(v.lo)), std::fabs(double(v.hi)));
            *mg = 1e-6 * (1.0 + std::fabs(a) * su + std::fabs(bb) * sv + std::fabs(c));
        };
        affine(t.uv[0], t.uv[1], t.uv[2], &ul, &uh, &um);
        affine(t.uv[3], t.uv[4], t.uv[5], &vl, &vh, &vm);
    }
    const bool linear = t.interp != kInterpClosest;
    Span sx, sy;
    if (known) {
        sx = texel_span(t.wrap, linear, ul, uh, um, t.width);
        sy = texel_span(t.wrap, linear, vl, vh, vm, t.height);
    } else {
        sx.all = sy.all = sx.outside = true;  // any coordinate, a NaN too
    }
    *zero = *zero || sx.outside || sy.outside;
    if (sx.all && sy.all) {
        for (int c = 0; c < 4; ++c)
            lo[c] = std::fmin(lo[c], b.all_lo[c]), hi[c] = std::fmax(hi[c], b.all_hi[c]);
        return;
    }
    std::vector<uint8_t> mx, my;
    block_mask(sx, b.block, b.bw, mx);
    block_mask(sy, b.block, b.bh, my);
    for (int y = 0; y < b.bh; ++y) {
        if (!my[size_t(y)]) continue;
        for (int x = 0; x < b.bw; ++x) {
            if (!mx[size_t(x)]) continue;
            const size_t i = (size_t(y) * size_t(b.bw) + size_t(x)) * 4;
            for (int c = 0; c < 4; ++c)
                lo[c] = std::fmin(lo[c], b.lo[i + size_t(c)]),
                hi[c] = std::fmax(hi[c], b.hi[i + size_t(c)]);
        }
    }
}

// One coordinate's interval through f (non-decreasing), widened against rounding.
template <class F>
Reg through(Reg a, F f) {
    if (!a.known) return a;
    return widen(make(f(a.lo), f(a.hi)), 1e-6f, 1e-6f);
}

}  // namespace

void image_rule(const SceneView& s, const NodeInstr& n, const Reg* a, Reg* t,
                ProgramBoundCache& cache) {
    if (!(n.aux >= 0 && n.aux < s.num_textures)) {  // a missing image: magenta
        t[0] = point(1.0f), t[1] = point(0.0f), t[2] = point(1.0f), t[3] = point(1.0f);
        return;
    }
    const Texture& tex = s.textures[n.aux];
    if (!blocks_of(s, n.aux, cache).finite) return;  // no rule (texels are finite at load)
    float lo[4] = {kInfBound, kInfBound, kInfBound, kInfBound};
    float hi[4] = {-kInfBound, -kInfBound, -kInfBound, -kInfBound};
    bool zero = false;
    if (n.mode == 1) {
        // box: side X reads (y or 1 - y, z), Y (x or 1 - x, z), Z (y or 1 - y, x), the side's
        // mirroring from the normal's sign: both kept
        auto either = [](Reg c) { return c.known ? hull(c, sub(point(1.0f), c)) : c; };
        const Reg x = either(a[0]), y = either(a[1]);
        const Reg sides[3][2] = {{y, a[2]}, {x, a[2]}, {y, a[0]}};
        for (const auto& sd : sides) lookup_range(s, n.aux, cache, sd[0], sd[1], lo, hi, &zero);
        // the weights are finite for a finite normal and blend; else none is > 0: 0
        for (int k = 3; k < 7; ++k) zero = zero || !a[k].known;
    } else {
        Reg u = a[0], v = a[1];
        if (n.mode == 2 || n.mode == 3) {
            u = make(0.0f, 1.0f);  // (1 - atan2 / pi) / 2
            if (n.mode == 2) {
                v = make(0.0f, 1.0f);  // 1 - acos / pi
            } else {                   // (d.z + 1) / 2; a point on the tube's axis reads uv (0, 0)
                v = through(a[2], [](float z) { return ((z - 0.5f) * 2.0f + 1.0f) * 0.5f; });
                if (v.known) v = hull(v, point(0.0f));
            }
        }
        lookup_range(s, n.aux, cache, u, v, lo, hi, &zero);
    }
    for (int c = 0; c < 4; ++c) {
        if (zero) lo[c] = std::fmin(lo[c], 0.0f), hi[c] = std::fmax(hi[c], 0.0f);
        if (tex.format == kTexRgba8Srgb && c < 3)
            lo[c] = srgb_decode(lo[c]), hi[c] = srgb_decode(hi[c]);
        // the blend's weights sum to 1 within float rounding, the lookups' too
        t[c] = widen(make(lo[c], hi[c]), 4e-6f, 1e-7f);
    }
}

}  // namespace bound
}  // namespace lantern
