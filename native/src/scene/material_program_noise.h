// Blender's procedural noise as host+device code, from the published algorithms: Bob Jenkins'
// lookup3 hash (public domain) over float bits, Perlin's improved gradient noise (2002) with
// Blender's per-dimension output scales, fBm and Musgrave's multifractals (Texturing &
// Modeling, ch. 16), Worley cellular noise. Blender's patterns depend on every constant here
// (hash seeds, gradient sets, offsets 100 + 100 h): tests/blender/test_bl_nodes.py compares
// them with Cycles per pixel.
#pragma once

#include <cstring>

#include "core/math.h"

namespace lantern {

// ---- lookup3 (Jenkins 2006): mix and final on three words ----
LANTERN_HD inline uint32_t rot32(uint32_t x, int k) { return (x << k) | (x >> (32 - k)); }
LANTERN_HD inline void jenkins_mix(uint32_t& a, uint32_t& b, uint32_t& c) {
    a -= c; a ^= rot32(c, 4);  c += b;
    b -= a; b ^= rot32(a, 6);  a += c;
    c -= b; c ^= rot32(b, 8);  b += a;
    a -= c; a ^= rot32(c, 16); c += b;
    b -= a; b ^= rot32(a, 19); a += c;
    c -= b; c ^= rot32(b, 4);  b += a;
}
LANTERN_HD inline void jenkins_final(uint32_t& a, uint32_t& b, uint32_t& c) {
    c ^= b; c -= rot32(b, 14);
    a ^= c; a -= rot32(c, 11);
    b ^= a; b -= rot32(a, 25);
    c ^= b; c -= rot32(b, 16);
    a ^= c; a -= rot32(c, 4);
    b ^= a; b -= rot32(a, 14);
    c ^= b; c -= rot32(b, 24);
}
// hashlittle's start for n words: 0xdeadbeef + 4 n (+ 13, Blender's initval)
LANTERN_HD inline uint32_t hash_u1(uint32_t kx) {
    uint32_t a, b, c;
    a = b = c = 0xdeadbeefu + (1u << 2) + 13u;
    a += kx;
    jenkins_final(a, b, c);
    return c;
}
LANTERN_HD inline uint32_t hash_u2(uint32_t kx, uint32_t ky) {
    uint32_t a, b, c;
    a = b = c = 0xdeadbeefu + (2u << 2) + 13u;
    b += ky;
    a += kx;
    jenkins_final(a, b, c);
    return c;
}
LANTERN_HD inline uint32_t hash_u3(uint32_t kx, uint32_t ky, uint32_t kz) {
    uint32_t a, b, c;
    a = b = c = 0xdeadbeefu + (3u << 2) + 13u;
    c += kz;
    b += ky;
    a += kx;
    jenkins_final(a, b, c);
    return c;
}
LANTERN_HD inline uint32_t hash_u4(uint32_t kx, uint32_t ky, uint32_t kz, uint32_t kw) {
    uint32_t a, b, c;
    a = b = c = 0xdeadbeefu + (4u << 2) + 13u;
    a += kx;
    b += ky;
    c += kz;
    jenkins_mix(a, b, c);
    a += kw;
    jenkins_final(a, b, c);
    return c;
}

LANTERN_HD inline uint32_t fbits(float f) {
    uint32_t u;
    memcpy(&u, &f, sizeof(u));
    return u;
}
LANTERN_HD inline float hash_to_unit(uint32_t h) { return float(h) / float(0xFFFFFFFFu); }
LANTERN_HD inline float hashf1(float x) { return hash_to_unit(hash_u1(fbits(x))); }
LANTERN_HD inline float hashf2(float x, float y) { return hash_to_unit(hash_u2(fbits(x), fbits(y))); }
LANTERN_HD inline float hashf3(float x, float y, float z) {
    return hash_to_unit(hash_u3(fbits(x), fbits(y), fbits(z)));
}
LANTERN_HD inline float hashf4(float x, float y, float z, float w) {
    return hash_to_unit(hash_u4(fbits(x), fbits(y), fbits(z), fbits(w)));
}
LANTERN_HD inline Vec3 hashf3_to_vec3(Vec3 p) {
    return Vec3{hashf3(p.x, p.y, p.z), hashf4(p.x, p.y, p.z, 1.0f), hashf4(p.x, p.y, p.z, 2.0f)};
}
LANTERN_HD inline Vec3 hashf2_to_vec3(float x, float y) {
    return Vec3{hashf2(x, y), hashf3(x, y, 1.0f), hashf3(x, y, 2.0f)};
}
LANTERN_HD inline Vec3 hashf1_to_vec3(float x) {
    return Vec3{hashf1(x), hashf2(x, 1.0f), hashf2(x, 2.0f)};
}
LANTERN_HD inline Vec3 hashf4_to_vec3(float x, float y, float z, float w) {
    return Vec3{hashf4(x, y, z, w), hashf4(z, x, w, y), hashf4(w, z, y, x)};
}
// ---- PCG 2D / 3D / 4D (Jarzynski & Olano, "Hash Functions for GPU Rendering", JCGT 2020) in
// Blender's signed-integer form (arithmetic shifts, the sign bit masked off at the end), over
// integer cells: what Blender's Voronoi hashes its cells with (measured against Cycles) ----
LANTERN_HD inline int32_t imul(int32_t a, int32_t b) { return int32_t(uint32_t(a) * uint32_t(b)); }
LANTERN_HD inline int32_t iadd(int32_t a, int32_t b) { return int32_t(uint32_t(a) + uint32_t(b)); }
LANTERN_HD inline int32_t ashr16(int32_t v) { return v < 0 ? ~(~v >> 16) : v >> 16; }
LANTERN_HD inline Vec3 pcg3d_unit(int32_t x, int32_t y, int32_t z) {
    int32_t v[3] = {x, y, z};
    for (int i = 0; i < 3; ++i) v[i] = iadd(imul(v[i], 1664525), 1013904223);
    v[0] = iadd(v[0], imul(v[1], v[2]));
    v[1] = iadd(v[1], imul(v[2], v[0]));
    v[2] = iadd(v[2], imul(v[0], v[1]));
    for (int i = 0; i < 3; ++i) v[i] ^= ashr16(v[i]);
    v[0] = iadd(v[0], imul(v[1], v[2]));
    v[1] = iadd(v[1], imul(v[2], v[0]));
    v[2] = iadd(v[2], imul(v[0], v[1]));
    const float s = 1.0f / float(0x7FFFFFFF);
    return Vec3{float(v[0] & 0x7FFFFFFF) * s, float(v[1] & 0x7FFFFFFF) * s,
                float(v[2] & 0x7FFFFFFF) * s};
}
LANTERN_HD inline void pcg4d_unit(int32_t x, int32_t y, int32_t z, int32_t w, float out[4]) {
    int32_t v[4] = {x, y, z, w};
    for (int i = 0; i < 4; ++i) v[i] = iadd(imul(v[i], 1664525), 1013904223);
    for (int round = 0; round < 2; ++round) {
        if (round == 1)
            for (int i = 0; i < 4; ++i) v[i] ^= ashr16(v[i]);
        v[0] = iadd(v[0], imul(v[1], v[3]));
        v[1] = iadd(v[1], imul(v[2], v[0]));
        v[2] = iadd(v[2], imul(v[0], v[1]));
        v[3] = iadd(v[3], imul(v[1], v[2]));
    }
    const float s = 1.0f / float(0x7FFFFFFF);
    for (int i = 0; i < 4; ++i) out[i] = float(v[i] & 0x7FFFFFFF) * s;
}
LANTERN_HD inline Vec2 pcg2d_unit(int32_t x, int32_t y) {
    int32_t v[2] = {iadd(imul(x, 1664525), 1013904223), iadd(imul(y, 1664525), 1013904223)};
    v[0] = iadd(v[0], imul(v[1], 1664525));
    v[1] = iadd(v[1], imul(v[0], 1664525));
    v[0] ^= ashr16(v[0]);
    v[1] ^= ashr16(v[1]);
    v[0] = iadd(v[0], imul(v[1], 1664525));
    v[1] = iadd(v[1], imul(v[0], 1664525));
    const float s = 1.0f / float(0x7FFFFFFF);
    return Vec2{float(v[0] & 0x7FFFFFFF) * s, float(v[1] & 0x7FFFFFFF) * s};
}

// Blender's per-seed offsets of the colour channels and distortion: 100 + 100 h
LANTERN_HD inline float noise_offset(float seed, float k) { return 100.0f + hashf2(seed, k) * 100.0f; }
LANTERN_HD inline float noise_offset1(float seed) { return 100.0f + hashf1(seed) * 100.0f; }

// ---- Perlin's improved noise: quintic fade, gradient sets of 1D-4D ----
LANTERN_HD inline float fade5(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }
LANTERN_HD inline float neg_if(float v, uint32_t c) { return c ? -v : v; }
LANTERN_HD inline float lerpf(float a, float b, float t) { return (1.0f - t) * a + t * b; }
LANTERN_HD inline float grad1(uint32_t h, float x) {
    h &= 15u;
    return neg_if(1.0f + float(h & 7u), h & 8u) * x;
}
LANTERN_HD inline float grad2(uint32_t h, float x, float y) {
    h &= 7u;
    float u = h < 4u ? x : y, v = 2.0f * (h < 4u ? y : x);
    return neg_if(u, h & 1u) + neg_if(v, h & 2u);
}
LANTERN_HD inline float grad3(uint32_t h, float x, float y, float z) {
    h &= 15u;
    float u = h < 8u ? x : y;
    float vt = (h == 12u || h == 14u) ? x : z;
    float v = h < 4u ? y : vt;
    return neg_if(u, h & 1u) + neg_if(v, h & 2u);
}
LANTERN_HD inline float grad4(uint32_t h, float x, float y, float z, float w) {
    h &= 31u;
    float u = h < 24u ? x : y, v = h < 16u ? y : z, s = h < 8u ? z : w;
    return neg_if(u, h & 1u) + neg_if(v, h & 2u) + neg_if(s, h & 4u);
}
LANTERN_HD inline int floor_frac(float x, float* f) {
    float fl = floorf(x);
    *f = x - fl;
    return int(fl);
}
LANTERN_HD inline float perlin1(float x) {
    float fx;
    int X = floor_frac(x, &fx);
    return lerpf(grad1(hash_u1(uint32_t(X)), fx), grad1(hash_u1(uint32_t(X + 1)), fx - 1.0f),
                 fade5(fx));
}
LANTERN_HD inline float perlin2(float x, float y) {
    float fx, fy;
    int X = floor_frac(x, &fx), Y = floor_frac(y, &fy);
    float u = fade5(fx), v = fade5(fy);
    auto g = [&](int i, int j) {
        return grad2(hash_u2(uint32_t(X + i), uint32_t(Y + j)), fx - float(i), fy - float(j));
    };
    return lerpf(lerpf(g(0, 0), g(1, 0), u), lerpf(g(0, 1), g(1, 1), u), v);
}
LANTERN_HD inline float perlin3(float x, float y, float z) {
    float fx, fy, fz;
    int X = floor_frac(x, &fx), Y = floor_frac(y, &fy), Z = floor_frac(z, &fz);
    float u = fade5(fx), v = fade5(fy), w = fade5(fz);
    auto g = [&](int i, int j, int k) {
        return grad3(hash_u3(uint32_t(X + i), uint32_t(Y + j), uint32_t(Z + k)), fx - float(i),
                     fy - float(j), fz - float(k));
    };
    float z0 = lerpf(lerpf(g(0, 0, 0), g(1, 0, 0), u), lerpf(g(0, 1, 0), g(1, 1, 0), u), v);
    float z1 = lerpf(lerpf(g(0, 0, 1), g(1, 0, 1), u), lerpf(g(0, 1, 1), g(1, 1, 1), u), v);
    return lerpf(z0, z1, w);
}
LANTERN_HD inline float perlin4(float x, float y, float z, float q) {
    float fx, fy, fz, fw;
    int X = floor_frac(x, &fx), Y = floor_frac(y, &fy), Z = floor_frac(z, &fz),
        W = floor_frac(q, &fw);
    float u = fade5(fx), v = fade5(fy), t = fade5(fz), s = fade5(fw);
    auto g = [&](int i, int j, int k, int l) {
        return grad4(hash_u4(uint32_t(X + i), uint32_t(Y + j), uint32_t(Z + k), uint32_t(W + l)),
                     fx - float(i), fy - float(j), fz - float(k), fw - float(l));
    };
    float r[2];
    for (int l = 0; l < 2; ++l) {
        float z0 = lerpf(lerpf(g(0, 0, 0, l), g(1, 0, 0, l), u),
                         lerpf(g(0, 1, 0, l), g(1, 1, 0, l), u), v);
        float z1 = lerpf(lerpf(g(0, 0, 1, l), g(1, 0, 1, l), u),
                         lerpf(g(0, 1, 1, l), g(1, 1, 1, l), u), v);
        r[l] = lerpf(z0, z1, t);
    }
    return lerpf(r[0], r[1], s);
}
// Signed noise in about [-1, 1] at a point of 1-4 dimensions (p[0..dim)); coordinates past 1e6
// wrap at 1e5 with a half-cell shift, as Blender keeps float precision.
// Out of line on the device: noise_fractal's nine call sites held nine copies of the four Perlin
// noises, compiled by ptxas in every kernel that runs node programs (docs/cuda_backend.md,
// "Build time").
#ifdef __CUDA_ARCH__
__noinline__
#endif
LANTERN_HD inline float snoise(const float* p, int dim) {
    float q[4];
    for (int i = 0; i < dim; ++i) {
        const float corr = fabsf(p[i]) >= 1000000.0f ? 0.5f : 0.0f;
        q[i] = fmodf(p[i], 100000.0f) + corr;
    }
    float r;
    switch (dim) {
    case 1: r = 0.2500f * perlin1(q[0]); break;
    case 2: r = 0.6616f * perlin2(q[0], q[1]); break;
    case 3: r = 0.9820f * perlin3(q[0], q[1], q[2]); break;
    default: r = 0.8344f * perlin4(q[0], q[1], q[2], q[3]); break;
    }
    return is_finite(r) ? r : 0.0f;
}

LANTERN_HD inline void scale_point(const float* p, float s, float* out, int dim) {
    for (int i = 0; i < dim; ++i) out[i] = p[i] * s;
}

enum NoiseType : int { kNoiseMultifractal = 0, kNoiseRidged = 1, kNoiseHybrid = 2,
                       kNoiseFbm = 3, kNoiseHetero = 4 };

struct NoiseParams {
    float detail, roughness, lacunarity, offset, gain;
    int type, normalize;
};

// One fractal of the Noise Texture at p (dim dimensions), as Blender 4.x defines its types.
LANTERN_HD inline float noise_fractal(const float* p, int dim, const NoiseParams& n) {
    float q[4];
    const int octaves = int(n.detail);
    const float rmd = n.detail - floorf(n.detail);
    switch (n.type) {
    case kNoiseMultifractal: {
        float value = 1.0f, pwr = 1.0f, s = 1.0f;
        for (int i = 0; i <= octaves; ++i) {
            scale_point(p, s, q, dim);
            value *= pwr * snoise(q, dim) + 1.0f;
            pwr *= n.roughness;
            s *= n.lacunarity;
        }
        if (rmd != 0.0f) {
            scale_point(p, s, q, dim);
            value *= rmd * pwr * snoise(q, dim) + 1.0f;
        }
        return value;
    }
    case kNoiseHetero: {
        float pwr = n.roughness, s = n.lacunarity;
        float value = n.offset + snoise(p, dim);
        for (int i = 1; i <= octaves; ++i) {
            scale_point(p, s, q, dim);
            value += (snoise(q, dim) + n.offset) * pwr * value;
            pwr *= n.roughness;
            s *= n.lacunarity;
        }
        if (rmd != 0.0f) {
            scale_point(p, s, q, dim);
            value += rmd * ((snoise(q, dim) + n.offset) * pwr * value);
        }
        return value;
    }
    case kNoiseHybrid: {
        float pwr = 1.0f, value = 0.0f, weight = 1.0f, s = 1.0f;
        for (int i = 0; weight > 0.001f && i <= octaves; ++i) {
            if (weight > 1.0f) weight = 1.0f;
            scale_point(p, s, q, dim);
            float signal = (snoise(q, dim) + n.offset) * pwr;
            pwr *= n.roughness;
            value += weight * signal;
            weight *= n.gain * signal;
            s *= n.lacunarity;
        }
        if (rmd != 0.0f && weight > 0.001f) {
            if (weight > 1.0f) weight = 1.0f;
            scale_point(p, s, q, dim);
            value += rmd * weight * ((snoise(q, dim) + n.offset) * pwr);
        }
        return value;
    }
    case kNoiseRidged: {
        float pwr = n.roughness, s = 1.0f;
        float signal = n.offset - fabsf(snoise(p, dim));
        signal *= signal;
        float value = signal, weight = 1.0f;
        for (int i = 1; i <= octaves; ++i) {
            s *= n.lacunarity;
            scale_point(p, s, q, dim);
            weight = clampf(signal * n.gain, 0.0f, 1.0f);
            signal = n.offset - fabsf(snoise(q, dim));
            signal *= signal;
            signal *= weight;
            value += signal * pwr;
            pwr *= n.roughness;
        }
        return value;
    }
    default: {  // fBm
        float s = 1.0f, amp = 1.0f, maxamp = 0.0f, sum = 0.0f;
        for (int i = 0; i <= octaves; ++i) {
            scale_point(p, s, q, dim);
            sum += snoise(q, dim) * amp;
            maxamp += amp;
            amp *= n.roughness;
            s *= n.lacunarity;
        }
        if (rmd != 0.0f) {
            scale_point(p, s, q, dim);
            const float sum2 = sum + snoise(q, dim) * amp;
            return n.normalize ? lerpf(0.5f * sum / maxamp + 0.5f,
                                       0.5f * sum2 / (maxamp + amp) + 0.5f, rmd)
                               : lerpf(sum, sum2, rmd);
        }
        return n.normalize ? 0.5f * sum / maxamp + 0.5f : sum;
    }
    }
}

// The Noise Texture: p already scaled (dim 1-4); distortion, then the value and (with colour)
// two more fractals at offset points. Seeds of the offsets follow Blender: distortion uses
// 0..dim-1, the colour's green and blue dim and dim + 1.
LANTERN_HD inline void noise_texture(const float* p_in, int dim, float distortion,
                                     const NoiseParams& n, float* value, Vec3* color) {
    float p[4] = {0.0f, 0.0f, 0.0f, 0.0f}, q[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    for (int i = 0; i < dim; ++i) p[i] = p_in[i];
    auto offset_point = [&](float seed, float* out) {
        if (dim == 1) {
            out[0] = p[0] + noise_offset1(seed);
            return;
        }
        for (int i = 0; i < dim; ++i) out[i] = p[i] + noise_offset(seed, float(i));
    };
    if (distortion != 0.0f) {
        float d[4] = {0.0f, 0.0f, 0.0f, 0.0f};
        for (int k = 0; k < dim; ++k) {
            offset_point(float(k), q);
            d[k] = snoise(q, dim) * distortion;
        }
        for (int k = 0; k < dim; ++k) p[k] += d[k];
    }
    *value = noise_fractal(p, dim, n);
    if (color) {
        const float s1 = dim == 1 ? 1.0f : float(dim), s2 = s1 + 1.0f;
        offset_point(s1, q);
        const float g = noise_fractal(q, dim, n);
        offset_point(s2, q);
        const float b = noise_fractal(q, dim, n);
        *color = Vec3{*value, g, b};
    }
}

}  // namespace lantern
