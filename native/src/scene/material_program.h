// A material's compiled node graph (addon/export/material_compile.py) and its evaluation at a
// shading point. One program per material input it drives (MaterialProgram::target); a program
// is a register program of plain instructions: registers 0..num_const-1 start as its
// constants, each instruction reads its inputs from one block of registers (its op fixes the
// layout) and writes its outputs to another. A switch over ops, no allocation, no virtuals.
// Only the programs of a hit's material run, and only the inputs a hit reads: material_at
// evaluates the shading targets, alpha.h the alpha, lights.h the emission.
#pragma once

#include "scene/material_program_ops.h"

namespace lantern {

// kTargetBump: a Bump node on the shading normal; its result is (height, strength, distance
// signed by Invert), run by program_bump, not at material_at. kTargetDisplacement: the
// Material Output's Displacement as bump, the same result; it bends Cycles' N itself, which
// node graphs read (program_graph_normal), before normal maps and Bump nodes.
enum ProgramTarget : uint32_t {
    kTargetBaseColor = 0, kTargetRoughness = 1, kTargetMetallic = 2, kTargetEmission = 3,
    kTargetAlpha = 4, kTargetMixFactor = 5, kTargetBump = 6, kTargetDisplacement = 7,
    kTargetNormalMap = 8, kTargetNormalMapWorld = 9, kTargetTangent = 10, kTargetDensity = 11,
    kTargetVolumeEmission = 12, kTargetVolumeColor = 13, kTargetVolumeEmissionColor = 14,
    kTargetVolumeAbsorptionColor = 15, kTargetCount = 16,
};
// kTargetVolumeColor: the Color of a volume's scattering or absorbing shader driven by a graph
// (scene/medium_hetero.h medium_coeffs_at: scattering color_scatter x c, absorption
// color_absorb x max(1 - c, 0)); kTargetVolumeEmissionColor: its Emission Color (Principled
// Volume) or an Emission shader's Color (scene/medium_fire.h medium_emission_at). Both run at
// points inside the medium, of a mesh volume or a Volume object. kTargetVolumeAbsorptionColor:
// Principled Volume's Absorption Color a (absorption color_absorb x max(1 - c, 0) x
// max(1 - sqrt(a), 0), c the colour program's or color_base).
// kTargetVolumeEmission: the Emission Strength of a Volume object's volume shader driven by a
// graph of its grids (scene/medium_fire.h medium_emission_at), run at points inside the medium.
// kTargetDensity: the Density of a material's volume shader (a heterogeneous medium,
// scene/medium_hetero.h), run at points inside the medium, never at a surface hit.
// kTargetTangent: the anisotropy tangent, a world direction (an unlinked Tangent input's
// default, Cycles' radial tangent about the object's Z axis, or a Tangent node in Radial
// mode), read by pt.h anisotropy_angle in place of the uv or triangle tangent.
// kTargetNormalMap: the Color of a tangent-space Normal Map node driven by a graph;
// kTargetNormalMapWorld: an Object or World space Normal Map's normal, already a world
// direction (the add-on compiles the colour's decoding and the object's normal matrix into
// it). The material then has kTexNormal with tex_normal -1 (pt.h program_normal_map).

struct MaterialProgram {
    int32_t first_instr, num_instr;
    int32_t first_const, num_const;   // preloaded into registers 0..num_const-1
    int32_t target;                   // ProgramTarget
    int32_t result;                   // register of the result (3 floats for colours)
};

// Runs program p at sp on register file r (material_program_ops.h: float* or ProgramRegs);
// its result (3 floats; scalars repeat in y, z unless the op wrote 3). program_run's body,
// a function of its own so that tests run the device's register file on the CPU.
template <typename R>
__attribute__((always_inline)) LANTERN_HD inline Vec3 program_run_on(const SceneView& s,
                                                                     const MaterialProgram& p,
                                                                     const ShadePoint& sp, R r) {
    const int nc = min_int(p.num_const, kProgramRegs);
    for (int i = 0; i < nc; ++i) r[i] = s.program_consts[p.first_const + i];
    for (int i = 0; i < p.num_instr; ++i)
        program_step(s, sp, s.program_code[p.first_instr + i], r);
    if (p.result < 0 || p.result + 3 > kProgramRegs) return Vec3{};
    Vec3 v = reg3(r, p.result);
    // NaN and infinities never leave a program (huge values are clamped by the caller)
    return Vec3{is_finite(v.x) ? v.x : 0.0f, is_finite(v.y) ? v.y : 0.0f,
                is_finite(v.z) ? v.z : 0.0f};
}

// Runs program p at sp. Never inlined: on the host a call keeps the op switch and its 192
// registers (a stack array) out of the stages that reach it (a diffuse-only scene's shading
// stage paid for their inlined copies). On the device the registers are the thread's column
// of SceneView::program_regs (global memory the CUDA renderer allocates when the scene has
// programs), not 768 B of every shade kernel's stack frame; its index is the thread's index
// in the launch, which CudaExec::each keeps below the buffer's stride (a grid-stride loop),
// and no program runs inside another, so one column per thread is enough. sp by value: a
// call site's shading point then travels as a parameter, where by reference each of a
// kernel's call sites kept its own copy in local memory.
__attribute__((noinline))
LANTERN_HD inline Vec3 program_run(const SceneView& s, const MaterialProgram& p,
                                   const ShadePoint sp) {
#ifdef __CUDA_ARCH__
    const uint32_t t = launch_thread(s.program_regs, s.device_threads);
    return program_run_on(s, p, sp, ProgramRegs{s.program_regs + t, s.device_threads});
#else
    float r[kProgramRegs];
    return program_run_on(s, p, sp, r);
#endif
}

LANTERN_HD inline bool program_has_target(const MaterialProgram* programs, const Material& m,
                                          uint32_t target) {
    if (!(m.tex_flags & kTexProgram)) return false;
    for (int i = 0; i < m.prog_count; ++i)
        if (uint32_t(programs[m.prog_first + i].target) == target) return true;
    return false;
}

// The value of the program of material m driving `target`; false when m has none.
LANTERN_HD inline bool program_eval(const SceneView& s, const Material& m, uint32_t target,
                                    const ShadePoint& sp, Vec3* out) {
    for (int i = 0; i < m.prog_count; ++i) {
        const MaterialProgram& p = s.programs[m.prog_first + i];
        if (uint32_t(p.target) == target) {
            *out = program_run(s, p, sp);
            return true;
        }
    }
    return false;
}

// The shading point of triangle tri at barycentrics bary seen from direction wo (towards the
// viewer), for the places that have no SurfaceHit: alpha tests and light samples.
LANTERN_HD inline ShadePoint shade_point_on_triangle(const SceneView& s, int32_t tri, Vec2 bary,
                                                     Vec3 wo) {
    const uint32_t* idx = s.indices + 3 * tri;
    const float w0 = 1.0f - bary.x - bary.y;
    const Vec3 a = s.positions[idx[0]], b = s.positions[idx[1]], c = s.positions[idx[2]];
    ShadePoint sp;
    sp.p = a * w0 + b * bary.x + c * bary.y;
    Vec3 ng = normalize(cross(b - a, c - a));
    sp.backfacing = dot(ng, wo) < 0.0f;
    Vec3 n = ng;
    if (s.normals) {
        const Vec3 ni = s.normals[idx[0]] * w0 + s.normals[idx[1]] * bary.x +
                        s.normals[idx[2]] * bary.y;
        if (is_finite(ni) && length_sq(ni) > 1e-12f) n = normalize(ni);
        if (dot(n, ng) < 0.0f) n = -n;
    }
    sp.ng = sp.backfacing ? -ng : ng;
    sp.n = sp.backfacing ? -n : n;
    sp.wo = wo;
    sp.tri = tri;
    sp.bary = bary;
    sp.st = Vec2{};
    if (s.uvs)
        sp.st = Vec2{s.uvs[idx[0]].x * w0 + s.uvs[idx[1]].x * bary.x + s.uvs[idx[2]].x * bary.y,
                     s.uvs[idx[0]].y * w0 + s.uvs[idx[1]].y * bary.x + s.uvs[idx[2]].y * bary.y};
    return sp;
}

// ---- Bump ----
// Cycles evaluates the height at the shading point and at offsets along its screen-space
// differentials dP/dx, dP/dy (times the node's Filter Width) and forms the normal of the
// bumped surface from the two differences. Lantern keeps no ray differentials; it takes the
// same formula over two offsets along the triangle's own edges, in barycentrics (so that
// every input a height graph reads, position, uv, attributes, moves consistently), each
// kBumpStep long in world units relative to the point's magnitude: a forward-difference
// estimate of the surface gradient, which converges to the gradient Cycles' finite
// differences estimate when the height is smooth at the scale of a pixel's tenth. Heights
// with detail finer than that differ (Cycles' then depend on the resolution; docs/nodes.md).
constexpr float kBumpStep = 2e-4f;

// The shading point of triangle tri at bary with normal n (front side) and the view along n:
// height graphs see the surface, not the path (the bumped normal is a property of the point,
// as BDPT's MIS needs).
LANTERN_HD inline ShadePoint bump_point(const SceneView& s, int32_t tri, Vec2 bary, Vec3 n) {
    ShadePoint sp = shade_point_on_triangle(s, tri, bary, n);
    sp.n = n;
    sp.wo = n;
    return sp;
}

// The front-side shading normal n of triangle tri at bary bent by material m's bump programs
// of `target` (kTargetBump, in order: a Bump fed by another Bump; or kTargetDisplacement); n
// unchanged where the result is degenerate or would face below the surface (as for normal
// maps).
LANTERN_HD inline Vec3 program_bump(const SceneView& s, const Material& m, int32_t tri,
                                    Vec2 bary, Vec3 n, Vec3 ng_front,
                                    uint32_t target = kTargetBump) {
    const uint32_t* idx = s.indices + 3 * tri;
    const Vec3 a = s.positions[idx[0]];
    const Vec3 e1 = s.positions[idx[1]] - a, e2 = s.positions[idx[2]] - a;
    const Vec3 p = a + e1 * bary.x + e2 * bary.y;
    const float step =
        kBumpStep * fmaxf(1.0f, fmaxf(fabsf(p.x), fmaxf(fabsf(p.y), fabsf(p.z))));
    const float l1 = length(e1), l2 = length(e2);
    if (!(l1 > 0.0f) || !(l2 > 0.0f)) return n;
    const float du = step / l1, dv = step / l2;
    const Vec3 dpdx = e1 * du, dpdy = e2 * dv;   // the two offsets, world units
    for (int i = 0; i < m.prog_count; ++i) {
        const MaterialProgram& prog = s.programs[m.prog_first + i];
        if (uint32_t(prog.target) != target) continue;
        const Vec3 c = program_run(s, prog, bump_point(s, tri, bary, n));
        const float hx =
            program_run(s, prog, bump_point(s, tri, Vec2{bary.x + du, bary.y}, n)).x;
        const float hy =
            program_run(s, prog, bump_point(s, tri, Vec2{bary.x, bary.y + dv}, n)).x;
        // the bumped surface's normal from the two differences [Cycles' Bump node; Mikkelsen,
        // "Bump Mapping Unparametrized Surfaces on the GPU", 2010, eq. 4]
        const Vec3 rx = cross(dpdy, n), ry = cross(n, dpdx);
        const float det = dot(dpdx, rx);
        const Vec3 grad = rx * (hx - c.x) + ry * (hy - c.x);
        const float strength = fmaxf(c.y, 0.0f);
        Vec3 nb = n * fabsf(det) - grad * (c.z * (det < 0.0f ? -1.0f : 1.0f));
        if (!is_finite(nb) || !(length_sq(nb) > 0.0f)) continue;
        nb = normalize(nb);
        nb = nb * strength + n * (1.0f - strength);
        if (!is_finite(nb) || !(length_sq(nb) > 1e-24f)) continue;
        nb = normalize(nb);
        if (dot(nb, ng_front) > 1e-4f) n = nb;
    }
    return n;
}

// The normal node graphs read at sp (Blender's Geometry > Normal; the default Normal of
// Fresnel, Layer Weight, Bump): Cycles' N, the interpolated normal bent by the Material
// Output's Displacement (as bump) alone. Bump and Normal Map nodes bend the normal of the
// BSDFs they feed, not this one (measured with bpy 5.0.1 and Cycles: test_nodes.py
// geometry_normal_*). On sp's side; sp.n where sp has no triangle.
LANTERN_HD inline Vec3 program_graph_normal(const SceneView& s, const Material& m,
                                            const ShadePoint& sp) {
    if (sp.tri < 0) return sp.n;
    const uint32_t* idx = s.indices + 3 * sp.tri;
    const float w0 = 1.0f - sp.bary.x - sp.bary.y;
    const Vec3 a = s.positions[idx[0]], b = s.positions[idx[1]], c = s.positions[idx[2]];
    const Vec3 ng_front = normalize(cross(b - a, c - a));
    if (!is_finite(ng_front)) return sp.n;
    Vec3 n = ng_front;
    if (s.normals) {
        const Vec3 ni = s.normals[idx[0]] * w0 + s.normals[idx[1]] * sp.bary.x +
                        s.normals[idx[2]] * sp.bary.y;
        if (is_finite(ni) && length_sq(ni) > 1e-12f) n = normalize(ni);
        if (dot(n, ng_front) < 0.0f) n = -n;
    }
    if (m.tex_flags & kTexBump)
        n = program_bump(s, m, sp.tri, sp.bary, n, ng_front, kTargetDisplacement);
    return sp.backfacing ? -n : n;
}

// Emitted radiance of material m at triangle tri, bary, seen from wo: its emission program
// there, else material_emission (texture or constant). Never inlined on the host (only
// textured and node-graph emitters reach it: lights.h triangle_emission).
#ifndef __CUDA_ARCH__
__attribute__((noinline))
#endif
LANTERN_HD inline Vec3 material_emission_at(const SceneView& s, const Material& m, int32_t tri,
                                            Vec2 bary, Vec3 wo) {
    Vec3 e;
    if (!(m.tex_flags & kTexProgram)) return material_emission(s, m, triangle_uv(s, tri, bary));
    ShadePoint sp = shade_point_on_triangle(s, tri, bary, wo);
    if (m.tex_flags & kTexBump) sp.n = program_graph_normal(s, m, sp);  // Cycles' N
    if (program_eval(s, m, kTargetEmission, sp, &e))
        return Vec3{clampf(e.x, 0.0f, 1e30f), clampf(e.y, 0.0f, 1e30f), clampf(e.z, 0.0f, 1e30f)};
    return material_emission(s, m, triangle_uv(s, tri, bary));
}

// Alpha (coverage) of material m's alpha program at tri, bary; false when it has none.
LANTERN_HD inline bool program_alpha(const SceneView& s, const Material& m, int32_t tri,
                                     Vec2 bary, Vec3 wo, float* alpha) {
    Vec3 a;
    if (!(m.tex_flags & kTexProgram) ||
        !program_eval(s, m, kTargetAlpha, shade_point_on_triangle(s, tri, bary, wo), &a))
        return false;
    *alpha = a.x >= 0.0f ? fminf(a.x, 1.0f) : 0.0f;
    return true;
}

}  // namespace lantern
