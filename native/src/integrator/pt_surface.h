// The surface at a path's hit, as pt and the walks that leave surfaces read it: the hit's
// frames (geometric and shading normals, normal maps, tangents for anisotropy), motion, and the
// shade point a material's programs evaluate at. Split out of pt.h (the 600-line mark).
#pragma once

#include "bsdf/material.h"
#include "core/offset.h"
#include "integrator/camera.h"
#include "integrator/path_state.h"
#include "scene/lights.h"

namespace lantern {
struct SurfaceHit {
    Vec3 p;
    Vec3 ng;    // geometric normal, facing the incoming ray
    Vec3 ns;    // shading normal, same hemisphere as ng
    Vec2 st;    // texture coordinates (the mesh's uvs; 0 without)
    bool front; // the ray arrived on the triangle's front (counter-clockwise) side
    float tangent_angle = 0.0f;  // anisotropic materials: the shading frame's turn about ns
    // kCoatNormal: the coat's normal; material_keeps_unbent_normal: the normal before Bump and
    // Normal Map nodes (Cycles' N), both local to frame(); (0, 0, 1) where unbent
    Vec3 coat_n{0.0f, 0.0f, 1.0f};
    LANTERN_HD Frame frame() const { return Frame::from_normal_angle(ns, tangent_angle); }
};

// A direction leaving a surface is usable when the geometric and the shading normal agree on
// its side (reflection or transmission); otherwise light would leak through the shading normal.
LANTERN_HD inline bool sides_agree(Vec3 w, Vec3 ng, Vec3 ns) {
    return dot(w, ng) * dot(w, ns) > 0.0f;
}
// The same for the view's side w at a light sub-path vertex (its connection to the camera or
// to a camera vertex, the direction it samples): a BSDF that reads the light's side only (a
// Lambert, Cycles' diffuse; a view-corrected glossy material: material_view_geometric) needs the
// reflection's geometric side alone, ng facing the light there.
LANTERN_HD inline bool view_side_agrees(const Material& m, Vec3 w, Vec3 ng, Vec3 ns) {
    return material_view_geometric(m) ? dot(w, ng) > 0.0f : sides_agree(w, ng, ns);
}
// The same for the light's side w at a camera sub-path vertex: a view-corrected glossy material
// (material_corrects_view) reflects light from under its shading normal (its lobes lie about
// the corrected one, its base reads the shading normal itself), so only the geometric side.
LANTERN_HD inline bool light_side_agrees(const Material& m, Vec3 w, Vec3 ng, Vec3 ns) {
    return material_corrects_view(m) ? dot(w, ng) > 0.0f : sides_agree(w, ng, ns);
}

// The uv tangent (direction of increasing u) of triangle tri at barycentrics bary, unit and
// orthogonal to n, and the bitangent's sign: the mesh's per-vertex tangents (MikkTSpace, as
// Blender exports them) or, without, the triangle's uv parametrisation. False when the
// triangle has no usable uv frame.
LANTERN_HD inline bool uv_tangent(const SceneView& s, int tri, Vec2 bary, Vec3 n, Vec3* t_out,
                                  float* sign_out) {
    if (!s.uvs) return false;
    const uint32_t* idx = s.indices + 3 * tri;
    const float w0 = 1.0f - bary.x - bary.y;
    Vec3 t = vec3(0.0f);
    float sign = 1.0f;
    if (s.tangents) {
        const float* t0 = s.tangents + 4 * idx[0];
        const float* t1 = s.tangents + 4 * idx[1];
        const float* t2 = s.tangents + 4 * idx[2];
        t = Vec3{t0[0], t0[1], t0[2]} * w0 + Vec3{t1[0], t1[1], t1[2]} * bary.x +
            Vec3{t2[0], t2[1], t2[2]} * bary.y;
        sign = t0[3] < 0.0f ? -1.0f : 1.0f;
    }
    if (!(length_sq(t) > 1e-20f)) {  // no tangents for this mesh: the uv parametrisation's
        Vec3 p0 = s.positions[idx[0]], p1 = s.positions[idx[1]], p2 = s.positions[idx[2]];
        Vec2 a = s.uvs[idx[0]], b = s.uvs[idx[1]], c = s.uvs[idx[2]];
        float du1 = b.x - a.x, dv1 = b.y - a.y, du2 = c.x - a.x, dv2 = c.y - a.y;
        float det = du1 * dv2 - dv1 * du2;
        if (!(fabsf(det) > 1e-20f)) return false;
        Vec3 e1 = p1 - p0, e2 = p2 - p0;
        t = (e1 * dv2 - e2 * dv1) / det;
        Vec3 bt = (e2 * du1 - e1 * du2) / det;
        sign = dot(cross(n, t), bt) < 0.0f ? -1.0f : 1.0f;
    }
    t = t - n * dot(n, t);
    if (!(length_sq(t) > 1e-20f) || !is_finite(t)) return false;
    *t_out = normalize(t);
    *sign_out = sign;
    return true;
}

// A tangent-space normal map (Blender's Normal Map node, tangent space): colour c (2c - 1 in
// the uv tangent frame) of `strength` applied to the front-side shading normal n of triangle
// tri. Returns n unchanged where the map or the frame is degenerate or would turn the normal
// below the surface. apply_normal_map reads c from a texture, program_normal_map from a graph.
LANTERN_HD inline Vec3 normal_from_tangent_color(const SceneView& s, Vec3 c, float strength,
                                                 int tri, Vec2 bary, Vec3 n, Vec3 ng_front) {
    Vec3 t;
    float sign;
    if (!uv_tangent(s, tri, bary, n, &t, &sign)) return n;
    Vec3 b = cross(n, t) * sign;
    Vec3 mapped = t * (2.0f * c.x - 1.0f) + b * (2.0f * c.y - 1.0f) + n * (2.0f * c.z - 1.0f);
    if (!is_finite(mapped) || !(length_sq(mapped) > 1e-12f)) return n;
    mapped = normalize(mapped);
    if (strength != 1.0f) {
        mapped = n + (mapped - n) * fmaxf(strength, 0.0f);
        if (!is_finite(mapped) || !(length_sq(mapped) > 1e-12f)) return n;
        mapped = normalize(mapped);
    }
    return dot(mapped, ng_front) > 1e-4f ? mapped : n;
}
LANTERN_HD inline Vec3 apply_normal_map(const SceneView& s, int32_t tex_index, float strength,
                                        int tri, Vec2 bary, Vec3 n, Vec3 ng_front, Vec2 st) {
    const Texture& tex = s.textures[tex_index];
    const Vec3 c = texture_color(texture_lookup(tex, s.texels, s.srgb_lut, st));
    return normal_from_tangent_color(s, c, strength, tri, bary, n, ng_front);
}
// The same with the colour from material m's normal-map program (a graph on the Normal Map
// node's Color), evaluated on the surface (the view along n; its Normal reads n); an Object
// or World space map's program gives the normal itself (kTargetNormalMapWorld).
LANTERN_HD inline Vec3 program_normal_map(const SceneView& s, const Material& m, int tri,
                                          Vec2 bary, Vec3 n, Vec3 ng_front) {
    Vec3 c;
    const ShadePoint sp = bump_point(s, tri, bary, n);
    if (program_eval(s, m, kTargetNormalMap, sp, &c))
        return normal_from_tangent_color(s, c, m.normal_strength, tri, bary, n, ng_front);
    if (!program_eval(s, m, kTargetNormalMapWorld, sp, &c)) return n;
    if (!(length_sq(c) > 1e-12f)) return n;
    Vec3 mapped = normalize(c);
    if (m.normal_strength != 1.0f) {
        mapped = n + (mapped - n) * fmaxf(m.normal_strength, 0.0f);
        if (!is_finite(mapped) || !(length_sq(mapped) > 1e-12f)) return n;
        mapped = normalize(mapped);
    }
    return dot(mapped, ng_front) > 1e-4f ? mapped : n;
}

// The anisotropy tangent of an anisotropic material, as the angle from Frame::from_normal(ns)'s
// first axis (0 for isotropic materials, whose lobes do not turn with the frame): a tangent
// program's (an unlinked Tangent input, Cycles' radial tangent about the object's Z; a Radial
// Tangent node), the uv tangent (a Tangent node in UV mode) or the triangle's p0 - p2, turned
// by the material's rotation.
LANTERN_HD inline float anisotropy_angle(const SceneView& s, const Material& m, int tri,
                                         Vec2 bary, Vec3 ns) {
    Vec3 t;
    float sign;
    if ((m.tex_flags & kTexProgram) && program_eval(s, m, kTargetTangent,
                                                    bump_point(s, tri, bary, ns), &t)) {
        t = t - ns * dot(ns, t);   // a program's world tangent (kTargetTangent)
        if (!(length_sq(t) > 1e-20f) || !is_finite(t)) return 0.0f;
    } else if (!(m.aniso_uv_tangent && uv_tangent(s, tri, bary, ns, &t, &sign))) {
        const uint32_t* idx = s.indices + 3 * tri;
        t = s.positions[idx[0]] - s.positions[idx[2]];
        t = t - ns * dot(ns, t);
        if (!(length_sq(t) > 1e-20f) || !is_finite(t)) return 0.0f;
    }
    const Frame f = Frame::from_normal(ns);
    const float angle = atan2f(dot(t, f.t), dot(t, f.s)) + 2.0f * kPi * m.aniso_rotation;
    return is_finite(angle) ? angle : 0.0f;
}

// The material-dependent part of the shading frame (kSceneFrames scenes only, so that the
// common path stays small): a normal map on the front-side normal n, the anisotropy tangent and
// the coat's own normal; node-graph bumps. Never inlined on the host (pt_surface stays small),
// nor on the device (LANTERN_DEVICE_NOINLINE: one copy per shade kernel for ptxas).
#ifndef __CUDA_ARCH__
__attribute__((noinline))
#endif
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline void pt_surface_frames(const SceneView& s, SurfaceHit& h, int tri, Vec2 uv,
                                         Vec3 n, Vec3 ng_front) {
    const Material& m = s.materials[s.tri_material[tri]];
    if (m.tex_flags & kTexBump)  // the Displacement output as bump: Cycles' N itself, first
        n = program_bump(s, m, tri, uv, n, ng_front, kTargetDisplacement);
    const Vec3 n_smooth = n;
    if (m.tex_flags & kTexNormal)
        n = m.tex_normal >= 0 ? apply_normal_map(s, m.tex_normal, m.normal_strength, tri, uv,
                                                 n, ng_front, h.st)
                              : program_normal_map(s, m, tri, uv, n, ng_front);
    if (m.tex_flags & kTexBump) n = program_bump(s, m, tri, uv, n, ng_front);  // node graphs
    h.ns = h.front ? n : -n;
    if (m.anisotropy > 0.0f) h.tangent_angle = anisotropy_angle(s, m, tri, uv, h.ns);
    if (material_keeps_unbent_normal(m) &&
        !(n.x == n_smooth.x && n.y == n_smooth.y && n.z == n_smooth.z)) {
        h.coat_n = normalize(h.frame().to_local(h.front ? n_smooth : -n_smooth));
    } else if (m.tex_flags & kCoatNormal) {  // the coat's own normal: its map, or the smooth normal
        Vec3 nc = m.tex_coat_normal >= 0 ? apply_normal_map(s, m.tex_coat_normal,
                                                             m.coat_normal_strength, tri, uv,
                                                             n_smooth, ng_front, h.st)
                                         : n_smooth;
        h.coat_n = normalize(h.frame().to_local(h.front ? nc : -nc));
    }
}

LANTERN_HD inline SurfaceHit pt_surface(const SceneView& s, int tri, Vec2 uv, Vec3 d) {
    Vec3 a = triangle_vertex(s, tri, 0), b = triangle_vertex(s, tri, 1),
         c = triangle_vertex(s, tri, 2);
    float w0 = 1.0f - uv.x - uv.y;
    SurfaceHit h;
    h.p = a * w0 + b * uv.x + c * uv.y;
    const Vec3 ng_front = normalize(cross(b - a, c - a));
    const uint32_t* idx = s.indices + 3 * tri;
    h.st = triangle_uv(s, tri, uv);
    Vec3 n = ng_front;  // the shading normal on the front side
    if (s.normals) {
        Vec3 ni = s.normals[idx[0]] * w0 + s.normals[idx[1]] * uv.x + s.normals[idx[2]] * uv.y;
        if (is_finite(ni) && length_sq(ni) > 1e-12f) {
            ni = normalize(ni);
            n = dot(ni, ng_front) < 0.0f ? -ni : ni;
        }
    }
    h.front = dot(ng_front, d) <= 0.0f;
    h.ng = h.front ? ng_front : -ng_front;
    h.ns = h.front ? n : -n;
    // (the mapped normal depends on the surface point only, never on the arriving direction:
    // camera and light sub-paths see the same BSDF, as BDPT's MIS needs; docs/materials.md)
    if (s.material_bits & kSceneFrames) pt_surface_frames(s, h, tri, uv, n, ng_front);
    return h;
}

// The hit at the path's time where meshes move (motion blur, scene/motion.h); out of line on
// the host, so that pt_shade's still path stays as it was, and on the device (ptxas).
#ifndef __CUDA_ARCH__
__attribute__((noinline))
#endif
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline SurfaceHit pt_surface_moved(const SceneView& s, int tri, Vec2 uv, Vec3 d,
                                              const Rng& rng) {
    return motion_surface<SurfaceHit>(
        s.motion, tri, uv, d, motion_time(rng),
        [&](Vec3 dx) { return pt_surface(s, tri, uv, dx); },
        [&](Vec3 e[3]) {
            for (int j = 0; j < 3; ++j) e[j] = s.positions[s.indices[3 * tri + j]];
        });
}

// What node-graph programs read at the hit (scene/material_program.h); wo: towards the viewer.
LANTERN_HD inline ShadePoint shade_point(const SurfaceHit& h, int tri, Vec2 bary, Vec3 wo) {
    ShadePoint sp;
    sp.p = h.p;
    sp.n = h.ns;
    sp.ng = h.ng;
    sp.wo = wo;
    sp.st = h.st;
    sp.tri = tri;
    sp.bary = bary;
    sp.backfacing = !h.front;
    return sp;
}

}  // namespace lantern
