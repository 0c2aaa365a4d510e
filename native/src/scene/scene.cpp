// HostScene from a SceneInput: the constructor (materials converted and checked, then the
// parts in order: tables, textures, programs, meshes, lights, filter, view), the pixel filter,
// the view the stages read (and its copy for a GPU), the viewport's camera edit. The parts live
// beside it: scene_materials.cpp, scene_meshes.cpp, scene_lights.cpp, material_program.cpp.
#include "scene/scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "integrator/camera.h"
#include "bsdf/material.h"
#include "scene/medium_fire.h"
#include "scene/scene_checks.h"
#include "scene/scene_limits.h"
#include "scene/subsurface_input.h"

namespace lantern {

Transform transform_from_rows(const float m[16]) {
    Transform t;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) t.m[r][c] = m[4 * r + c];
    }
    return t;
}

namespace {

// The texture indices of a material and its alpha; an index out of range is a clear error.
void set_material_textures(Material& m, const MaterialInput& mi, size_t k, size_t num_textures,
                           std::vector<std::string>& warnings) {
    auto check = [&](int t, const char* what, uint32_t bit, int32_t& out) {
        if (t < 0) return;
        if (size_t(t) >= num_textures) {
            throw std::invalid_argument("material " + std::to_string(k) + " ('" + mi.name +
                                        "'): " + what + " texture " + std::to_string(t) +
                                        " out of range (scene has " +
                                        std::to_string(num_textures) + " textures)");
        }
        out = t;
        m.tex_flags |= bit;
    };
    check(mi.tex_base_color, "base_color", kTexBaseColor, m.tex_base_color);
    check(mi.tex_roughness, "roughness", kTexRoughness, m.tex_roughness);
    check(mi.tex_metallic, "metallic", kTexMetallic, m.tex_metallic);
    check(mi.tex_alpha, "alpha", kTexAlpha, m.tex_alpha);
    check(mi.tex_normal, "normal", kTexNormal, m.tex_normal);
    check(mi.tex_emission, "emission", kTexEmission, m.tex_emission);
    m.emission_scale = m.emission;  // with an emission texture: its multiplier
    m.normal_strength = finite_in(mi.normal_strength, 0.0f, kInf, 1.0f);
    // the coat's own normal: its map, or the smooth normal under a mapped base (Cycles: an
    // unlinked Coat Normal is the interpolated normal, not the base's)
    m.tex_coat_normal = -1;
    int32_t coat_tex = -1;
    check(mi.tex_coat_normal, "coat_normal", 0u, coat_tex);
    if (m.type == kMaterialPrincipled && m.coat_weight > 0.0f &&
        (coat_tex >= 0 || (m.tex_flags & kTexNormal))) {
        m.tex_coat_normal = coat_tex;
        m.tex_flags |= kCoatNormal;
    }
    m.coat_normal_strength = finite_in(mi.coat_normal_strength, 0.0f, 1e3f, 1.0f);
    float alpha = finite_in(mi.alpha, 0.0f, 1.0f, 1.0f);
    if (!std::isfinite(mi.alpha))
        warnings.push_back("material '" + mi.name + "': alpha is not finite; opaque instead");
    m.transparency = 1.0f - alpha;
    m.holdout = mi.holdout ? 1u : 0u;
    if ((m.tex_flags & kTexMetallic) && m.type == kMaterialConductor) {
        // a metallic texture needs the principled layers; the conductor type has none
        m.tex_flags &= ~kTexMetallic;
        warnings.push_back("material '" + mi.name + "': a metallic texture on a conductor is "
                           "ignored (fully metallic)");
    }
}

// Depth of field, made safe: f-stop 0 (a huge radius) stays finite, focus distance 0 becomes
// Cycles' 1e-5 m, a bad ratio 1; the lens is a pinhole for orthographic cameras (warned).
void set_lens(const SceneInput& in, CameraView& c, std::vector<std::string>& warnings) {
    c.panoramic = in.panoramic && !in.orthographic ? 1 : 0;
    if (c.panoramic) {  // ranges clamped to the sphere; an empty one becomes the full sphere
        float lo = finite_in(in.pano_range[0], -kPi, kPi, -kPi);
        float hi = finite_in(in.pano_range[1], -kPi, kPi, kPi);
        float la = finite_in(in.pano_range[2], -0.5f * kPi, 0.5f * kPi, -0.5f * kPi);
        float lb = finite_in(in.pano_range[3], -0.5f * kPi, 0.5f * kPi, 0.5f * kPi);
        if (!(hi > lo)) lo = -kPi, hi = kPi;
        if (!(lb > la)) la = -0.5f * kPi, lb = 0.5f * kPi;
        const float r[4] = {lo, hi, la, lb};
        for (int k = 0; k < 4; ++k) c.pano_range[k] = r[k];
    }
    c.lens_radius = finite_in(in.lens_radius, 0.0f, 1e6f, 0.0f);
    c.focus_distance = finite_in(in.focus_distance, 1e-5f, 1e30f, 10.0f);
    c.blades = in.aperture_blades >= 3 ? std::min(in.aperture_blades, 1000) : 0;
    c.blade_rotation = finite_in(in.aperture_rotation, -1e4f, 1e4f, 0.0f);
    c.inv_aperture_ratio = 1.0f / finite_in(in.aperture_ratio, 1e-3f, 1e3f, 1.0f);
    if (c.lens_radius > 0.0f && (c.orthographic || c.panoramic)) {
        warnings.push_back(std::string("depth of field on ") +
                           (c.panoramic ? "a panoramic" : "an orthographic") +
                           " camera is not supported; rendered sharp");
        c.lens_radius = 0.0f;
    }
}

// principled_coat_table, kept per process: the coat's albedo is a function of its roughness
// and IOR alone (a quadrature per cosine, ~20 ms a material), which a scene's coats mostly
// share and every new session of the same scene repeats.
void cached_coat_table(const Material& m, MaterialTables& tab) {
    using Row = std::array<float, kPrincipledAlbedoN>;
    static std::mutex lock;
    static std::map<std::pair<float, float>, Row> rows;
    const std::pair<float, float> key(m.coat_roughness, m.coat_ior);
    {
        std::lock_guard<std::mutex> hold(lock);
        auto it = rows.find(key);
        if (it != rows.end()) {
            std::copy(it->second.begin(), it->second.end(), tab.coat_albedo);
            return;
        }
    }
    principled_coat_table(m, tab);
    Row row;
    std::copy(tab.coat_albedo, tab.coat_albedo + kPrincipledAlbedoN, row.begin());
    std::lock_guard<std::mutex> hold(lock);
    if (rows.size() >= 4096) rows.clear();  // a bound for sessions that sweep the coat
    rows.emplace(key, row);
}

}  // namespace

HostScene::HostScene(const SceneInput& in, bool soft_light_paths)
    : soft_light_paths_(soft_light_paths) {
    textures_in_count_ = in.textures.size();
    if (in.width <= 0 || in.height <= 0 || in.width > 65536 || in.height > 65536) {
        throw std::invalid_argument("film size must be between 1 and 65536 pixels, got " +
                                    std::to_string(in.width) + "x" + std::to_string(in.height));
    }
    check_film_memory(in.width, in.height);  // before anything of the film's size is allocated
    for (size_t k = 0; k < in.materials.size(); ++k) {
        const MaterialInput& mi = in.materials[k];
        Material m{};
        MaterialTables tab{};  // m's until the loop ends, then material_tables_[k]
        m.tables = &tab;
        // an albedo alone (Diffuse, Translucent BSDF, a principled with no metal or glass
        // anywhere: Metallic and Transmission 0, no texture or program on Metallic) is used
        // as given, above 1 too, as Cycles does (a closure weight; its Principled clamps the
        // base colour only as the metal's F0, the glass tint and subsurface); where the base
        // colour is also a Fresnel F0 or a tint it stays within [0, 1]
        bool drives_metallic = false;
        for (int i = 0; i < mi.program_count && mi.program_first >= 0; ++i) {
            const size_t at = 6 * (size_t(mi.program_first) + size_t(i)) + 4;
            drives_metallic |= at < in.programs.size() && in.programs[at] == kTargetMetallic;
        }
        const bool albedo_only =
            mi.type == "diffuse" || mi.type == "translucent" ||
            (mi.type == "principled" && !(mi.metallic > 0.0f) && !(mi.transmission > 0.0f) &&
             mi.tex_metallic < 0 && !drives_metallic);
        m.base_color = sanitize_color(mi.base_color, albedo_only ? 1e30f : 1.0f);
        m.emission = sanitize_color(mi.emission, 1e30f);
        m.specular_tint = sanitize_color(mi.specular_tint, 1.0f);
        // NaN roughness -> 0.5, NaN/absurd ior -> 1.5; roughness clamps to [0, 1], ior to
        // [1/100, 100] (ior < 1, e.g. air bubbles in water, is legal)
        m.roughness = finite_in(mi.roughness, 0.0f, 1.0f, 0.5f);
        m.anisotropy = finite_in(mi.anisotropy, 0.0f, 1.0f, 0.0f);
        m.aniso_rotation = std::isfinite(mi.anisotropic_rotation)
                               ? mi.anisotropic_rotation - std::floor(mi.anisotropic_rotation)
                               : 0.0f;
        if (mi.tangent != "uv" && mi.tangent != "triangle") {
            throw std::invalid_argument("material " + std::to_string(k) + " ('" + mi.name +
                                        "'): unknown tangent '" + mi.tangent +
                                        "' (uv, triangle)");
        }
        m.aniso_uv_tangent = mi.tangent == "uv" ? 1u : 0u;
        m.diffuse_roughness = finite_in(mi.diffuse_roughness, 0.0f, 1.0f, 0.0f);
        m.ior = std::isfinite(mi.ior) && mi.ior > 0.0f ? std::min(std::max(mi.ior, 0.01f), 100.0f) : 1.5f;
        // complex Fresnel: eta >= 0 (fresnel_conductor keeps it above 1e-4), k >= 0; a
        // non-finite entry falls back to a perfect mirror (eta 0, k 1)
        m.fresnel = mi.complex_fresnel ? kFresnelComplex : kFresnelF82Tint;
        float eta[3], kk[3];
        for (int c = 0; c < 3; ++c) {
            bool ok = std::isfinite(mi.eta[c]) && std::isfinite(mi.k[c]);
            eta[c] = ok ? std::min(std::max(mi.eta[c], 0.0f), 1e4f) : 0.0f;
            kk[c] = ok ? std::min(std::max(mi.k[c], 0.0f), 1e4f) : 1.0f;
        }
        m.eta = {eta[0], eta[1], eta[2]};
        m.k = {kk[0], kk[1], kk[2]};
        if (mi.distribution != "ggx" && mi.distribution != "beckmann") {
            throw std::invalid_argument("material " + std::to_string(k) + " ('" + mi.name +
                                        "'): unknown distribution '" + mi.distribution +
                                        "' (ggx, beckmann)");
        }
        m.beckmann = mi.distribution == "beckmann" ? 1u : 0u;
        // Thin Film (principled specular layer and metal, conductors): NaN or negative
        // thickness -> none; above 100 um no interference is left to see, so clamp there
        m.film_thickness = finite_in(mi.thin_film_thickness, 0.0f, 1e5f, 0.0f);
        m.film_ior = finite_in(mi.thin_film_ior, 1.0f, 100.0f, 1.33f);
        if (mi.type == "diffuse") {
            m.type = kMaterialDiffuse;
        } else if (mi.type == "conductor") {
            m.type = kMaterialConductor;
        } else if (mi.type == "dielectric") {
            m.type = kMaterialDielectric;
        } else if (mi.type == "translucent") {
            m.type = kMaterialTranslucent;
        } else if (mi.type == "mix") {
            m.type = kMaterialMix;  // leaves checked below, once every material exists
        } else if (mi.type == "hair") {
            set_hair_material(m, mi);
        } else if (mi.type == "principled") {
            m.type = kMaterialPrincipled;
            auto unit = [](float v, float fallback) { return finite_in(v, 0.0f, 1.0f, fallback); };
            m.metallic = unit(mi.metallic, 0.0f);
            m.transmission = unit(mi.transmission, 0.0f);
            // Blender's Specular IOR Level scales F0 of the IOR (0.5: unchanged, 0: none)
            const float level = finite_in(mi.specular_level, 0.0f, kInf, 0.5f);
            const float ior = std::max(m.ior, 1.0f / m.ior);
            float f0 = ((ior - 1.0f) / (ior + 1.0f)) * ((ior - 1.0f) / (ior + 1.0f));
            f0 = std::min(f0 * 2.0f * level, 0.99f);
            const float r = std::sqrt(f0);
            m.spec_eta = (1.0f + r) / (1.0f - r);
            m.coat_weight = unit(mi.coat_weight, 0.0f);
            m.coat_roughness = unit(mi.coat_roughness, 0.03f);
            m.coat_ior = finite_in(mi.coat_ior, 1.0f, 100.0f, 1.5f);
            m.coat_tint = sanitize_color(mi.coat_tint, 1.0f);
            if (m.coat_weight > 0.0f) cached_coat_table(m, tab);
            m.sheen_weight = finite_in(mi.sheen_weight, 0.0f, kInf, 0.0f);
            m.sheen_roughness = unit(mi.sheen_roughness, 0.5f);
            m.sheen_tint = sanitize_color(mi.sheen_tint, 1.0f);
            if (m.sheen_weight > 0.0f) principled_sheen_table(m, tab);
            set_material_subsurface(m, mi, k, warnings_);
        } else {
            throw std::invalid_argument("material " + std::to_string(k) + " ('" + mi.name +
                                        "'): unknown type '" + mi.type +
                                        "' (diffuse, conductor, dielectric, principled, mix, translucent, hair)");
        }
        // GGX multiple-scattering compensation (the compensation tables are GGX's: a Beckmann
        // conductor goes without, as Mitsuba); its tables are made once the node programs
        // have set the material's inputs (fill_lobe_tables)
        m.multiscatter = mi.multiscatter && !m.beckmann ? 1u : 0u;
        set_material_textures(m, mi, k, in.textures.size(), warnings_);
        if (albedo_only) m.tex_flags |= kAlbedoBase;
        if (m.type == kMaterialDielectric && mi.tint_reflection) m.tex_flags |= kTintReflection;
        materials_.push_back(m);
        material_tables_.push_back(tab);
    }
    if (materials_.empty()) {
        Material m{};
        m.base_color = {0.8f, 0.8f, 0.8f};
        m.type = kMaterialDiffuse;
        m.roughness = 0.5f;
        m.ior = 1.5f;
        m.specular_tint = {1.0f, 1.0f, 1.0f};
        m.fresnel = kFresnelF82Tint;
        materials_.push_back(m);
        material_tables_.push_back(MaterialTables{});
    }
    point_material_tables();
    set_mix_leaves(in);
    add_textures(in);
    finish_emission_textures();
    add_programs(in);
    fill_lobe_tables();
    add_meshes(in);
    add_curves(in);
    add_lights(in);
    build_light_linking(in);
    add_curve_prims(in);
    drop_redundant_shadow_links();
    build_lamp_rays(in);
    build_filter(in.filter_width);
    finish_view(in);
    build_media(in);
    build_motion(in);
}

// Inverted CDF of the Blackman-Harris filter: maps u in [0,1] to an offset in pixels. As in
// Cycles, Blender's filter width w spans the window [-w, w] (measured against bpy 5.0.1: edge
// pixels of a plane that ends at the image border match Cycles only with this width).
void HostScene::build_filter(float filter_width) {
    if (!(filter_width > 0.0f) || !std::isfinite(filter_width)) filter_width = 1.5f;
    const float width = 2.0f * std::min(filter_width, 16.0f);
    const int fine = 16384, table = 4096;
    std::vector<double> cdf(fine + 1, 0.0);
    for (int k = 0; k < fine; ++k) {
        float x = -0.5f * width + width * (float(k) + 0.5f) / float(fine);
        cdf[k + 1] = cdf[k] + std::max(0.0f, blackman_harris(x, width));
    }
    filter_cdf_.resize(table);
    int j = 0;
    for (int i = 0; i < table; ++i) {
        double target = cdf[fine] * double(i) / double(table - 1);
        while (j < fine && cdf[j + 1] < target) ++j;
        double seg = cdf[j + 1] - cdf[j];
        double f = seg > 0.0 ? (target - cdf[j]) / seg : 0.0;
        filter_cdf_[i] = float(-0.5 * width + width * (double(j) + std::min(1.0, std::max(0.0, f))) / fine);
    }
}

// Keep in step with finish_view: every pointer of SceneView (and CameraView) is copied here.
SceneView HostScene::copied_view(
    const std::function<const void*(const void*, size_t)>& copy) const {
    auto put = [&](const auto* host, size_t count) {
        using T = std::remove_cv_t<std::remove_pointer_t<decltype(host)>>;
        return static_cast<const T*>(host && count ? copy(host, count * sizeof(T)) : nullptr);
    };
    SceneView v = view_;
    v.positions = put(view_.positions, positions_.size());
    v.normals = put(view_.normals, normals_.size());
    v.uvs = put(view_.uvs, uvs_.size());
    v.tangents = put(view_.tangents, tangents_.size());
    v.textures = put(view_.textures, textures_.size());
    v.texels = put(view_.texels, texels_.size());
    v.srgb_lut = put(view_.srgb_lut, srgb_lut_.size());
    v.indices = put(view_.indices, indices_.size());
    v.tri_material = put(view_.tri_material, tri_material_.size());
    v.tri_flags = put(view_.tri_flags, tri_flags_.size());
    v.tri_rays = put(view_.tri_rays, tri_rays_.size());
    v.tri_light_set = put(view_.tri_light_set, tri_light_set_.size());
    v.light_receivers = put(view_.light_receivers, light_receivers_.size());
    v.light_rays = put(view_.light_rays, light_rays_.size());
    v.tri_shadow_set = put(view_.tri_shadow_set, tri_shadow_set_.size());
    v.tri_terminator = put(view_.tri_terminator, tri_terminator_.size());
    v.light_blockers = put(view_.light_blockers, light_blockers_.size());
    v.tri_light = put(view_.tri_light, tri_light_.size());
    // the materials point at their tables: the copies point at the copied tables
    v.material_tables = put(view_.material_tables, material_tables_.size());
    std::vector<Material> rebased(materials_);
    for (size_t k = 0; k < rebased.size(); ++k)
        rebased[k].tables = v.material_tables ? v.material_tables + k : nullptr;
    v.materials = put(rebased.data(), rebased.size());
    v.lights = put(view_.lights, lights_.size());
    v.light_cdf = put(view_.light_cdf, light_cdf_.size());
    v.nee_cdf = put(view_.nee_cdf, nee_cdf_.size());
    v.emit_cdf = put(view_.emit_cdf, emit_cdf_.size());
    v.light_tree = put(view_.light_tree, light_tree_.nodes.size());
    v.distant_lights = put(view_.distant_lights, light_tree_.distant.size());
    v.hittable_lights = put(view_.hittable_lights, hittable_lights_.size());
    v.miss_lights = put(view_.miss_lights, miss_lights_.size());
    v.camera.filter_cdf = put(view_.camera.filter_cdf, filter_cdf_.size());
    v.programs = put(view_.programs, programs_.size());
    v.program_code = put(view_.program_code, program_code_.size());
    v.program_consts = put(view_.program_consts, program_consts_.size());
    v.attributes = put(view_.attributes, attributes_.size());
    v.env.texels = put(view_.env.texels, env_->texels.size());
    v.env.marginal = put(view_.env.marginal, env_->marginal.size());
    v.env.conditional = put(view_.env.conditional, env_->conditional.size());
    v.media = put(view_.media, media_.size());
    v.material_medium = put(view_.material_medium, material_medium_.size());
    v.light_medium = put(view_.light_medium, light_medium_.size());
    v.medium_maps = put(view_.medium_maps, medium_maps_.size());
    v.grids = put(view_.grids, grids_.size());
    v.grid_voxels = put(view_.grid_voxels, grid_voxels_.size());
    v.majorant_grids = put(view_.majorant_grids, majorant_grids_.size());
    v.majorant_values = put(view_.majorant_values, majorant_values_.size());
    v.blackbody_table = put(view_.blackbody_table, view_.blackbody_table ? 3 * kBlackbodyKnots : 0);
    v.motion.steps = put(view_.motion.steps, motion_steps_.size());
    v.motion.objects = put(view_.motion.objects, motion_objects_.size());
    v.motion.medium_objects = put(view_.motion.medium_objects, motion_media_.size());
    v.curves.segs = put(view_.curves.segs, curve_segs_.size());
    v.curves.keys.keys = put(view_.curves.keys.keys, curve_keys_.size());
    v.curves.sets = put(view_.curves.sets, curve_sets_.size());
    v.motion.deforms = put(view_.motion.deforms, motion_deforms_.size());
    v.motion.deform_corners = put(view_.motion.deform_corners, motion_corners_.size());
    return v;
}

void HostScene::finish_view(const SceneInput& in) {
    SceneView& v = view_;
    v.positions = positions_.data();
    v.normals = normals_.empty() ? nullptr : normals_.data();
    v.uvs = uvs_.empty() ? nullptr : uvs_.data();
    v.tangents = tangents_.empty() ? nullptr : tangents_.data();
    v.textures = textures_.empty() ? nullptr : textures_.data();
    v.texels = texels_.empty() ? nullptr : texels_.data();
    v.srgb_lut = srgb_lut_.data();
    v.num_textures = int32_t(textures_.size());
    v.indices = indices_.data();
    v.tri_material = tri_material_.data();
    v.tri_flags = tri_flags_.data();
    v.tri_rays = tri_rays_.empty() ? nullptr : tri_rays_.data();
    v.tri_light_set = tri_light_set_.empty() ? nullptr : tri_light_set_.data();
    v.light_receivers = light_receivers_.empty() ? nullptr : light_receivers_.data();
    v.light_rays = light_rays_.empty() ? nullptr : light_rays_.data();
    // (tri_rays_ is built only where some mesh is hidden from some kind; light_rays_ also where
    // a lamp only casts no shadow, which hides it from no kind)
    v.rays_hidden = !tri_rays_.empty() ||
                    std::any_of(light_rays_.begin(), light_rays_.end(), [](uint8_t r) {
                        return (r & kRayKindsAll) != kRayKindsAll;
                    });
    v.tri_shadow_set = tri_shadow_set_.empty() ? nullptr : tri_shadow_set_.data();
    v.tri_terminator = tri_terminator_.empty() ? nullptr : tri_terminator_.data();
    v.light_blockers = light_blockers_.empty() ? nullptr : light_blockers_.data();
    v.tri_light = tri_light_.data();
    v.num_triangles = int32_t(indices_.size() / 3);  // tri_material_ holds the strands' too
    v.curves.segs = curve_segs_.empty() ? nullptr : curve_segs_.data();
    v.curves.num_segs = int32_t(curve_segs_.size());
    v.curves.keys = CurveKeys{curve_keys_.empty() ? nullptr : curve_keys_.data(),
                              curve_keys_.empty() ? 0 : curve_steps_, v.curves.num_segs};
    v.materials = materials_.data();
    v.material_tables = material_tables_.data();
    v.num_materials = int32_t(materials_.size());
    v.material_bits = 0;
    v.has_subsurface = 0;
    if (const char* c = std::getenv("LANTERN_SSS_ADJOINT")) {  // tests' controls (lt_sss.h,
        const std::string k = c;                                  // bdpt_sss_light.h)
        v.sss_adjoint_control = k == "lambert"    ? 1
                                : k == "nocos"    ? 2
                                : k == "nosplit"  ? 3
                                : k == "nomedium" ? 5
                                : k == "nodirect" ? 6
                                                  : 4;
    }
    if (const char* c = std::getenv("LANTERN_LT_STRAND"))  // tests' control (lt_strand.h)
        v.lt_strand_control = std::string(c) == "nothrough" ? 1 : 0;
    for (const Material& m : materials_) {
        if (m.subsurface > 0.0f) v.has_subsurface = 1;
        if (m.tex_flags & kMaterialResolve) v.material_bits |= kSceneResolve;
        if ((m.tex_flags & (kTexNormal | kCoatNormal | kTexBump)) || m.anisotropy > 0.0f)
            v.material_bits |= kSceneFrames;
        if (m.tex_flags & kTexProgram) v.material_bits |= kScenePrograms;
    }
    v.no_shadow_objects = 0;
    for (uint8_t f : tri_flags_)
        if (!(f & kCastShadow)) {
            v.no_shadow_objects = 1;
            break;
        }
    v.programs = programs_.empty() ? nullptr : programs_.data();
    v.program_code = program_code_.empty() ? nullptr : program_code_.data();
    v.program_consts = program_consts_.empty() ? nullptr : program_consts_.data();
    v.attributes = attributes_.empty() ? nullptr : attributes_.data();
    v.num_attribute_channels = attributes_.empty() ? 0 : num_attribute_channels_;
    v.env = env_->view;
    v.lights = lights_.data();
    v.light_cdf = light_cdf_.data();
    v.nee_cdf = has_nee_lights_ ? nee_cdf_.data() : nullptr;
    v.emit_cdf = has_emitters_ ? emit_cdf_.data() : nullptr;
    v.num_lights = int32_t(lights_.size());
    v.light_tree_on = light_tree_on_ ? 1 : 0;
    v.catcher_mode = in.catcher_mode >= kCatcherMatte && in.catcher_mode <= kCatcherPass
                         ? in.catcher_mode : kCatcherMatte;
    v.world_rays = in.world_rays & kWorldRaysAll;
    v.light_tree = light_tree_.nodes.empty() ? nullptr : light_tree_.nodes.data();
    v.num_tree_nodes = int32_t(light_tree_.nodes.size());
    v.distant_lights = light_tree_.distant.empty() ? nullptr : light_tree_.distant.data();
    v.num_distant_lights = int32_t(light_tree_.distant.size());
    for (size_t k = 0; k < lights_.size(); ++k) {
        const Light& l = lights_[k];
        bool sphere = (l.type == kLightPoint || l.type == kLightSpot) && l.radius > 0.0f;
        if (sphere || l.type == kLightArea) hittable_lights_.push_back(int32_t(k));
        if (l.type == kLightWorld || (l.type == kLightSun && l.cos_sun < 1.0f)) {
            miss_lights_.push_back(int32_t(k));
        }
    }
    v.hittable_lights = hittable_lights_.data();
    v.num_hittable_lights = int32_t(hittable_lights_.size());
    v.miss_lights = miss_lights_.data();
    v.num_miss_lights = int32_t(miss_lights_.size());
    CameraView& c = v.camera;
    c.orthographic = in.orthographic ? 1 : 0;
    c.width = in.width;
    c.height = in.height;
    c.to_world = rigid(in.camera_to_world);
    if (!within_limit(c.to_world.origin()) && is_finite(c.to_world.origin())) {
        warnings_.push_back("the camera is " + format_metres(distance_from_origin(c.to_world.origin())) +
                            " m from the origin, beyond the " + format_metres(kMaxCoordinate) +
                            " m the ray queries can take; its rays start where they reach the "
                            "scene's bounds");
    }
    for (int k = 0; k < 4; ++k) c.screen[k] = in.screen[k];
    c.clip_start = std::max(0.0f, in.clip_start);
    c.clip_end = in.clip_end > c.clip_start ? in.clip_end : kInf;
    c.filter_cdf = filter_cdf_.data();
    c.filter_table_size = int32_t(filter_cdf_.size());
    c.filter_width = in.filter_width;
    set_lens(in, c, warnings_);
}

// The viewport's camera moves without a rebuild (Session::update_camera): the same fields as
// finish_view sets, from a SceneInput of which only the film and camera are read.
void HostScene::set_camera(const SceneInput& in) {
    if (in.width <= 0 || in.height <= 0 || in.width > 65536 || in.height > 65536) {
        throw std::invalid_argument("film size must be between 1 and 65536 pixels, got " +
                                    std::to_string(in.width) + "x" + std::to_string(in.height));
    }
    if (in.filter_width != view_.camera.filter_width) build_filter(in.filter_width);
    CameraView& c = view_.camera;
    c.orthographic = in.orthographic ? 1 : 0;
    c.width = in.width;
    c.height = in.height;
    c.to_world = rigid(in.camera_to_world);
    for (int k = 0; k < 4; ++k) c.screen[k] = in.screen[k];
    c.clip_start = std::max(0.0f, in.clip_start);
    c.clip_end = in.clip_end > c.clip_start ? in.clip_end : kInf;
    c.filter_cdf = filter_cdf_.data();
    c.filter_table_size = int32_t(filter_cdf_.size());
    c.filter_width = in.filter_width;
    if (!media_.empty()) view_.camera_medium = camera_medium_at(c.to_world.origin());
}

}  // namespace lantern
