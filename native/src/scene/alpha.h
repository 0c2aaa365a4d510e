// Alpha (Blender's Alpha input; coverage): a surface of alpha a stops a ray with probability a
// and is otherwise passed as if absent, for every kind of ray (camera, indirect, light,
// shadow). This is pbrt-v4's stochastic alpha test: the expected image is that of the
// Transparent-BSDF mix Cycles renders, every integrator and its MIS stay unchanged (a passed
// surface is simply not there for that ray), and only triangles flagged kAlphaTested pay for
// it. The decision is a hash of the ray and the triangle, the same on the CPU (an Embree
// filter) and in the BVH traversal, so renders stay deterministic.
#pragma once

#include <cstring>

#include "core/rng.h"
#include "scene/material_program.h"
#include "scene/scene_view.h"
#include "scene/texture.h"

namespace lantern {

LANTERN_HD inline uint32_t float_bits(float f) {
    uint32_t u;
    memcpy(&u, &f, sizeof(u));
    return u;
}

// A uniform number in [0, 1) from the ray and the triangle.
LANTERN_HD inline float alpha_hash(Vec3 o, Vec3 d, int32_t tri) {
    uint64_t h = mix64(uint64_t(float_bits(o.x)) | (uint64_t(float_bits(o.y)) << 32));
    h = mix64(h ^ (uint64_t(float_bits(o.z)) | (uint64_t(float_bits(d.x)) << 32)));
    h = mix64(h ^ (uint64_t(float_bits(d.y)) | (uint64_t(float_bits(d.z)) << 32)));
    h = mix64(h ^ uint64_t(uint32_t(tri)));
    return float(h >> 40) * (1.0f / 16777216.0f);
}

// The coverage of triangle tri at barycentrics (u, v): the alpha texture there, else the
// material's constant alpha; a node-graph alpha program (seen along ray direction d) first.
LANTERN_HD inline float alpha_at(const SceneView& s, int32_t tri, Vec2 bary,
                                 Vec3 d = Vec3{0.0f, 0.0f, -1.0f}) {
    const Material& m = s.materials[s.tri_material[tri]];
    float pa;
    if (program_alpha(s, m, tri, bary, -d, &pa)) return pa;
    if (!(m.tex_flags & kTexAlpha)) return 1.0f - m.transparency;
    const Texture& t = s.textures[m.tex_alpha];
    float a = texture_scalar(t, texture_lookup(t, s.texels, s.srgb_lut, triangle_uv(s, tri, bary)));
    return a >= 0.0f ? fminf(a, 1.0f) : 0.0f;  // NaN -> 0
}

// Whether the ray (o, d) stops at its hit of alpha-tested triangle tri.
LANTERN_HD inline bool alpha_stops(const SceneView& s, int32_t tri, Vec2 bary, Vec3 o, Vec3 d) {
    float a = alpha_at(s, tri, bary, d);
    if (a >= 1.0f) return true;
    if (a <= 0.0f) return false;
    return alpha_hash(o, d, tri) < a;
}

}  // namespace lantern
