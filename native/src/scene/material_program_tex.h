// Blender's procedural texture nodes and the view-dependent utility nodes as host+device code:
// Checker, Gradient, Magic, Wave, Voronoi (F1, F2, smooth F1; four metrics; 1D-4D), White
// Noise, ColorRamp and curve tables, Fresnel, Layer Weight, and the image projections. Formulas
// from the manual's definitions and the published algorithms (Worley 1996 for Voronoi).
#pragma once

#include "scene/material_program_math.h"
#include "scene/material_program_noise.h"

namespace lantern {

LANTERN_HD inline float node_checker(Vec3 p) {
    // nudged off the cell borders, as Blender does, so that integer planes pick one side
    const int xi = abs(int(floorf((p.x + 0.000001f) * 0.999999f)));
    const int yi = abs(int(floorf((p.y + 0.000001f) * 0.999999f)));
    const int zi = abs(int(floorf((p.z + 0.000001f) * 0.999999f)));
    return ((xi % 2 == yi % 2) == (zi % 2 != 0)) ? 1.0f : 0.0f;
}

// Gradient types (material_compile.GRADIENT_TYPES)
LANTERN_HD inline float node_gradient(int type, Vec3 p) {
    float r;
    switch (type) {
    case 0: r = p.x; break;
    case 1: r = fmaxf(p.x, 0.0f); r = r * r; break;
    case 2: r = clampf(p.x, 0.0f, 1.0f); r = r * r * (3.0f - 2.0f * r); break;
    case 3: r = (p.x + p.y) * 0.5f; break;
    case 4: r = atan2f(p.y, p.x) / (2.0f * kPi) + 0.5f; break;
    case 5: r = fmaxf(0.999999f - length(p), 0.0f); r = r * r; break;
    default: r = fmaxf(0.999999f - length(p), 0.0f); break;
    }
    return clampf(r, 0.0f, 1.0f);
}

LANTERN_HD inline Vec3 node_magic(Vec3 p, int depth, float d) {
    float x = sinf((p.x + p.y + p.z) * 5.0f);
    float y = cosf((-p.x + p.y - p.z) * 5.0f);
    float z = -cosf((-p.x - p.y + p.z) * 5.0f);
    if (depth > 0) {
        x *= d; y *= d; z *= d;
        y = -cosf(x - y + z); y *= d;
        if (depth > 1) { x = cosf(x - y - z); x *= d; }
        if (depth > 2) { z = sinf(-x - y - z); z *= d; }
        if (depth > 3) { x = -cosf(-x + y - z); x *= d; }
        if (depth > 4) { y = -sinf(-x + y + z); y *= d; }
        if (depth > 5) { y = -cosf(-x + y + z); y *= d; }
        if (depth > 6) { x = cosf(x + y + z); x *= d; }
        if (depth > 7) { z = sinf(x + y - z); z *= d; }
        if (depth > 8) { x = -cosf(-x - y + z); x *= d; }
        if (depth > 9) { y = -sinf(x - y + z); y *= d; }
    }
    if (d != 0.0f) {
        d *= 2.0f;
        x /= d; y /= d; z /= d;
    }
    return Vec3{0.5f - x, 0.5f - y, 0.5f - z};
}

// Brick (Blender's manual: rows of height row_height, bricks of brick_width, every
// offset_freq-th row shifted by offset x width, every squash_freq-th row's bricks squash x
// wide); tint from the integer noise of the brick's (row, column) (Hugo Elias' hash), mortar
// within mortar_size of a brick's edge, softened over mortar_smooth (none where it is negative,
// as in Cycles). Returns the mortar factor.
LANTERN_HD inline float brick_noise(uint32_t n) {
    n = (n + 1013u) & 0x7fffffffu;
    n = (n >> 13) ^ n;
    const uint32_t nn = (n * (n * n * 60493u + 19990303u) + 1376312589u) & 0x7fffffffu;
    return 0.5f * (float(nn) / 1073741824.0f);
}
LANTERN_HD inline float node_brick(Vec3 p, float mortar_size, float mortar_smooth, float bias,
                                   float width, float row_height, float offset, int offset_freq,
                                   float squash, int squash_freq, float* tint) {
    // Bricks of no (or negative) width or height go through the same arithmetic, as in Cycles:
    // x / 0 is +-inf or NaN, whose cell (clamped; NaN to the low end) hashes and divides as
    // Cycles' integer conversion of it does, and the distance to the far edge is <= 0, so such
    // bricks are all mortar wherever mortar_size > 0 (difftest D36)
    auto cell = [](float v) { return int(clampf(floorf(v), -1073741824.0f, 1073741824.0f)); };
    const int row = cell(p.y / row_height);
    float shift = 0.0f;
    if (offset_freq != 0 && squash_freq != 0) {
        width *= (row % squash_freq) != 0 ? 1.0f : squash;
        shift = (row % offset_freq) != 0 ? 0.0f : width * offset;
    }
    const int col = cell((p.x + shift) / width);
    const float x = (p.x + shift) - width * float(col);
    const float y = p.y - row_height * float(row);
    *tint = clampf(brick_noise((uint32_t(row) << 16) + (uint32_t(col) & 0xFFFFu)) + bias, 0.0f,
                   1.0f);
    float d = fminf(fminf(x, y), fminf(width - x, row_height - y));
    if (d >= mortar_size) return 0.0f;
    if (mortar_smooth == 0.0f) return 1.0f;
    // Cycles' smoothstep of d / mortar_smooth, 0 below 0: a negative Mortar Smooth leaves no
    // mortar at all (d > 0 here), where smoothstep(0, s, d) read 1 (difftest D18)
    const float f = (1.0f - d / mortar_size) / mortar_smooth;
    if (!(f > 0.0f)) return 0.0f;
    return f >= 1.0f ? 1.0f : f * f * (3.0f - 2.0f * f);
}

// Wave: type 0 bands, 1 rings; dir: bands X, Y, Z, diagonal / rings X, Y, Z, spherical;
// profile 0 sine, 1 saw, 2 triangle
LANTERN_HD inline float node_wave(Vec3 p, int type, int dir, int profile, float distortion,
                                  float detail, float dscale, float droughness, float phase) {
    p = (p + vec3(0.000001f)) * 0.999999f;
    float n;
    if (type == 0) {
        n = dir == 0 ? p.x * 20.0f : dir == 1 ? p.y * 20.0f : dir == 2 ? p.z * 20.0f
                                                                       : (p.x + p.y + p.z) * 10.0f;
    } else {
        Vec3 rp = p;
        if (dir == 0) rp.x = 0.0f;
        else if (dir == 1) rp.y = 0.0f;
        else if (dir == 2) rp.z = 0.0f;
        n = length(rp) * 20.0f;
    }
    n += phase;
    if (distortion != 0.0f) {
        const float q[3] = {p.x * dscale, p.y * dscale, p.z * dscale};
        NoiseParams np{detail, droughness, 2.0f, 0.0f, 1.0f, kNoiseFbm, 1};
        n += distortion * (noise_fractal(q, 3, np) * 2.0f - 1.0f);
    }
    if (profile == 0) return 0.5f + 0.5f * sinf(n - 0.5f * kPi);
    n /= 2.0f * kPi;
    if (profile == 1) return n - floorf(n);
    return fabsf(n - floorf(n + 0.5f)) * 2.0f;
}

// ---- Voronoi (Worley): features F1, F2, smooth F1; metrics Euclidean, Manhattan, Chebychev,
// Minkowski (1D: |a - b| whatever the metric); 1D (over w), 2D (x, y), 3D (x, y, z), 4D
// (x, y, z, w). Written once over D axes (D a template parameter, so that each dimension's
// loops unroll as the 3D-only code's did). ----
struct VoronoiOut {
    float distance;
    Vec3 color, position;
    float w;  // the position's w (1D and 4D)
};
template <int D>
LANTERN_HD inline float voronoi_distance(const float* a, const float* b, int metric,
                                         float exponent) {
    if (D == 1) return fabsf(b[0] - a[0]);
    float acc = 0.0f;
    for (int i = 0; i < D; ++i) {
        const float d = fabsf(a[i] - b[i]);
        switch (metric) {
        case 1: acc += d; break;
        case 2: acc = fmaxf(acc, d); break;
        case 3: acc += powf(d, exponent); break;
        default: acc += d * d; break;
        }
    }
    if (metric == 3) return powf(acc, 1.0f / exponent);
    return metric == 0 ? sqrtf(acc) : acc;
}
// the feature point of integer cell c in [0, 1) per axis (PCG, as Blender; 1D: the float
// hash of the cell's value), and the cell's colour (2D: PCG 3D with z = 0, 4D: the first
// three of PCG 4D)
template <int D>
LANTERN_HD inline void voronoi_point_hash(const int* c, float* h) {
    if constexpr (D == 1) {
        h[0] = hashf1(float(c[0]));
    } else if constexpr (D == 2) {
        const Vec2 v = pcg2d_unit(c[0], c[1]);
        h[0] = v.x, h[1] = v.y;
    } else if constexpr (D == 3) {
        const Vec3 v = pcg3d_unit(c[0], c[1], c[2]);
        h[0] = v.x, h[1] = v.y, h[2] = v.z;
    } else {
        pcg4d_unit(c[0], c[1], c[2], c[3], h);
    }
}
template <int D>
LANTERN_HD inline Vec3 voronoi_color_hash(const int* c) {
    if constexpr (D == 1) {
        return hashf1_to_vec3(float(c[0]));
    } else if constexpr (D == 4) {
        float h[4];
        pcg4d_unit(c[0], c[1], c[2], c[3], h);
        return Vec3{h[0], h[1], h[2]};
    } else {
        return pcg3d_unit(c[0], c[1], D == 2 ? 0 : c[2]);
    }
}
// feature 0 F1, 1 F2, 2 smooth F1 at p (D coordinates, scaled); randomness in [0, 1],
// smoothness in [0, 0.5] (the op clamps them, as Cycles). position: D coordinates.
template <int D>
LANTERN_HD inline float voronoi_features(const float* p, int feature, int metric, float exponent,
                                         float randomness, float smoothness, Vec3* color,
                                         float* position) {
    int cell[D], off[D], best1[D] = {}, best2[D] = {};
    float local[D], pos1[D] = {}, pos2[D] = {}, smooth_pos[D] = {};
    for (int a = 0; a < D; ++a) {
        const float f = floorf(p[a]);
        cell[a] = int(f);
        local[a] = p[a] - f;
    }
    const int r = feature == 2 ? 2 : 1;
    for (int a = 0; a < D; ++a) off[a] = -r;
    float d1 = kInf, d2 = kInf, smooth_d = 0.0f;
    Vec3 smooth_color{};
    bool first = true;
    for (;;) {   // every offset in [-r, r]^D, axis 0 fastest (Cycles' order)
        int c[D];
        float h[D], pp[D];
        for (int a = 0; a < D; ++a) c[a] = cell[a] + off[a];
        voronoi_point_hash<D>(c, h);
        for (int a = 0; a < D; ++a) pp[a] = float(off[a]) + h[a] * randomness;
        const float d = voronoi_distance<D>(pp, local, metric, exponent);
        if (feature == 2) {   // Cycles' first cell takes h = 1 (no blend)
            const float h01 = first ? 1.0f
                                    : smoothstepf(0.0f, 1.0f,
                                                  0.5f + 0.5f * (smooth_d - d) / smoothness);
            first = false;
            float corr = smoothness * h01 * (1.0f - h01);
            smooth_d = lerpf(smooth_d, d, h01) - corr;
            corr /= 1.0f + 3.0f * smoothness;
            smooth_color = mix3(smooth_color, voronoi_color_hash<D>(c), h01) - vec3(corr);
            for (int a = 0; a < D; ++a) smooth_pos[a] = lerpf(smooth_pos[a], pp[a], h01) - corr;
        } else if (d < d1) {
            d2 = d1;
            d1 = d;
            for (int a = 0; a < D; ++a) {
                best2[a] = best1[a], best1[a] = off[a];
                pos2[a] = pos1[a], pos1[a] = pp[a];
            }
        } else if (d < d2) {
            d2 = d;
            for (int a = 0; a < D; ++a) best2[a] = off[a], pos2[a] = pp[a];
        }
        int a = 0;
        while (a < D && off[a] == r) off[a++] = -r;
        if (a == D) break;
        ++off[a];
    }
    const float* pos = feature == 2 ? smooth_pos : feature == 1 ? pos2 : pos1;
    for (int a = 0; a < D; ++a) position[a] = pos[a] + float(cell[a]);
    if (feature == 2) {
        *color = smooth_color;
        return smooth_d;
    }
    int c[D];
    for (int a = 0; a < D; ++a) c[a] = cell[a] + (feature == 1 ? best2[a] : best1[a]);
    *color = voronoi_color_hash<D>(c);
    return feature == 1 ? d2 : d1;
}
// coord (x, y, z, w), already scaled; dim 1 reads w, 2 x and y, 3 x, y and z, 4 all
LANTERN_HD inline VoronoiOut node_voronoi(const float coord[4], int dim, int feature, int metric,
                                          float exponent, float randomness, float smoothness) {
    VoronoiOut o{0.0f, Vec3{}, Vec3{}, 0.0f};
    float pos[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    switch (dim) {
    case 1:
        o.distance = voronoi_features<1>(coord + 3, feature, metric, exponent, randomness,
                                         smoothness, &o.color, pos + 3);
        break;
    case 2:
        o.distance = voronoi_features<2>(coord, feature, metric, exponent, randomness,
                                         smoothness, &o.color, pos);
        break;
    case 4:
        o.distance = voronoi_features<4>(coord, feature, metric, exponent, randomness,
                                         smoothness, &o.color, pos);
        break;
    default:
        o.distance = voronoi_features<3>(coord, feature, metric, exponent, randomness,
                                         smoothness, &o.color, pos);
        break;
    }
    o.position = Vec3{pos[0], pos[1], pos[2]};
    o.w = pos[3];
    return o;
}

// White Noise of dim 1-4 over (p, w): value and colour
LANTERN_HD inline float node_white_noise(Vec3 p, float w, int dim, Vec3* color) {
    switch (dim) {
    case 1: *color = hashf1_to_vec3(w); return hashf1(w);
    case 2: *color = hashf2_to_vec3(p.x, p.y); return hashf2(p.x, p.y);
    case 4: *color = hashf4_to_vec3(p.x, p.y, p.z, w); return hashf4(p.x, p.y, p.z, w);
    default: *color = hashf3_to_vec3(p); return hashf3(p.x, p.y, p.z);
    }
}

// A baked table of n RGBA entries (ColorRamp: Blender's own evaluation at i / (n - 1)),
// read at f in [0, 1] with linear steps between entries (none for Constant), as Cycles does.
LANTERN_HD inline void table_lookup(const float* t, int n, float f, bool interp, float out[4]) {
    f = clampf(is_finite(f) ? f : 0.0f, 0.0f, 1.0f) * float(n - 1);
    const int i = min_int(max_int(int(f), 0), n - 1);
    const float u = f - float(i);
    for (int c = 0; c < 4; ++c) out[c] = t[4 * i + c];
    if (interp && u > 0.0f && i + 1 < n)
        for (int c = 0; c < 4; ++c) out[c] = (1.0f - u) * out[c] + u * t[4 * (i + 1) + c];
}
// A curve table over [lo, hi] (RGB / Float Curves), linear beyond it from the end slopes.
LANTERN_HD inline float curve_lookup(const float* t, int n, int channel, float lo, float hi,
                                     float x) {
    const float range = hi - lo;
    float f = range != 0.0f ? (x - lo) / range : 0.0f;
    if (!is_finite(f)) return 0.0f;
    const float step = 1.0f / float(n - 1);
    if (f < 0.0f) return t[channel] - f * (t[channel] - t[4 + channel]) / step;
    if (f > 1.0f) {
        const float a = t[4 * (n - 1) + channel], b = t[4 * (n - 2) + channel];
        return a + (f - 1.0f) * (a - b) / step;
    }
    f *= float(n - 1);
    const int i = min_int(int(f), n - 2);
    const float u = f - float(i);
    return (1.0f - u) * t[4 * i + channel] + u * t[4 * (i + 1) + channel];
}

// Fresnel reflectance of a dielectric of relative index eta at cosine cosi (Fresnel node)
LANTERN_HD inline float fresnel_dielectric_cos(float cosi, float eta) {
    const float c = fabsf(cosi);
    float g = eta * eta - 1.0f + c * c;
    if (g > 0.0f) {
        g = sqrtf(g);
        const float a = (g - c) / (g + c), b = (c * (g + c) - 1.0f) / (c * (g - c) + 1.0f);
        return 0.5f * a * a * (1.0f + b * b);
    }
    return 1.0f;
}
LANTERN_HD inline float node_fresnel(float ior, Vec3 i, Vec3 n, bool backfacing) {
    float eta = fmaxf(ior, 1e-5f);
    eta = backfacing ? 1.0f / eta : eta;
    return fresnel_dielectric_cos(dot(i, n), eta);
}
LANTERN_HD inline void node_layer_weight(float blend, Vec3 i, Vec3 n, bool backfacing,
                                         float* fresnel, float* facing) {
    float eta = fmaxf(1.0f - blend, 1e-5f);
    eta = backfacing ? eta : 1.0f / eta;
    *fresnel = fresnel_dielectric_cos(dot(i, n), eta);
    float f = fabsf(dot(i, n));
    if (blend != 0.5f) {
        float b = clampf(blend, 0.0f, 1.0f - 1e-5f);
        b = b < 0.5f ? 2.0f * b : 0.5f / (1.0f - b);
        f = powf(f, b);
    }
    *facing = 1.0f - f;
}

// ---- Box projection (Image Texture, projection Box) ----
// Blender's definition: the object-space shading normal n picks the box side whose axis it is
// nearest, the image laid on that side's plane (X side: (y, z), Y side: (x, z), Z side:
// (y, x), mirrored on the sides facing so that the image reads the same way round the box);
// Blend in [0, 1] widens each edge between sides into a band where two (at a corner three)
// sides mix. The weights of the X, Y, Z sides, summing to 1, from the normalised |n|.
LANTERN_HD inline Vec3 image_box_weights(Vec3 n, float blend) {
    Vec3 a{fabsf(n.x), fabsf(n.y), fabsf(n.z)};
    const float sum = a.x + a.y + a.z;
    if (!(sum > 0.0f)) return Vec3{0.0f, 0.0f, 1.0f};
    a = a / sum;
    blend = clampf(blend, 0.0f, 1.0f);
    const float limit = 0.5f * (1.0f + blend);
    if (a.x > limit * (a.x + a.y) && a.x > limit * (a.x + a.z)) return Vec3{1.0f, 0.0f, 0.0f};
    if (a.y > limit * (a.x + a.y) && a.y > limit * (a.y + a.z)) return Vec3{0.0f, 1.0f, 0.0f};
    if (a.z > limit * (a.x + a.z) && a.z > limit * (a.y + a.z)) return Vec3{0.0f, 0.0f, 1.0f};
    if (!(blend > 0.0f)) return Vec3{0.0f, 0.0f, 1.0f};  // no side stands out: one side
    // an edge band between two sides: the ratio of their two components, rescaled to [0, 1]
    auto edge = [blend](float p, float q) {
        return clampf((p / (p + q) - 0.5f * (1.0f - blend)) / blend, 0.0f, 1.0f);
    };
    if (a.z < (1.0f - limit) * (a.x + a.y)) {
        const float w = edge(a.x, a.y);
        return Vec3{w, 1.0f - w, 0.0f};
    }
    if (a.x < (1.0f - limit) * (a.y + a.z)) {
        const float w = edge(a.y, a.z);
        return Vec3{0.0f, w, 1.0f - w};
    }
    if (a.y < (1.0f - limit) * (a.x + a.z)) {
        const float w = edge(a.x, a.z);
        return Vec3{w, 0.0f, 1.0f - w};
    }
    // a corner: all three sides
    const float k = 1.0f / (2.0f * limit - 1.0f);
    return Vec3{((2.0f - limit) * a.x + (limit - 1.0f)) * k,
                ((2.0f - limit) * a.y + (limit - 1.0f)) * k,
                ((2.0f - limit) * a.z + (limit - 1.0f)) * k};
}

// The image coordinates of box side `axis` (0 X, 1 Y, 2 Z) for the point co, normal n.
LANTERN_HD inline Vec2 image_box_uv(int axis, Vec3 co, Vec3 n) {
    if (axis == 0) return Vec2{n.x < 0.0f ? 1.0f - co.y : co.y, co.z};
    if (axis == 1) return Vec2{n.y > 0.0f ? 1.0f - co.x : co.x, co.z};
    return Vec2{n.z > 0.0f ? 1.0f - co.y : co.y, co.x};
}

// Image Texture projections of a vector: 0 flat (x, y), 2 sphere, 3 tube (box: the weights
// above, three lookups: material_program_ops.h)
LANTERN_HD inline Vec2 image_projection(int projection, Vec3 co) {
    if (projection == 0 || projection == 1) return Vec2{co.x, co.y};
    const Vec3 d = (co - vec3(0.5f)) * 2.0f;
    if (projection == 3) {
        const float len = sqrtf(d.x * d.x + d.y * d.y);
        if (!(len > 0.0f)) return Vec2{};
        return Vec2{(1.0f - atan2f(d.x / len, d.y / len) / kPi) * 0.5f, (d.z + 1.0f) * 0.5f};
    }
    const float len = length(d);
    if (!(len > 0.0f)) return Vec2{};
    const float u = (d.x == 0.0f && d.y == 0.0f) ? 0.0f
                                                 : (1.0f - atan2f(d.x, d.y) / kPi) * 0.5f;
    return Vec2{u, 1.0f - acosf(clampf(d.z / len, -1.0f, 1.0f)) / kPi};
}

}  // namespace lantern
