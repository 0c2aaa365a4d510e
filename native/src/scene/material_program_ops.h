// Node programs, the machine: what a program reads at a hit (ShadePoint), its ops and
// their register layouts (NodeOp), and program_step, one instruction over the register
// file. material_program.h runs programs and applies them (bump, emission, alpha).
#pragma once

#include "scene/material_program_tex.h"
#include "scene/scene_view.h"

namespace lantern {

constexpr int kProgramRegs = 192;  // floats per evaluation (the compiler stays below)

// What a node graph can read at a hit.
struct ShadePoint {
    Vec3 p;        // world position
    Vec3 n;        // shading normal, turned to the side the path arrived from (Cycles' N)
    Vec3 ng;       // geometric normal, same side
    Vec3 wo;       // unit direction towards the viewer (Cycles' I)
    Vec2 st;       // the mesh's uv map
    int32_t tri;   // triangle, -1 when unknown (attributes then read 0), -2 - k: a point
                   // inside heterogeneous medium k (scene/medium_hetero.h)
    Vec2 bary;     // barycentrics of vertices 1 and 2
    bool backfacing;
};

// Per-vertex attribute channel c (3 floats) of the hit's triangle, interpolated.
LANTERN_HD inline Vec3 shade_attribute(const SceneView& s, const ShadePoint& sp, int c) {
    if (sp.tri <= -2) {  // a point inside heterogeneous medium -2 - tri: the channel's map
        if (!s.medium_maps || c < 0 || c >= s.num_attribute_channels) return Vec3{};
        return s.medium_maps[size_t(-2 - sp.tri) * size_t(s.num_attribute_channels) + size_t(c)]
            .point(sp.p);
    }
    if (sp.tri < 0 || !s.attributes || c < 0 || c >= s.num_attribute_channels) return Vec3{};
    const uint32_t* idx = s.indices + 3 * sp.tri;
    const float w[3] = {1.0f - sp.bary.x - sp.bary.y, sp.bary.x, sp.bary.y};
    Vec3 r{};
    const size_t stride = size_t(3) * size_t(s.num_attribute_channels);
    for (int k = 0; k < 3; ++k) {
        const float* a = s.attributes + size_t(idx[k]) * stride + 3 * c;
        r += Vec3{a[0], a[1], a[2]} * w[k];
    }
    return r;
}

// ---- Geometry inputs (kOpInput modes, material_compile.INPUTS) ----
LANTERN_HD inline Vec3 shade_input(const SceneView& s, const ShadePoint& sp, int mode, int aux) {
    switch (mode) {
    case 0: return sp.p;
    case 1: return sp.n;
    case 2: return Vec3{sp.st.x, sp.st.y, 0.0f};
    case 3: return sp.wo;
    case 4: return shade_attribute(s, sp, aux);  // generated, object, colour, ...
    case 5: {  // camera space: x right, y up, z forward (Cycles' camera coordinates)
        const Transform& c = s.camera.to_world;
        const Vec3 d = sp.p - c.origin();
        return Vec3{dot(d, c.axis(0)), dot(d, c.axis(1)), -dot(d, c.axis(2))};
    }
    case 6: {  // window: the point's place on the film in [0, 1]^2
        const Transform& c = s.camera.to_world;
        const Vec3 d = sp.p - c.origin();
        float x = dot(d, c.axis(0)), y = dot(d, c.axis(1)), z = -dot(d, c.axis(2));
        if (!s.camera.orthographic) {
            if (!(z > 0.0f)) return Vec3{};
            x /= z;
            y /= z;
        }
        const float* w = s.camera.screen;
        return Vec3{safe_div(x - w[0], w[1] - w[0]), safe_div(y - w[2], w[3] - w[2]), 0.0f};
    }
    case 7: return sp.n * (2.0f * dot(sp.n, sp.wo)) - sp.wo;  // reflection
    case 8: return sp.ng;
    case 9: return vec3(sp.backfacing ? 1.0f : 0.0f);
    default: return Vec3{};
    }
}

// ---- The program ----
enum NodeOp : uint8_t {
    kOpCopy = 0,       // out[0..dim) = in[0..dim)
    kOpInput,          // mode: shade_input; aux: attribute channel
    kOpMath,           // in: a b c; mode: operation; flags&1 clamp
    kOpVectorMath,     // in: a(3) b(3) c(3) scale; out: vector(3) value
    kOpMix,            // in: fac(3) a(3) b(3); mode: blend; flags: 1 clamp factor, 2 clamp
                       // result, 4 non-uniform factor
    kOpMapRange,       // in: value min max to_min to_max steps (each dim floats)
    kOpClamp,          // in: value min max
    kOpInvert,         // in: fac color(3)
    kOpGamma,          // in: color(3) gamma
    kOpBrightContrast, // in: color(3) bright contrast
    kOpHsv,            // in: hue sat val fac color(3)
    kOpSeparate,       // in: color(3); mode 0 rgb/xyz, 1 hsv, 2 hsl; out 3
    kOpCombine,        // in: 3 floats; mode 0 rgb/xyz, 1 hsv, 2 hsl; out 3
    kOpRgbToBw,        // in: color(3)
    kOpChecker,        // in: vector(3) color1(3) color2(3) scale; out: color(3) fac
    kOpGradient,       // in: vector(3); mode type; out: color(3) fac
    kOpNoise,          // in: vector(3) w scale detail roughness lacunarity offset gain
                       // distortion; mode type; dim; flags&1 normalize, &2 no colour;
                       // out: fac color(3)
    kOpWhiteNoise,     // in: vector(3) w; dim; out: value color(3)
    kOpVoronoi,        // in: vector(3) w scale smoothness exponent randomness; mode feature;
                       // aux metric; dim; out: distance color(3) position(3) w
    kOpWave,           // in: vector(3) scale distortion detail dscale droughness phase;
                       // mode type; aux dir; aux2 profile; out: color(3) fac
    kOpMagic,          // in: vector(3) scale distortion; aux depth; out: color(3) fac
    kOpRamp,           // in: fac; aux: table in consts, aux2: entries; flags&1 interpolate;
                       // out: color(3) alpha
    kOpCurves,         // in: fac color(3); aux: table (n entries of r g b c, then lo hi);
                       // aux2: n; mode 0 rgb, 1 float (reads in[1]); out color(3)
    kOpFresnel,        // in: ior normal(3); out: fac
    kOpLayerWeight,    // in: blend normal(3); out: fresnel facing
    kOpImage,          // in: vector(3), box (mode 1) also normal(3) blend; aux: texture;
                       // mode: projection; out: color(3) alpha
    kOpMapping,        // in: vector(3) location(3) rotation(3) scale(3); mode: type
    kOpNormalize,      // in: vector(3): a unit vector (0 stays 0)
    kOpBrick,          // in: vector(3) color1(3) color2(3) mortar(3) scale mortar_size
                       // mortar_smooth bias brick_width row_height offset squash;
                       // aux offset frequency, aux2 squash frequency; out: color(3) fac
    kOpGrid,           // no inputs (reads the point); aux: SceneView::grids index (-1 or out
                       // of range: 0, a missing attribute); out: color(3) fac: a Volume
                       // object's grid at the point, as an Attribute node reads it (a float
                       // grid's value in all three, a colour grid's colour and its mean)
};

// NodeInstr::flags bit set by the core's constant folding (material_program.cpp) on an
// instruction whose inputs are all constant: Cycles folds such a node on the host, where a
// Power of 0 to a negative exponent is powf's +inf, not the 0 it gives at render time
constexpr uint8_t kInstrConstant = 0x80;

struct NodeInstr {
    uint8_t op, mode, flags, dim;
    uint16_t in, out;   // first register of the input and output blocks
    int32_t aux, aux2;
};

// The register file program_step works on (R): a float* on the host, a stack array of
// kProgramRegs floats (the generated code of a plain array); on the device a ProgramRegs, one
// thread's column of a device buffer laid out [register][thread] (SceneView::program_regs),
// so that a warp's accesses to one register are consecutive words, as local memory's are, and
// no kernel's stack frame holds the 768 B of registers (docs/cuda_backend.md "Kernel
// resources"). tests/cpp/test_program_regs.cpp runs every op through both on the CPU.
struct ProgramRegs {
    float* p;         // register 0 of this thread
    uint32_t stride;  // floats from one register to the next (threads in the buffer)
    LANTERN_HD float& operator[](int j) const { return p[uint32_t(j) * stride]; }
    LANTERN_HD ProgramRegs operator+(int k) const {
        return ProgramRegs{p + uint32_t(k) * stride, stride};
    }
};

#ifdef __CUDA_ARCH__
// This thread's index in its launch: its column of SceneView's per-thread scratch, of
// `threads` columns (a launch past them is a bug of the launch: the kernel stops).
__device__ inline uint32_t launch_thread(const void* buffer, uint32_t threads) {
    const uint32_t t = blockIdx.x * blockDim.x + threadIdx.x;
    if (!buffer || t >= threads) __trap();
    return t;
}
#endif

template <typename R>
LANTERN_HD inline Vec3 reg3(const R& r, int i) { return Vec3{r[i], r[i + 1], r[i + 2]}; }
template <typename R>
LANTERN_HD inline void set3(const R& r, int i, Vec3 v) {
    r[i] = v.x;
    r[i + 1] = v.y;
    r[i + 2] = v.z;
}

LANTERN_HD inline Vec3 rotate_euler_xyz(Vec3 v, Vec3 a, bool inverse) {
    const float cx = cosf(a.x), sx = sinf(a.x), cy = cosf(a.y), sy = sinf(a.y),
                cz = cosf(a.z), sz = sinf(a.z);
    // R = Rz Ry Rx (Blender's XYZ Euler), rows
    const Vec3 r0{cy * cz, sy * sx * cz - cx * sz, sy * cx * cz + sx * sz};
    const Vec3 r1{cy * sz, sy * sx * sz + cx * cz, sy * cx * sz - sx * cz};
    const Vec3 r2{-sy, cy * sx, cy * cx};
    if (!inverse) return Vec3{dot(r0, v), dot(r1, v), dot(r2, v)};
    return r0 * v.x + r1 * v.y + r2 * v.z;
}

LANTERN_HD inline Vec3 node_mapping(int type, Vec3 v, Vec3 loc, Vec3 rot, Vec3 scale) {
    switch (type) {
    case 1:  // texture: the inverse of point
        return Vec3{safe_div(1.0f, scale.x), safe_div(1.0f, scale.y), safe_div(1.0f, scale.z)} *
               rotate_euler_xyz(v - loc, rot, true);
    case 2: return rotate_euler_xyz(v * scale, rot, false);  // vector
    case 3: return safe_normalize(rotate_euler_xyz(  // normal
                Vec3{safe_div(v.x, scale.x), safe_div(v.y, scale.y), safe_div(v.z, scale.z)},
                rot, false));
    default: return rotate_euler_xyz(v * scale, rot, false) + loc;  // point
    }
}

// One instruction; r: the register file (float* or ProgramRegs, above).
template <typename R>
LANTERN_HD inline void program_step(const SceneView& s, const ShadePoint& sp, const NodeInstr& n,
                                    R r) {
    const R a = r + n.in;  // read only
    const R o = r + n.out;
    switch (n.op) {
    case kOpCopy:
        for (int k = 0; k < n.dim; ++k) o[k] = a[k];
        break;
    case kOpInput: set3(o, 0, shade_input(s, sp, n.mode, n.aux)); break;
    case kOpMath: {
        float v = node_math(n.mode, a[0], a[1], a[2]);
        if ((n.flags & kInstrConstant) && n.mode == 5) v = folded_pow(a[0], a[1], v);
        o[0] = (n.flags & 1) ? clampf(v, 0.0f, 1.0f) : v;
        break;
    }
    case kOpVectorMath: {
        float value;
        Vec3 v = node_vector_math(n.mode, reg3(a, 0), reg3(a, 3), reg3(a, 6), a[9], &value);
        if ((n.flags & kInstrConstant) && n.mode == 27)
            v = Vec3{folded_pow(a[0], a[3], v.x), folded_pow(a[1], a[4], v.y),
                     folded_pow(a[2], a[5], v.z)};
        set3(o, 0, v);
        o[3] = value;
        break;
    }
    case kOpMix: {
        Vec3 t = (n.flags & 4) ? reg3(a, 0) : vec3(a[0]);
        if (n.flags & 1) t = Vec3{clampf(t.x, 0, 1), clampf(t.y, 0, 1), clampf(t.z, 0, 1)};
        Vec3 c;
        if (n.mode == 255 || (n.flags & 4))  // float / vector mix: a lerp per component
            c = reg3(a, 3) * (vec3(1.0f) - t) + reg3(a, 6) * t;
        else
            c = node_blend(n.mode, t.x, reg3(a, 3), reg3(a, 6));
        if (n.flags & 2) c = Vec3{clampf(c.x, 0, 1), clampf(c.y, 0, 1), clampf(c.z, 0, 1)};
        set3(o, 0, c);
        break;
    }
    case kOpMapRange:
        for (int k = 0; k < n.dim; ++k)
            o[k] = node_map_range(n.mode, n.flags & 1, a[k], a[n.dim + k], a[2 * n.dim + k],
                                  a[3 * n.dim + k], a[4 * n.dim + k], a[5 * n.dim + k]);
        break;
    case kOpClamp: o[0] = node_clamp(n.mode, a[0], a[1], a[2]); break;
    case kOpInvert: set3(o, 0, mix3(reg3(a, 1), vec3(1.0f) - reg3(a, 1), a[0])); break;
    case kOpGamma:
        for (int k = 0; k < 3; ++k) o[k] = a[k] > 0.0f ? powf(a[k], a[3]) : a[k];
        break;
    case kOpBrightContrast: {
        const float ca = 1.0f + a[4], cb = a[3] - a[4] * 0.5f;
        for (int k = 0; k < 3; ++k) o[k] = fmaxf(ca * a[k] + cb, 0.0f);
        break;
    }
    case kOpHsv: {
        const Vec3 in = reg3(a, 4);
        Vec3 h = rgb_to_hsv(in);
        h.x = h.x + a[0] + 0.5f;
        h.x -= floorf(h.x);
        h.y = clampf(h.y * a[1], 0.0f, 1.0f);
        h.z *= a[2];
        Vec3 c = mix3(in, hsv_to_rgb(h), a[3]);
        set3(o, 0, Vec3{fmaxf(c.x, 0.0f), fmaxf(c.y, 0.0f), fmaxf(c.z, 0.0f)});
        break;
    }
    case kOpSeparate:
        set3(o, 0, n.mode == 1 ? rgb_to_hsv(reg3(a, 0))
                               : n.mode == 2 ? rgb_to_hsl(reg3(a, 0)) : reg3(a, 0));
        break;
    case kOpCombine:
        set3(o, 0, n.mode == 1 ? hsv_to_rgb(reg3(a, 0))
                               : n.mode == 2 ? hsl_to_rgb(reg3(a, 0)) : reg3(a, 0));
        break;
    case kOpRgbToBw: o[0] = luminance(reg3(a, 0)); break;
    case kOpChecker: {
        const float f = node_checker(reg3(a, 0) * a[9]);
        set3(o, 0, f == 1.0f ? reg3(a, 3) : reg3(a, 6));
        o[3] = f;
        break;
    }
    case kOpGradient: {
        const float f = node_gradient(n.mode, reg3(a, 0));
        set3(o, 0, vec3(f));
        o[3] = f;
        break;
    }
    case kOpNoise: {
        const float sc = a[4];
        float p[4] = {a[0] * sc, a[1] * sc, a[2] * sc, a[3] * sc};
        if (n.dim == 1) p[0] = a[3] * sc;
        NoiseParams np{clampf(a[5], 0.0f, 15.0f), fmaxf(a[6], 0.0f), a[7], a[8], a[9],
                       n.mode, n.flags & 1};
        Vec3 c{};
        float v;
        noise_texture(p, n.dim, a[10], np, &v, (n.flags & 2) ? nullptr : &c);  // 2: value only
        o[0] = v;
        set3(o, 1, c);
        break;
    }
    case kOpWhiteNoise: {
        Vec3 c;
        o[0] = node_white_noise(reg3(a, 0), a[3], n.dim, &c);
        set3(o, 1, c);
        break;
    }
    case kOpVoronoi: {
        const float sc = a[4];
        const float coord[4] = {a[0] * sc, a[1] * sc, a[2] * sc, a[3] * sc};
        VoronoiOut v = node_voronoi(coord, n.dim, n.mode, n.aux, a[6], clampf(a[7], 0.0f, 1.0f),
                                    clampf(a[5] * 0.5f, 0.0f, 0.5f));
        o[0] = v.distance;
        set3(o, 1, v.color);
        set3(o, 4, Vec3{safe_div(v.position.x, sc), safe_div(v.position.y, sc),
                        safe_div(v.position.z, sc)});
        o[7] = safe_div(v.w, sc);
        break;
    }
    case kOpWave: {
        const float f = node_wave(reg3(a, 0) * a[3], n.mode, n.aux, n.aux2, a[4], a[5], a[6],
                                  a[7], a[8]);
        set3(o, 0, vec3(f));
        o[3] = f;
        break;
    }
    case kOpMagic: {
        const Vec3 c = node_magic(reg3(a, 0) * a[3], n.aux, a[4]);
        set3(o, 0, c);
        o[3] = (c.x + c.y + c.z) * (1.0f / 3.0f);
        break;
    }
    case kOpRamp: {
        float c[4];
        table_lookup(s.program_consts + n.aux, n.aux2, a[0], n.flags & 1, c);
        set3(o, 0, Vec3{c[0], c[1], c[2]});
        o[3] = c[3];
        break;
    }
    case kOpCurves: {
        const float* t = s.program_consts + n.aux;
        const float lo = t[4 * n.aux2], hi = t[4 * n.aux2 + 1];
        if (n.mode == 1) {  // float curve: value in[1]
            o[0] = lerpf(a[1], curve_lookup(t, n.aux2, 0, lo, hi, a[1]), a[0]);
            break;
        }
        const Vec3 in = reg3(a, 1);
        const Vec3 c{curve_lookup(t, n.aux2, 0, lo, hi, in.x),
                     curve_lookup(t, n.aux2, 1, lo, hi, in.y),
                     curve_lookup(t, n.aux2, 2, lo, hi, in.z)};
        set3(o, 0, mix3(in, c, a[0]));
        break;
    }
    case kOpFresnel: o[0] = node_fresnel(a[0], sp.wo, reg3(a, 1), sp.backfacing); break;
    case kOpLayerWeight: {
        float fresnel, facing;
        node_layer_weight(a[0], sp.wo, reg3(a, 1), sp.backfacing, &fresnel, &facing);
        o[0] = fresnel;
        o[1] = facing;
        break;
    }
    case kOpImage: {
        Vec4 c{};
        if (n.aux >= 0 && n.aux < s.num_textures && n.mode == 1) {  // box: up to three sides
            const Texture& t = s.textures[n.aux];
            const Vec3 nb = sp.backfacing ? -reg3(a, 3) : reg3(a, 3);
            const Vec3 w = image_box_weights(nb, a[6]);
            const float wk[3] = {w.x, w.y, w.z};
            for (int k = 0; k < 3; ++k) {
                if (!(wk[k] > 0.0f)) continue;
                const Vec4 q =
                    texture_lookup(t, s.texels, s.srgb_lut, image_box_uv(k, reg3(a, 0), nb));
                c = Vec4{c.x + q.x * wk[k], c.y + q.y * wk[k], c.z + q.z * wk[k],
                         c.w + q.w * wk[k]};
            }
        } else if (n.aux >= 0 && n.aux < s.num_textures) {
            const Texture& t = s.textures[n.aux];
            c = texture_lookup(t, s.texels, s.srgb_lut, image_projection(n.mode, reg3(a, 0)));
        } else {
            c = Vec4{1.0f, 0.0f, 1.0f, 1.0f};  // a missing image: magenta, as Cycles
        }
        set3(o, 0, Vec3{c.x, c.y, c.z});
        o[3] = c.w;
        break;
    }
    case kOpMapping:
        set3(o, 0, node_mapping(n.mode, reg3(a, 0), reg3(a, 3), reg3(a, 6), reg3(a, 9)));
        break;
    case kOpNormalize: set3(o, 0, safe_normalize(reg3(a, 0))); break;
    case kOpBrick: {
        float tint;
        const float f = node_brick(reg3(a, 0) * a[12], a[13], a[14], a[15], a[16], a[17],
                                   a[18], n.aux, a[19], n.aux2, &tint);
        Vec3 c1 = reg3(a, 3);
        if (f != 1.0f) c1 = c1 * (1.0f - tint) + reg3(a, 6) * tint;
        set3(o, 0, mix3(c1, reg3(a, 9), f));
        o[3] = f;
        break;
    }
    case kOpGrid: {
        Vec3 c{};
        if (n.aux >= 0 && n.aux < s.num_grids) {
            const DensityGrid& g = s.grids[n.aux];
            c = g.channels == 3 ? grid_color(g, s.grid_voxels, vec3(0.0f), sp.p).color
                                : vec3(grid_lookup(g, s.grid_voxels, sp.p));
        }
        set3(o, 0, c);
        o[3] = (c.x + c.y + c.z) * (1.0f / 3.0f);
        break;
    }
    default: break;
    }
}

}  // namespace lantern
