// The interval arithmetic of scene/program_bound.cpp and its rule table's parts in other files
// (host only, internal to the bound): Reg, one register's interval, and the rules of the
// procedural textures (program_bound_noise.cpp: the Noise Texture, every type;
// program_bound_tex.cpp: Voronoi, Magic, Brick, Vector Math, Mapping, Mix, Curves, HSV,
// Separate / Combine; program_bound_image.cpp: the Image Texture).
// A rule writes the intervals of its op's outputs (t[0..8)); an output it leaves unknown fails
// the bound where it is read.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "scene/material_program.h"
#include "scene/program_bound.h"

namespace lantern {
namespace bound {

constexpr float kInfBound = std::numeric_limits<float>::infinity();

struct Reg {
    float lo, hi;
    bool known;
};

inline Reg point(float v) { return Reg{v, v, true}; }
inline Reg unknown() { return Reg{-kInfBound, kInfBound, false}; }
inline Reg make(float a, float b) {
    if (!(std::isfinite(a) && std::isfinite(b))) return unknown();
    return Reg{std::min(a, b), std::max(a, b), true};
}
inline Reg add(Reg a, Reg b) { return make(a.lo + b.lo, a.hi + b.hi); }
inline Reg sub(Reg a, Reg b) { return make(a.lo - b.hi, a.hi - b.lo); }
inline Reg mul(Reg a, Reg b) {
    const float c[4] = {a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi};
    for (float v : c)
        if (!std::isfinite(v)) return unknown();
    return Reg{*std::min_element(c, c + 4), *std::max_element(c, c + 4), true};
}
// the smallest interval holding both
inline Reg hull(Reg a, Reg b) {
    if (!a.known || !b.known) return unknown();
    return Reg{std::min(a.lo, b.lo), std::max(a.hi, b.hi), true};
}
// a function non-decreasing in its argument
template <class F>
Reg monotone(Reg a, F f) {
    return make(f(a.lo), f(a.hi));
}
inline Reg clamp_to(Reg a, float lo, float hi) {
    return Reg{std::fmin(std::fmax(a.lo, lo), hi), std::fmin(std::fmax(a.hi, lo), hi), true};
}
inline Reg clamp01(Reg a) { return clamp_to(a, 0.0f, 1.0f); }
inline bool constant(Reg a) { return a.known && a.lo == a.hi; }
inline Reg abs_of(Reg a) {
    if (a.lo >= 0.0f) return a;
    if (a.hi <= 0.0f) return make(-a.hi, -a.lo);
    return make(0.0f, std::max(-a.lo, a.hi));
}
inline Reg square(Reg a) {
    const Reg m = abs_of(a);
    return make(m.lo * m.lo, m.hi * m.hi);
}
// a relative and absolute widening against float rounding in the op's own arithmetic
inline Reg widen(Reg a, float rel, float abs_margin = 0.0f) {
    if (!a.known) return a;
    const float m = rel * std::max(std::fabs(a.lo), std::fabs(a.hi)) + abs_margin;
    return make(a.lo - m, a.hi + m);
}

// Perlin's noise of dimension dim (snoise, material_program_noise.h), Blender's output scale
// included: a proven bound of |snoise| (program_bound_noise.cpp).
float snoise_sup(int dim);
// The interval of snoise(., dim) over the box [lo, hi] of noise space (dim coordinates): the
// values on a lattice of the box widened by a proven bound of the interpolation's error, or
// [-snoise_sup, snoise_sup] where the box is too large for the lattice or the lattice would
// take more than *budget points (budget: the points left, decreased by those used; null: no
// limit) (program_bound_noise.cpp).
Reg snoise_range(int dim, const float* lo, const float* hi, int* budget = nullptr);

// The rules (t: the op's outputs; a: its inputs; both by register, as NodeOp lays them out).
void noise_rule(const NodeInstr& n, const Reg* a, Reg* t);
void voronoi_rule(const NodeInstr& n, const Reg* a, Reg* t);
void magic_rule(const NodeInstr& n, const Reg* a, Reg* t);
void brick_rule(const NodeInstr& n, const Reg* a, Reg* t);
void vector_math_rule(const NodeInstr& n, const Reg* a, Reg* t);
void mapping_rule(const NodeInstr& n, const Reg* a, Reg* t);
void mix_rule(const NodeInstr& n, const Reg* a, Reg* t);
void curves_rule(const NodeInstr& n, const Reg* a, Reg* t, const float* table);
void hsv_rule(const NodeInstr& n, const Reg* a, Reg* t);
void hsx_rule(const NodeInstr& n, const Reg* a, Reg* t);  // Separate / Combine
// the Image Texture (program_bound_image.cpp): its texels' range over the coordinates' box
void image_rule(const SceneView& s, const NodeInstr& n, const Reg* a, Reg* t,
                ProgramBoundCache& cache);

}  // namespace bound
}  // namespace lantern
