// A material at a hit, before its BSDF is evaluated: its typed lobe parameters
// (material_conductor, material_dielectric, material_inputs), its node-graph programs and
// textures applied (material_apply_programs, material_resolve_inputs) and its mix leaves
// resolved (material_resolve, material_at): what bsdf/material.h evaluates. Split from
// material.h along that seam (issue 31); nothing here evaluates a lobe.
#pragma once

#include "bsdf/conductor.h"
#include "bsdf/dielectric.h"
#include "bsdf/lambert.h"
#include "bsdf/multiscatter.h"
#include "bsdf/principled.h"
#include "scene/material_program.h"
#include "scene/texture.h"
#include "scene/scene_view.h"

namespace lantern {

// A conductor's Fresnel is Blender's F82-tint (F0 = base_color) or, with kFresnelComplex, the
// exact one of eta + i k, which base_color then scales (Mitsuba's specular_reflectance).
LANTERN_HD inline ConductorParams material_conductor(const Material& m) {
    ConductorParams p = m.fresnel == kFresnelComplex
                            ? conductor_complex(m.roughness, m.eta, m.k, m.anisotropy)
                            : conductor_f82(m.roughness, m.base_color, m.specular_tint,
                                            m.anisotropy);
    p.beckmann = m.beckmann != 0;
    p.film_thickness = m.film_thickness;
    p.film_ior = m.film_ior;
    return p;
}
LANTERN_HD inline Vec3 material_conductor_scale(const Material& m) {
    return m.fresnel == kFresnelComplex ? m.base_color : vec3(1.0f);
}
LANTERN_HD inline DielectricParams material_dielectric(const Material& m, bool front,
                                                       Transport mode) {
    return dielectric(m.roughness, front ? m.ior : 1.0f / m.ior, mode, m.anisotropy);
}

// What resolving a material at a hit can change (textures, node-graph programs): the rest of
// a resolved copy is the material's own. A mix keeps these for its textured leaves instead of
// whole copies (mix_leaf_at puts them back), so that a GPU thread's scratch holds one Material.
struct MaterialInputs {
    Vec3 base_color, emission, fms_metal, fms_spec;
    float roughness, metallic;
    float mix_weight[2];  // kTargetMixFactor (read only where the material is a mix)
    uint32_t resolved;    // a mix leaf's: 0 when the leaf is the scene's as it is
};
LANTERN_HD inline MaterialInputs material_inputs(const Material& m) {
    MaterialInputs in;
    in.base_color = m.base_color;
    in.emission = m.emission;
    in.fms_metal = m.fms_metal;
    in.fms_spec = m.fms_spec;
    in.roughness = m.roughness;
    in.metallic = m.metallic;
    in.mix_weight[0] = m.mix_weight[0];
    in.mix_weight[1] = m.mix_weight[1];
    in.resolved = 1;
    return in;
}
LANTERN_HD inline void material_set_inputs(Material& m, const MaterialInputs& in) {
    m.base_color = in.base_color;
    m.emission = in.emission;
    m.fms_metal = in.fms_metal;
    m.fms_spec = in.fms_spec;
    m.roughness = in.roughness;
    m.metallic = in.metallic;
    m.mix_weight[0] = in.mix_weight[0];
    m.mix_weight[1] = in.mix_weight[1];
}

// Room for what material_at resolves: a copy of the material and, for a mix, its leaves'
// inputs. Left uninitialised (Material is trivially copyable and only ever assigned whole), so
// that the common untextured hit pays nothing for it. 376 + 4 x 68 = 648 bytes on the host
// (with whole leaves 5 x 368 = 1,840): the albedo tables, which resolution never changes,
// stay in the scene (Material::tables). On the device 376: a GPU thread's resolved mix
// leaves are whole Materials in its slot of SceneView::mix_leaves (material_resolve), not on
// the shade kernels' stack, and no leaf is copied where it is evaluated.
struct MaterialScratch {
    union {
        Material m;
    };
#ifndef __CUDA_ARCH__
    MaterialInputs leaf[kMixLeaves];
#endif
    LANTERN_HD MaterialScratch() {}
};

// Leaf i of the resolved mix m: the scene's leaf, or its copy in `tmp` with the inputs
// material_at resolved for it.
LANTERN_HD inline const Material& mix_leaf_at(const Material& m, int i, Material& tmp) {
#ifdef __CUDA_ARCH__
    (void)tmp;  // the device's resolved leaves are whole already (MaterialScratch)
    return *m.mix_leaf[i];
#else
    if (!m.mix_inputs || !m.mix_inputs[i].resolved) return *m.mix_leaf[i];
    tmp = *m.mix_leaf[i];
    material_set_inputs(tmp, m.mix_inputs[i]);
    return tmp;
#endif
}

// The inputs node-graph programs drive (kTexProgram), written into `out` (m's inputs, maybe
// already textured): only the targets m has programs for run (NaN -> 0 inside program_run,
// then clamped to the input's range, as textures are).
LANTERN_HD inline void material_apply_programs(const SceneView& s, const Material& m,
                                               const ShadePoint& sp, MaterialInputs& out) {
    auto unit = [](float v) { return v >= 0.0f ? fminf(v, 1.0f) : 0.0f; };
    for (int i = 0; i < m.prog_count; ++i) {
        const MaterialProgram& p = s.programs[m.prog_first + i];
        // alpha.h reads the alpha where rays are traced, pt_surface_frames the bump
        if (p.target == kTargetAlpha || p.target == kTargetBump ||
            p.target == kTargetDisplacement || p.target == kTargetNormalMap ||
            p.target == kTargetNormalMapWorld || p.target == kTargetTangent ||
            p.target == kTargetDensity || p.target >= int32_t(kTargetVolumeEmission))
            continue;  // (the volume targets run inside media: medium_hetero.h, medium_fire.h)
        const Vec3 v = program_run(s, p, sp);
        switch (p.target) {
        case kTargetBaseColor: {
            // an albedo alone above 1 as Cycles uses it (kAlbedoBase, scene.cpp)
            const Vec3 c = (m.tex_flags & kAlbedoBase) ? Vec3{fmaxf(v.x, 0.0f), fmaxf(v.y, 0.0f), fmaxf(v.z, 0.0f)}
                                       : Vec3{unit(v.x), unit(v.y), unit(v.z)};
            out.base_color = c;
            Vec3 favg = m.metal_favg0 + (m.metal_favg1 - m.metal_favg0) * c;
            out.fms_metal = ms_fresnel_from_average(favg, m.e_avg);
            break;
        }
        case kTargetRoughness: out.roughness = unit(v.x); break;
        case kTargetMetallic: out.metallic = unit(v.x); break;
        case kTargetEmission: {
            // a non-finite emission (a degenerate graph's +inf) is none, as Cycles' film drops a
            // non-finite contribution (difftest D23); negatives are 0 (docs/nodes.md, D17)
            auto em = [](float x) { return x >= 0.0f && x < kInf ? fminf(x, 1e30f) : 0.0f; };
            out.emission = Vec3{em(v.x), em(v.y), em(v.z)};
            break;
        }
        case kTargetMixFactor: {
            const float f = unit(v.x);
            out.mix_weight[0] = 1.0f - f;
            out.mix_weight[1] = f;
            break;
        }
        default: break;
        }
    }
}

// The multiple-scattering Fresnels of m at a per-hit roughness (its tables' rough_rows): E_avg
// from the roughness rows, the metal's average Fresnel at the hit's base colour (affine in it),
// the specular layer's its own. The lobes read E(mu) and the layer's albedo from the rows too
// (ms_white_albedo, principled_spec_albedo), so no table is that of the socket's hidden value.
LANTERN_HD inline void material_rough_fms(const Material& m, MaterialInputs& out) {
    if (!m.tables || !m.tables->rough_rows || !m.multiscatter) return;
    const float e_avg =
        ms_rough(m, out.roughness, [](const MaterialTables& t) { return t.e_avg; });
    out.fms_metal = ms_fresnel_from_average(
        m.metal_favg0 + (m.metal_favg1 - m.metal_favg0) * out.base_color, e_avg);
    out.fms_spec = ms_fresnel_from_average(m.tables->spec_favg, e_avg);
}

// The inputs of material m (not a mix, with kTexShading) at shading point sp: `out` starts as
// m's own and takes the texture and program values (NaN -> 0, clamped to their ranges). Where
// the roughness is per hit, the tables are read at it (rough_rows; material_rough_fms). Out of
// line on the device (LANTERN_DEVICE_NOINLINE): the camera shade kernel resolved at five sites.
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline void material_resolve_inputs(const SceneView& s, const Material& m,
                                               const ShadePoint& sp, MaterialInputs& out) {
    out = material_inputs(m);
    const Vec2 st = sp.st;
    auto unit = [](float v) { return v >= 0.0f ? fminf(v, 1.0f) : 0.0f; };  // NaN -> 0
    if (m.tex_flags & kTexRoughness) {
        const Texture& t = s.textures[m.tex_roughness];
        out.roughness = unit(texture_scalar(t, texture_lookup(t, s.texels, s.srgb_lut, st)));
    }
    if (m.tex_flags & kTexMetallic) {
        const Texture& t = s.textures[m.tex_metallic];
        out.metallic = unit(texture_scalar(t, texture_lookup(t, s.texels, s.srgb_lut, st)));
    }
    if (m.tex_flags & kTexEmission) out.emission = material_emission(s, m, st);
    if (m.tex_flags & kTexBaseColor) {
        const Texture& t = s.textures[m.tex_base_color];
        Vec3 c = texture_color(texture_lookup(t, s.texels, s.srgb_lut, st));
        c = Vec3{unit(c.x), unit(c.y), unit(c.z)};
        out.base_color = c;
        // the metal's multiple-scattering Fresnel follows F0 = base colour (affine in F0)
        Vec3 favg = m.metal_favg0 + (m.metal_favg1 - m.metal_favg0) * c;
        out.fms_metal = ms_fresnel_from_average(favg, m.e_avg);
    }
    if (m.tex_flags & kTexProgram) material_apply_programs(s, m, sp, out);
    material_rough_fms(m, out);
}

// Material m (not a mix) at shading point sp: m itself when none of its BSDF inputs is
// textured or driven by a node graph (no copy: untextured scenes pay nothing), else a copy in
// `scratch` with the resolved inputs.
LANTERN_HD inline const Material& material_resolve_leaf(const SceneView& s, const Material& m,
                                                        const ShadePoint& sp, Material& scratch) {
    if (!(m.tex_flags & kTexShading)) return m;
    MaterialInputs in;
    material_resolve_inputs(s, m, sp, in);
    scratch = m;
    material_set_inputs(scratch, in);
    return scratch;
}

// material_at's resolution (textures, programs; a mix with its leaves), kept out of its
// inlined check: never inlined on the host, so that the stages of a scene without textures,
// programs or mixes carry none of it (bench/material_cost.py; docs/nodes.md "Cost").
#ifndef __CUDA_ARCH__
__attribute__((noinline))
#endif
LANTERN_HD inline const Material& material_resolve(const SceneView& s, const Material& m,
                                                   const ShadePoint& sp_hit,
                                                   MaterialScratch& scratch) {
    // a bumped or normal-mapped hit's shading normal is not the one node graphs read
    ShadePoint sp = sp_hit;
    if (m.tex_flags & (kTexBump | kTexNormal)) sp.n = program_graph_normal(s, m, sp_hit);
    if (m.type != kMaterialMix) return material_resolve_leaf(s, m, sp, scratch.m);
    scratch.m = m;
#ifdef __CUDA_ARCH__
    // this thread's slot of SceneView::mix_leaves holds its textured leaves, resolved whole:
    // one resolved mix per thread at a time, as one MaterialScratch per shade kernel (the
    // camera kernel's, bdpt.h kOneScratch, resolves the camera vertex's again after a cache
    // vertex's took it)
    scratch.m.mix_inputs = nullptr;
    for (int i = 0; i < m.mix_count; ++i) {
        const Material& leaf = s.materials[m.mix_child[i]];
        scratch.m.mix_leaf[i] = &leaf;
        if (!(leaf.tex_flags & kTexShading)) continue;
        Material& own =
            s.mix_leaves[size_t(launch_thread(s.mix_leaves, s.device_threads)) * kMixLeaves + i];
        MaterialInputs in;
        material_resolve_inputs(s, leaf, sp, in);
        own = leaf;
        material_set_inputs(own, in);
        scratch.m.mix_leaf[i] = &own;
    }
#else
    scratch.m.mix_inputs = scratch.leaf;
    for (int i = 0; i < m.mix_count; ++i) {
        const Material& leaf = s.materials[m.mix_child[i]];
        scratch.m.mix_leaf[i] = &leaf;
        scratch.leaf[i].resolved = 0;
        if (leaf.tex_flags & kTexShading) material_resolve_inputs(s, leaf, sp, scratch.leaf[i]);
    }
#endif
    if (m.tex_flags & kTexMix) {
        const Texture& t = s.textures[m.tex_mix];
        float f = texture_scalar(t, texture_lookup(t, s.texels, s.srgb_lut, sp.st));
        f = f >= 0.0f ? fminf(f, 1.0f) : 0.0f;
        scratch.m.mix_weight[0] = 1.0f - f;
        scratch.m.mix_weight[1] = f;
    }
    if (m.tex_flags & kTexProgram) {
        MaterialInputs in = material_inputs(scratch.m);
        material_apply_programs(s, m, sp, in);
        material_set_inputs(scratch.m, in);
    }
    return scratch.m;
}

// The material of id at shading point sp, ready for material_eval / material_sample: the
// scene's own entry, or a resolved copy in `scratch` (textures, node-graph programs; a mix
// with its leaves). The check is all a scene without textures, programs or mixes runs
// (measured: bench/material_cost.py).
LANTERN_HD inline const Material& material_at(const SceneView& s, uint32_t id,
                                              const ShadePoint& sp, MaterialScratch& scratch) {
    const Material& m = s.materials[id];
    if (!(s.material_bits & kSceneResolve) || !(m.tex_flags & kMaterialResolve)) return m;
    return material_resolve(s, m, sp, scratch);
}

// The same with the shading point built only when the material needs resolving: make() ->
// ShadePoint (a lambda; a diffuse-only scene never builds one).
template <class MakeShadePoint>
LANTERN_HD inline const Material& material_at_point(const SceneView& s, uint32_t id,
                                                    const MakeShadePoint& make,
                                                    MaterialScratch& scratch) {
    const Material& m = s.materials[id];
    if (!(s.material_bits & kSceneResolve) || !(m.tex_flags & kMaterialResolve)) return m;
    return material_resolve(s, m, make(), scratch);
}

// The same at texture coordinates st alone (no position: programs reading geometry see 0).
LANTERN_HD inline const Material& material_at(const SceneView& s, uint32_t id, Vec2 st,
                                              MaterialScratch& scratch) {
    ShadePoint sp{};
    sp.st = st;
    sp.tri = -1;
    sp.n = sp.ng = sp.wo = Vec3{0.0f, 0.0f, 1.0f};
    return material_at(s, id, sp, scratch);
}

}  // namespace lantern
