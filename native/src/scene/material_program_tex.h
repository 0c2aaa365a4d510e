// Blender's procedural texture nodes and the view-dependent utility nodes as host+device code:
// Checker, Gradient, Magic, Wave, Voronoi (F1, F2, smooth F1; four metrics; 2D/3D), White
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
// within mortar_size of a brick's edge, softened over mortar_smooth. Returns the mortar factor.
LANTERN_HD inline float brick_noise(uint32_t n) {
    n = (n + 1013u) & 0x7fffffffu;
    n = (n >> 13) ^ n;
    const uint32_t nn = (n * (n * n * 60493u + 19990303u) + 1376312589u) & 0x7fffffffu;
    return 0.5f * (float(nn) / 1073741824.0f);
}
LANTERN_HD inline float node_brick(Vec3 p, float mortar_size, float mortar_smooth, float bias,
                                   float width, float row_height, float offset, int offset_freq,
                                   float squash, int squash_freq, float* tint) {
    *tint = 0.0f;
    if (!(width > 0.0f) || !(row_height > 0.0f)) return 0.0f;  // degenerate bricks: all brick
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
    d = 1.0f - d / mortar_size;
    return d < mortar_smooth ? smoothstepf(0.0f, mortar_smooth, d) : 1.0f;
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
// Minkowski; 2D (p.z ignored) or 3D ----
LANTERN_HD inline float voronoi_distance(Vec3 a, Vec3 b, int metric, float exponent) {
    const Vec3 d = a - b;
    switch (metric) {
    case 1: return fabsf(d.x) + fabsf(d.y) + fabsf(d.z);
    case 2: return fmaxf(fabsf(d.x), fmaxf(fabsf(d.y), fabsf(d.z)));
    case 3: return powf(powf(fabsf(d.x), exponent) + powf(fabsf(d.y), exponent) +
                            powf(fabsf(d.z), exponent), 1.0f / exponent);
    default: return length(d);
    }
}
struct VoronoiOut {
    float distance;
    Vec3 color, position;
};
// the feature point of an integer cell (PCG, as Blender), and a cell's colour
LANTERN_HD inline Vec3 voronoi_point_hash(int x, int y, int z, int dim) {
    if (dim == 2) {
        const Vec2 h = pcg2d_unit(x, y);
        return Vec3{h.x, h.y, 0.0f};
    }
    return pcg3d_unit(x, y, z);
}
LANTERN_HD inline Vec3 voronoi_color_hash(int x, int y, int z, int dim) {
    return pcg3d_unit(x, y, dim == 2 ? 0 : z);
}
// feature 0 F1, 1 F2, 2 smooth F1
LANTERN_HD inline VoronoiOut node_voronoi(Vec3 coord, int dim, int feature, int metric,
                                          float exponent, float randomness, float smoothness) {
    if (dim == 2) coord.z = 0.0f;
    const Vec3 cell{floorf(coord.x), floorf(coord.y), floorf(coord.z)};
    const Vec3 local = coord - cell;
    const int cx = int(cell.x), cy = int(cell.y), cz = int(cell.z);
    const int r = feature == 2 ? 2 : 1;
    const int rz = dim == 2 ? 0 : r;
    VoronoiOut o{8.0f, Vec3{}, Vec3{}};
    float d1 = 8.0f, d2 = 8.0f;
    Vec3 off1{}, off2{}, pos1{}, pos2{};
    for (int k = -rz; k <= rz; ++k)
        for (int j = -r; j <= r; ++j)
            for (int i = -r; i <= r; ++i) {
                const Vec3 off{float(i), float(j), float(k)};
                const Vec3 pp = off + voronoi_point_hash(cx + i, cy + j, cz + k, dim) *
                                          randomness;
                const float d = voronoi_distance(pp, local, metric, exponent);
                if (feature == 2) {
                    const float h01 = smoothstepf(0.0f, 1.0f,
                                                  0.5f + 0.5f * (o.distance - d) / smoothness);
                    float corr = smoothness * h01 * (1.0f - h01);
                    o.distance = lerpf(o.distance, d, h01) - corr;
                    corr /= 1.0f + 3.0f * smoothness;
                    const Vec3 cc = voronoi_color_hash(cx + i, cy + j, cz + k, dim);
                    o.color = mix3(o.color, cc, h01) - vec3(corr);
                    o.position = mix3(o.position, pp, h01) - vec3(corr);
                } else if (d < d1) {
                    d2 = d1; off2 = off1; pos2 = pos1;
                    d1 = d; off1 = off; pos1 = pp;
                } else if (d < d2) {
                    d2 = d; off2 = off; pos2 = pp;
                }
            }
    auto color_of = [&](Vec3 off) {
        return voronoi_color_hash(cx + int(off.x), cy + int(off.y), cz + int(off.z), dim);
    };
    if (feature == 2) {
        o.position = o.position + cell;
    } else if (feature == 1) {
        o.distance = d2;
        o.color = color_of(off2);
        o.position = pos2 + cell;
    } else {
        o.distance = d1;
        o.color = color_of(off1);
        o.position = pos1 + cell;
    }
    if (dim == 2) o.position.z = 0.0f;
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
