// Image textures as stages see them: texels in one pool, a small header per texture, and the
// lookup (wrap, closest or bilinear) as host+device code. Texel rows run bottom to top, as
// Blender's Image.pixels: uv (0, 0) is the lower-left corner of the image, texel centres at
// ((x + 0.5) / width, (y + 0.5) / height), as in Cycles.
#pragma once

#include "core/math.h"

namespace lantern {

struct Vec4 {
    float x = 0, y = 0, z = 0, w = 0;
};

enum TextureFormat : int32_t {
    kTexRgba8Srgb = 0,    // 8-bit sRGB-encoded colour (filtered encoded, then decoded), linear alpha
    kTexRgba8Linear = 1,  // 8-bit linear values (Non-Color data, linear images)
    kTexRgba32F = 2,      // 32-bit float, scene linear (float images)
};

enum TextureWrap : int32_t { kWrapRepeat = 0, kWrapExtend = 1, kWrapClip = 2, kWrapMirror = 3 };
enum TextureInterp : int32_t { kInterpLinear = 0, kInterpClosest = 1 };
// Which output of the Image Texture node a material input reads
// (colour -> luminance, the alpha output, or one channel after Blender's Separate Color)
enum TextureOutput : int32_t {
    kTexOutColor = 0, kTexOutAlpha = 1, kTexOutRed = 2, kTexOutGreen = 3, kTexOutBlue = 4
};

struct Texture {
    uint64_t offset;       // byte offset of texel (0, 0) in the pool
    int32_t width, height;
    int32_t format;        // TextureFormat
    int32_t wrap;          // TextureWrap
    int32_t interp;        // TextureInterp
    int32_t output;        // TextureOutput: what scalar inputs (roughness, metallic, alpha) read
    float uv[6];           // affine uv transform (Blender's Mapping node): u' = uv[0] u + uv[1] v
                           // + uv[2], v' = uv[3] u + uv[4] v + uv[5]
};

// The sRGB transfer function's inverse (IEC 61966-2-1) for an encoded value in [0, 1].
LANTERN_HD inline float srgb_decode(float c) {
    return c <= 0.04045f ? c * (1.0f / 12.92f) : powf((c + 0.055f) * (1.0f / 1.055f), 2.4f);
}

// One texel with wrapping; false outside the image for kWrapClip (transparent black there).
LANTERN_HD inline bool texture_wrap(int32_t wrap, int i, int n, int& out) {
    switch (wrap) {
    case kWrapExtend:
        out = min_int(max_int(i, 0), n - 1);
        return true;
    case kWrapClip:
        out = i;
        return i >= 0 && i < n;
    case kWrapMirror: {
        int period = 2 * n;
        int k = i % period;
        if (k < 0) k += period;
        out = k < n ? k : period - 1 - k;
        return true;
    }
    default: {
        int k = i % n;
        out = k < 0 ? k + n : k;
        return true;
    }
    }
}

LANTERN_HD inline Vec4 texture_texel(const Texture& t, const uint8_t* pool, const float* srgb_lut,
                                     int x, int y) {
    int xi, yi;
    bool in_x = texture_wrap(t.wrap, x, t.width, xi);
    bool in_y = texture_wrap(t.wrap, y, t.height, yi);
    if (!in_x || !in_y) return Vec4{};
    const size_t idx = size_t(yi) * size_t(t.width) + size_t(xi);
    if (t.format == kTexRgba32F) {
        const float* p = reinterpret_cast<const float*>(pool + t.offset) + 4 * idx;
        return Vec4{p[0], p[1], p[2], p[3]};
    }
    const uint8_t* p = pool + t.offset + 4 * idx;
    const float a = float(p[3]) * (1.0f / 255.0f);
    if (t.format == kTexRgba8Srgb)
        return Vec4{srgb_lut[p[0]], srgb_lut[p[1]], srgb_lut[p[2]], a};
    return Vec4{float(p[0]) * (1.0f / 255.0f), float(p[1]) * (1.0f / 255.0f),
                float(p[2]) * (1.0f / 255.0f), a};
}

// The filtered value at texture coordinates st (before the texture's own uv transform).
// Out of line on the device: one copy per kernel for ptxas instead of one per texture read
// (docs/cuda_backend.md, "Build time").
#ifdef __CUDA_ARCH__
__noinline__
#endif
LANTERN_HD inline Vec4 texture_lookup(const Texture& t, const uint8_t* pool, const float* srgb_lut,
                                      Vec2 st) {
    float u = t.uv[0] * st.x + t.uv[1] * st.y + t.uv[2];
    float v = t.uv[3] * st.x + t.uv[4] * st.y + t.uv[5];
    if (!is_finite(u) || !is_finite(v)) return Vec4{};
    // keep the integer part in range before converting (a huge u would overflow int);
    // repeat and mirror are periodic, extend and clip saturate anyway
    const float lim = 1e6f;
    if (fabsf(u) > lim || fabsf(v) > lim) {
        if (t.wrap == kWrapRepeat || t.wrap == kWrapMirror) {
            float pu = t.wrap == kWrapMirror ? 2.0f : 1.0f;
            u -= pu * floorf(u / pu);
            v -= pu * floorf(v / pu);
        } else {
            u = clampf(u, -2.0f, 3.0f);
            v = clampf(v, -2.0f, 3.0f);
        }
    }
    float x = u * float(t.width), y = v * float(t.height);
    if (t.interp == kInterpClosest)
        return texture_texel(t, pool, srgb_lut, int(floorf(x)), int(floorf(y)));
    x -= 0.5f;
    y -= 0.5f;
    float fx = floorf(x), fy = floorf(y);
    int x0 = int(fx), y0 = int(fy);
    float ax = x - fx, ay = y - fy;
    // 8-bit sRGB images are filtered in their encoded values and decoded afterwards, as
    // Cycles does (it keeps them as bytes): between a black and a white texel, halfway is
    // decode(0.5) = 0.21, not 0.5 (measured against Cycles: docs/materials_vs_cycles.md)
    const float* lut = t.format == kTexRgba8Srgb ? nullptr : srgb_lut;
    Texture raw = t;
    if (t.format == kTexRgba8Srgb) raw.format = kTexRgba8Linear;
    Vec4 a = texture_texel(raw, pool, lut, x0, y0);
    Vec4 b = texture_texel(raw, pool, lut, x0 + 1, y0);
    Vec4 c = texture_texel(raw, pool, lut, x0, y0 + 1);
    Vec4 d = texture_texel(raw, pool, lut, x0 + 1, y0 + 1);
    float w00 = (1 - ax) * (1 - ay), w10 = ax * (1 - ay), w01 = (1 - ax) * ay, w11 = ax * ay;
    Vec4 r{a.x * w00 + b.x * w10 + c.x * w01 + d.x * w11,
           a.y * w00 + b.y * w10 + c.y * w01 + d.y * w11,
           a.z * w00 + b.z * w10 + c.z * w01 + d.z * w11,
           a.w * w00 + b.w * w10 + c.w * w01 + d.w * w11};
    if (t.format == kTexRgba8Srgb) {
        r.x = srgb_decode(r.x);
        r.y = srgb_decode(r.y);
        r.z = srgb_decode(r.z);
    }
    return r;
}

LANTERN_HD inline Vec3 texture_color(Vec4 v) { return Vec3{v.x, v.y, v.z}; }

// What a scalar input (roughness, metallic, alpha) reads: the alpha output, or the colour
// converted to a value as Blender's implicit colour -> float conversion (luminance).
LANTERN_HD inline float texture_scalar(const Texture& t, Vec4 v) {
    switch (t.output) {
    case kTexOutAlpha: return v.w;
    case kTexOutRed: return v.x;
    case kTexOutGreen: return v.y;
    case kTexOutBlue: return v.z;
    default: return luminance(Vec3{v.x, v.y, v.z});
    }
}

}  // namespace lantern
