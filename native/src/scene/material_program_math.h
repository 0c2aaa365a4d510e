// The arithmetic of Blender's utility nodes as host+device code: Math and Vector Math (every
// operation, with Blender's "safe" conventions: x / 0 = 0, log and sqrt of invalid inputs = 0),
// colour blending (the Mix node's blend modes), HSV conversion, Map Range and Clamp. The
// operation numbers are the order of the lists in addon/export/material_compile.py.
#pragma once

#include "core/math.h"

namespace lantern {

LANTERN_HD inline float safe_div(float a, float b) { return b != 0.0f ? a / b : 0.0f; }
LANTERN_HD inline float safe_fmod(float a, float b) { return b != 0.0f ? fmodf(a, b) : 0.0f; }
LANTERN_HD inline float floored_mod(float a, float b) {
    return b != 0.0f ? a - floorf(a / b) * b : 0.0f;
}
// Cycles at render time (bpy 5.0.1, measured on every Math and Vector Math op over zero,
// negative, integer and fractional operands; difftest D35): a negative base to a fractional
// power is 0, and so is 0 to a negative power (powf's +inf). Its constant folding on the host
// keeps +inf there: folded_pow, for an instruction marked kInstrConstant.
LANTERN_HD inline float safe_pow(float a, float b) {
    if (a < 0.0f && b != floorf(b)) return 0.0f;
    if (a == 0.0f && b < 0.0f) return 0.0f;
    return powf(a, b);
}
// a Power Cycles folds (constant inputs): 0 to a negative exponent stays powf's +inf there
LANTERN_HD inline float folded_pow(float a, float b, float v) {
    return (a == 0.0f && b < 0.0f) ? powf(a, b) : v;
}
// log base 1 divides by log(1) = 0: 0 in Cycles (its safe division), folded or not
LANTERN_HD inline float safe_log(float a, float b) {
    return (a > 0.0f && b > 0.0f) ? safe_div(logf(a), logf(b)) : 0.0f;
}
LANTERN_HD inline float wrapf(float v, float hi, float lo) {
    const float range = hi - lo;
    return range != 0.0f ? v - range * floorf((v - lo) / range) : lo;
}
LANTERN_HD inline float pingpongf(float a, float b) {
    if (b == 0.0f) return 0.0f;
    const float f = (a - b) / (b * 2.0f);
    return fabsf((f - floorf(f)) * b * 2.0f - b);
}
LANTERN_HD inline float smoothminf(float a, float b, float c) {
    if (c != 0.0f) {
        const float h = fmaxf(c - fabsf(a - b), 0.0f) / c;
        return fminf(a, b) - h * h * h * c * (1.0f / 6.0f);
    }
    return fminf(a, b);
}
LANTERN_HD inline float signf(float a) { return a > 0.0f ? 1.0f : (a < 0.0f ? -1.0f : 0.0f); }

// Math node: Blender's operation list (material_compile.MATH_OPS)
LANTERN_HD inline float node_math(int op, float a, float b, float c) {
    switch (op) {
    case 0: return a + b;
    case 1: return a - b;
    case 2: return a * b;
    case 3: return safe_div(a, b);
    case 4: return a * b + c;
    case 5: return safe_pow(a, b);
    case 6: return safe_log(a, b);
    case 7: return a > 0.0f ? sqrtf(a) : 0.0f;
    case 8: return a > 0.0f ? 1.0f / sqrtf(a) : 0.0f;
    case 9: return fabsf(a);
    case 10: return expf(a);
    case 11: return fminf(a, b);
    case 12: return fmaxf(a, b);
    case 13: return a < b ? 1.0f : 0.0f;
    case 14: return a > b ? 1.0f : 0.0f;
    case 15: return signf(a);
    case 16: return fabsf(a - b) <= fmaxf(c, 1e-5f) ? 1.0f : 0.0f;
    case 17: return smoothminf(a, b, c);
    case 18: return -smoothminf(-a, -b, c);
    case 19: return floorf(a + 0.5f);
    case 20: return floorf(a);
    case 21: return ceilf(a);
    case 22: return truncf(a);
    case 23: return a - floorf(a);
    case 24: return safe_fmod(a, b);
    case 25: return floored_mod(a, b);
    case 26: return wrapf(a, b, c);
    case 27: return floorf(safe_div(a, b)) * b;
    case 28: return pingpongf(a, b);
    case 29: return sinf(a);
    case 30: return cosf(a);
    case 31: return tanf(a);
    case 32: return asinf(clampf(a, -1.0f, 1.0f));
    case 33: return acosf(clampf(a, -1.0f, 1.0f));
    case 34: return atanf(a);
    case 35: return atan2f(a, b);
    case 36: return sinhf(a);
    case 37: return coshf(a);
    case 38: return tanhf(a);
    case 39: return a * (kPi / 180.0f);
    case 40: return a * (180.0f / kPi);
    default: return 0.0f;
    }
}

LANTERN_HD inline Vec3 safe_normalize(Vec3 a) {
    const float l = length(a);
    return l > 0.0f ? a * (1.0f / l) : Vec3{};
}
LANTERN_HD inline Vec3 vmap2(Vec3 a, Vec3 b, float (*f)(float, float)) {
    return Vec3{f(a.x, b.x), f(a.y, b.y), f(a.z, b.z)};
}
LANTERN_HD inline float fadd(float a, float b) { return a + b; }
LANTERN_HD inline float fminw(float a, float b) { return fminf(a, b); }
LANTERN_HD inline float fmaxw(float a, float b) { return fmaxf(a, b); }

// Vector Math node (material_compile.VECTOR_OPS): the vector result, and *value for the
// operations whose output is a value (dot, distance, length)
LANTERN_HD inline Vec3 node_vector_math(int op, Vec3 a, Vec3 b, Vec3 c, float s, float* value) {
    *value = 0.0f;
    switch (op) {
    case 0: return a + b;
    case 1: return a - b;
    case 2: return a * b;
    case 3: return Vec3{safe_div(a.x, b.x), safe_div(a.y, b.y), safe_div(a.z, b.z)};
    case 4: return a * b + c;
    case 5: return cross(a, b);
    case 6: {
        const float bb = dot(b, b);
        return bb != 0.0f ? b * (dot(a, b) / bb) : Vec3{};
    }
    case 7: {
        const Vec3 n = safe_normalize(b);
        return a - n * (2.0f * dot(n, a));
    }
    case 8: {  // refract(a, normalize(b), eta = scale)
        const Vec3 n = safe_normalize(b);
        const float d = dot(n, a), k = 1.0f - s * s * (1.0f - d * d);
        return k < 0.0f ? Vec3{} : a * s - n * (s * d + sqrtf(k));
    }
    case 9: return dot(c, b) < 0.0f ? a : -a;
    case 10: *value = dot(a, b); return Vec3{};
    case 11: *value = length(a - b); return Vec3{};
    case 12: *value = length(a); return Vec3{};
    case 13: return a * s;
    case 14: return safe_normalize(a);
    case 15: return Vec3{floorf(safe_div(a.x, b.x)) * b.x, floorf(safe_div(a.y, b.y)) * b.y,
                         floorf(safe_div(a.z, b.z)) * b.z};
    case 16: return Vec3{floorf(a.x), floorf(a.y), floorf(a.z)};
    case 17: return Vec3{ceilf(a.x), ceilf(a.y), ceilf(a.z)};
    case 18: return Vec3{safe_fmod(a.x, b.x), safe_fmod(a.y, b.y), safe_fmod(a.z, b.z)};
    case 19: return Vec3{wrapf(a.x, b.x, c.x), wrapf(a.y, b.y, c.y), wrapf(a.z, b.z, c.z)};
    case 20: return Vec3{a.x - floorf(a.x), a.y - floorf(a.y), a.z - floorf(a.z)};
    case 21: return Vec3{fabsf(a.x), fabsf(a.y), fabsf(a.z)};
    case 22: return vmap2(a, b, fminw);
    case 23: return vmap2(a, b, fmaxw);
    case 24: return Vec3{sinf(a.x), sinf(a.y), sinf(a.z)};
    case 25: return Vec3{cosf(a.x), cosf(a.y), cosf(a.z)};
    case 26: return Vec3{tanf(a.x), tanf(a.y), tanf(a.z)};
    case 27: return Vec3{safe_pow(a.x, b.x), safe_pow(a.y, b.y), safe_pow(a.z, b.z)};
    case 28: return Vec3{signf(a.x), signf(a.y), signf(a.z)};
    case 29: return Vec3{floored_mod(a.x, b.x), floored_mod(a.y, b.y), floored_mod(a.z, b.z)};
    default: return Vec3{};
    }
}

// ---- HSV (hue in [0, 1)) ----
LANTERN_HD inline Vec3 rgb_to_hsv(Vec3 rgb) {
    const float cmax = fmaxf(rgb.x, fmaxf(rgb.y, rgb.z));
    const float cmin = fminf(rgb.x, fminf(rgb.y, rgb.z));
    const float cdelta = cmax - cmin;
    const float v = cmax;
    float h = 0.0f, s = 0.0f;
    if (cmax != 0.0f) s = cdelta / cmax;
    if (s != 0.0f) {
        const Vec3 c = Vec3{cmax - rgb.x, cmax - rgb.y, cmax - rgb.z} / cdelta;
        if (rgb.x == cmax) h = c.z - c.y;
        else if (rgb.y == cmax) h = 2.0f + c.x - c.z;
        else h = 4.0f + c.y - c.x;
        h /= 6.0f;
        if (h < 0.0f) h += 1.0f;
    }
    return Vec3{h, s, v};
}
LANTERN_HD inline Vec3 hsv_to_rgb(Vec3 hsv) {
    float h = hsv.x;
    const float s = hsv.y, v = hsv.z;
    if (s == 0.0f) return Vec3{v, v, v};
    if (h == 1.0f) h = 0.0f;
    h *= 6.0f;
    const float i = floorf(h), f = h - i;
    const float p = v * (1.0f - s), q = v * (1.0f - s * f), t = v * (1.0f - s * (1.0f - f));
    switch (int(i)) {
    case 0: return Vec3{v, t, p};
    case 1: return Vec3{q, v, p};
    case 2: return Vec3{p, v, t};
    case 3: return Vec3{p, q, v};
    case 4: return Vec3{t, p, v};
    default: return Vec3{v, p, q};
    }
}
LANTERN_HD inline Vec3 rgb_to_hsl(Vec3 c) {
    const float cmax = fmaxf(c.x, fmaxf(c.y, c.z)), cmin = fminf(c.x, fminf(c.y, c.z));
    const float l = fminf(1.0f, (cmax + cmin) * 0.5f);
    if (cmax == cmin) return Vec3{0.0f, 0.0f, l};
    const float d = cmax - cmin;
    const float s = l > 0.5f ? d / (2.0f - cmax - cmin) : d / (cmax + cmin);
    float h;
    if (cmax == c.x) h = (c.y - c.z) / d + (c.y < c.z ? 6.0f : 0.0f);
    else if (cmax == c.y) h = (c.z - c.x) / d + 2.0f;
    else h = (c.x - c.y) / d + 4.0f;
    return Vec3{h / 6.0f, s, l};
}
LANTERN_HD inline Vec3 hsl_to_rgb(Vec3 hsl) {
    const float h = hsl.x, s = hsl.y, l = hsl.z;
    const float nr = fabsf(h * 6.0f - 3.0f) - 1.0f;
    const float ng = 2.0f - fabsf(h * 6.0f - 2.0f);
    const float nb = 2.0f - fabsf(h * 6.0f - 4.0f);
    const float chroma = (1.0f - fabsf(2.0f * l - 1.0f)) * s;
    return Vec3{(clampf(nr, 0, 1) - 0.5f) * chroma + l, (clampf(ng, 0, 1) - 0.5f) * chroma + l,
                (clampf(nb, 0, 1) - 0.5f) * chroma + l};
}

// ---- Mix node, colour: Blender's blend modes (material_compile.BLEND_MODES), factor t ----
LANTERN_HD inline Vec3 mix3(Vec3 a, Vec3 b, float t) { return a * (1.0f - t) + b * t; }
LANTERN_HD inline float dodge1(float a, float b, float t) {
    if (a == 0.0f) return a;
    const float tmp = 1.0f - t * b;
    if (tmp <= 0.0f) return 1.0f;
    return fminf(a / tmp, 1.0f);
}
LANTERN_HD inline float burn1(float a, float b, float t) {
    float tmp = (1.0f - t) + t * b;
    if (tmp <= 0.0f) return 0.0f;
    tmp = 1.0f - (1.0f - a) / tmp;
    return clampf(tmp, 0.0f, 1.0f);
}
LANTERN_HD inline float overlay1(float a, float b, float t) {
    const float tm = 1.0f - t;
    return a < 0.5f ? a * (tm + 2.0f * t * b) : 1.0f - (tm + 2.0f * t * (1.0f - b)) * (1.0f - a);
}
LANTERN_HD inline Vec3 node_blend(int mode, float t, Vec3 a, Vec3 b) {
    const float tm = 1.0f - t;
    switch (mode) {
    case 0: return mix3(a, b, t);
    case 1: return mix3(a, vmap2(a, b, fminw), t);                        // darken
    case 2: return a * (vec3(tm) + b * t);                                // multiply
    case 3: return Vec3{burn1(a.x, b.x, t), burn1(a.y, b.y, t), burn1(a.z, b.z, t)};
    case 4: return mix3(a, vmap2(a, b, fmaxw), t);                        // lighten
    case 5: return vec3(1.0f) - (vec3(tm) + (vec3(1.0f) - b) * t) * (vec3(1.0f) - a);  // screen
    case 6: return Vec3{dodge1(a.x, b.x, t), dodge1(a.y, b.y, t), dodge1(a.z, b.z, t)};
    case 7: return a + b * t;                                             // add
    case 8: return Vec3{overlay1(a.x, b.x, t), overlay1(a.y, b.y, t), overlay1(a.z, b.z, t)};
    case 9: return a - b * t;                                             // subtract
    case 10: return Vec3{b.x != 0.0f ? tm * a.x + t * a.x / b.x : a.x,
                         b.y != 0.0f ? tm * a.y + t * a.y / b.y : a.y,
                         b.z != 0.0f ? tm * a.z + t * a.z / b.z : a.z};  // divide
    case 11: return mix3(a, Vec3{fabsf(a.x - b.x), fabsf(a.y - b.y), fabsf(a.z - b.z)}, t);
    case 12: {                                                            // exclusion
        Vec3 e = mix3(a, a + b - a * b * 2.0f, t);
        return Vec3{fmaxf(e.x, 0.0f), fmaxf(e.y, 0.0f), fmaxf(e.z, 0.0f)};
    }
    case 13: {                                                            // soft light
        const Vec3 scr = vec3(1.0f) - (vec3(1.0f) - b) * (vec3(1.0f) - a);
        return a * tm + ((vec3(1.0f) - a) * b * a + a * scr) * t;
    }
    case 14: return a + (b * 2.0f - vec3(1.0f)) * t;                      // linear light
    case 15: case 16: case 17: case 18: {                                 // hue, sat, value, colour
        const Vec3 h2 = rgb_to_hsv(b);
        Vec3 h1 = rgb_to_hsv(a);
        if (mode == 15 || mode == 18) {
            if (h2.y == 0.0f) return a;
            h1.x = h2.x;
            if (mode == 18) h1.y = h2.y;
            return mix3(a, hsv_to_rgb(h1), t);
        }
        if (mode == 16) {
            if (h1.y == 0.0f) return a;
            h1.y = tm * h1.y + t * h2.y;
            return hsv_to_rgb(h1);
        }
        h1.z = tm * h1.z + t * h2.z;
        return hsv_to_rgb(h1);
    }
    default: return a;
    }
}

// ---- Map Range (material_compile.MAP_RANGE_MODES): linear, stepped, smoothstep, smootherstep ----
LANTERN_HD inline float smoothstepf(float e0, float e1, float x) {
    if (x < e0) return 0.0f;
    if (x >= e1) return 1.0f;
    const float t = (x - e0) / (e1 - e0);
    return t * t * (3.0f - 2.0f * t);
}
LANTERN_HD inline float smootherstepf(float e0, float e1, float x) {
    const float t = clampf(safe_div(x - e0, e1 - e0), 0.0f, 1.0f);
    return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f);
}
LANTERN_HD inline float node_map_range(int mode, bool clamp, float v, float fmin, float fmax,
                                       float tmin, float tmax, float steps) {
    float f;
    switch (mode) {
    case 1: {
        f = safe_div(v - fmin, fmax - fmin);
        f = steps > 0.0f ? floorf(f * (steps + 1.0f)) / steps : 0.0f;
        break;
    }
    case 2:
        f = fmin > fmax ? 1.0f - smoothstepf(fmax, fmin, v) : smoothstepf(fmin, fmax, v);
        break;
    case 3:
        f = fmin > fmax ? 1.0f - smootherstepf(fmax, fmin, v) : smootherstepf(fmin, fmax, v);
        break;
    default:
        f = safe_div(v - fmin, fmax - fmin);
        break;
    }
    float r = tmin + f * (tmax - tmin);
    if (clamp && mode <= 1) r = tmax > tmin ? clampf(r, tmin, tmax) : clampf(r, tmax, tmin);
    return r;
}

// Clamp node: mode 0 min-max, 1 range (min and max in either order)
LANTERN_HD inline float node_clamp(int mode, float v, float lo, float hi) {
    if (mode == 1 && lo > hi) return clampf(v, hi, lo);
    return fminf(fmaxf(v, lo), hi);
}

}  // namespace lantern
