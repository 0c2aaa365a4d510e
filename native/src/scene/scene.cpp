#include "scene/scene.h"

#include <algorithm>
#include <cstring>
#include <cmath>
#include <cstdlib>
#include <initializer_list>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "integrator/camera.h"
#include "bsdf/material.h"
#include "integrator/light_path.h"
#include "scene/scene_limits.h"

namespace lantern {

namespace {

// A scalar input: clamped to [lo, hi] when finite, `fallback` when NaN or infinite.
float finite_in(float v, float lo, float hi, float fallback) {
    return std::isfinite(v) ? std::min(std::max(v, lo), hi) : fallback;
}

Vec3 sanitize_color(Vec3 c, float hi) {
    auto f = [hi](float v) { return finite_in(v, 0.0f, hi, 0.0f); };
    return {f(c.x), f(c.y), f(c.z)};
}

// Rotation part of a row-major 4x4 with its scale removed (Gram-Schmidt on the columns).
Transform rigid(const float m[16]) {
    Transform t = transform_from_rows(m);
    Vec3 x = normalize(t.axis(0));
    Vec3 y = t.axis(1) - x * dot(t.axis(1), x);
    y = normalize(y);
    Vec3 z = cross(x, y);
    if (dot(z, t.axis(2)) < 0.0f) z = -z;
    Vec3 cols[3] = {x, y, z};
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) t.m[r][c] = cols[c][r];
    }
    return t;
}

}  // namespace

Transform transform_from_rows(const float m[16]) {
    Transform t;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) t.m[r][c] = m[4 * r + c];
    }
    return t;
}

namespace {

// The index of `value` in `names` (an enum's order), or a clear error naming the choices.
int32_t name_index(const std::string& value, std::initializer_list<const char*> names,
                   const std::string& who, const char* what) {
    int32_t k = 0;
    std::string choices;
    for (const char* n : names) {
        if (value == n) return k;
        choices += (k++ ? ", " : "") + std::string(n);
    }
    throw std::invalid_argument(who + ": unknown " + what + " '" + value + "' (" + choices + ")");
}

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

// Pick probabilities proportional to `weight`, handed to set(k, pdf) (0 where the weights sum to
// 0), and their CDF appended to `cdf` (the last entry exactly 1; all 0 when nothing can be
// picked). True when some light can be picked.
template <class SetPdf>
bool build_pick_cdf(const std::vector<double>& weight, std::vector<float>& cdf, SetPdf set) {
    double total = 0.0;
    for (double w : weight) total += w;
    double acc = 0.0;
    for (size_t k = 0; k < weight.size(); ++k) {
        set(k, total > 0.0 ? float(weight[k] / total) : 0.0f);
        acc += weight[k];
        cdf.push_back(total > 0.0 ? float(acc / total) : 0.0f);
    }
    if (total > 0.0) cdf.back() = 1.0f;
    return total > 0.0;
}

}  // namespace

HostScene::HostScene(const SceneInput& in) {
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
            if (m.coat_weight > 0.0f) principled_coat_table(m, tab);
            m.sheen_weight = finite_in(mi.sheen_weight, 0.0f, kInf, 0.0f);
            m.sheen_roughness = unit(mi.sheen_roughness, 0.5f);
            m.sheen_tint = sanitize_color(mi.sheen_tint, 1.0f);
            if (m.sheen_weight > 0.0f) principled_sheen_table(m, tab);
        } else {
            throw std::invalid_argument("material " + std::to_string(k) + " ('" + mi.name +
                                        "'): unknown type '" + mi.type +
                                        "' (diffuse, conductor, dielectric, principled, mix, translucent)");
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
    add_lights(in);
    build_filter(in.filter_width);
    finish_view(in);
}

namespace {

// The white GGX lobe's tables (ms_e, e_avg) at the roughness rows: the same for every
// material, made once per process
const MaterialTables* white_ggx_rows() {
    static const std::vector<MaterialTables> rows = [] {
        std::vector<MaterialTables> r(kRoughRows, MaterialTables{});
        for (int j = 0; j < kRoughRows; ++j) ms_fill_table(float(j) / (kRoughRows - 1), r[j]);
        return r;
    }();
    return rows.data();
}

// The specular-layer basis (bsdf/principled.h SpecBasis) at the roughness rows for specular
// IOR eta, made once per IOR and process (a scene's Principled materials mostly share one)
const SpecBasis* spec_basis_rows(float eta) {
    static std::mutex lock;
    static std::map<float, std::vector<SpecBasis>> rows;
    std::lock_guard<std::mutex> hold(lock);
    auto it = rows.find(eta);
    if (it == rows.end()) {
        std::vector<SpecBasis> r(kRoughRows);
        for (int j = 0; j < kRoughRows; ++j)
            principled_spec_basis(float(j) / (kRoughRows - 1), eta, r[j]);
        it = rows.emplace(eta, std::move(r)).first;
    }
    return it->second.data();
}

// True when a texture or a node program gives m's roughness per hit.
bool roughness_per_hit(const Material& m, const std::vector<MaterialProgram>& programs) {
    if (m.tex_flags & kTexRoughness) return true;
    if (!(m.tex_flags & kTexProgram)) return false;
    for (int i = 0; i < m.prog_count; ++i)
        if (programs[size_t(m.prog_first + i)].target == kTargetRoughness) return true;
    return false;
}

}  // namespace

// The multiple-scattering compensation and the principled layer's albedo (with it), at the
// material's roughness as the node programs left it (a constant graph folded into it); with a
// roughness per hit also at the roughness rows (MaterialTables::rough_rows), appended after
// the materials' own tables.
void HostScene::fill_lobe_tables() {
    const size_t own = materials_.size();
    std::vector<MaterialTables> rows;
    for (size_t k = 0; k < own; ++k) {
        Material& m = materials_[k];
        if (m.type != kMaterialConductor && m.type != kMaterialPrincipled) continue;
        MaterialTables& tab = material_tables_[k];
        m.tables = &tab;
        const float e_avg = ms_fill_table(m, tab);
        Material mc = m;
        auto metal_fresnel = [&](float mu) {
            return conductor_fresnel(material_conductor(mc), mu) * material_conductor_scale(mc);
        };
        m.fms_metal = ms_fresnel(metal_fresnel, e_avg);
        // F_avg is affine in F0 (F82-tint and the scaled complex Fresnel alike): its ends
        // give fms_metal for a textured base colour (material_at)
        m.e_avg = e_avg;
        mc.base_color = vec3(0.0f);
        m.metal_favg0 = ms_average_fresnel(metal_fresnel);
        mc.base_color = vec3(1.0f);
        m.metal_favg1 = ms_average_fresnel(metal_fresnel);
        mc = m;
        if (m.type == kMaterialPrincipled) {
            tab.spec_favg =
                ms_average_fresnel([&](float mu) { return principled_spec_fresnel(mc, mu); });
            m.fms_spec = ms_fresnel_from_average(tab.spec_favg, e_avg);
            principled_albedo_table(m, tab);
        }
        tab.rough_rows = 0;
        const bool rows_read = m.multiscatter || m.type == kMaterialPrincipled;
        if (!rows_read || !roughness_per_hit(m, programs_)) continue;
        tab.rough_rows = int32_t(own + rows.size() - k);
        const MaterialTables* white = white_ggx_rows();
        // the layer's albedo from the shared basis of its IOR, or (a film, anisotropy) its own
        const bool shared = !(m.film_thickness > 0.0f) && !(m.anisotropy > 0.0f);
        const SpecBasis* basis =
            m.type == kMaterialPrincipled && shared ? spec_basis_rows(m.spec_eta) : nullptr;
        for (int j = 0; j < kRoughRows; ++j) {
            MaterialTables row = white[j];
            if (m.type == kMaterialPrincipled) {
                Material mr = m;
                mr.roughness = float(j) / (kRoughRows - 1);
                mr.tables = &row;  // a row: rough_rows 0, its own tables
                mr.fms_spec = ms_fresnel_from_average(tab.spec_favg, row.e_avg);
                if (basis)
                    principled_albedo_from_basis(mr, basis[j], row);
                else
                    principled_albedo_table(mr, row);
            }
            rows.push_back(row);
        }
    }
    material_tables_.insert(material_tables_.end(), rows.begin(), rows.end());
    point_material_tables();
}

// Each material at its own tables (the vectors no longer grow; a copy of the scene would need
// this again, see the class).
void HostScene::point_material_tables() {
    for (size_t k = 0; k < materials_.size(); ++k) materials_[k].tables = &material_tables_[k];
}

// Mix materials: their leaves exist and are not mixes, weights finite and >= 0; the mix
// emits its own emission plus the weighted sum of its leaves'.
void HostScene::set_mix_leaves(const SceneInput& in) {
    for (size_t k = 0; k < materials_.size(); ++k) {
        Material& m = materials_[k];
        if (m.type != kMaterialMix) continue;
        const MaterialInput& mi = in.materials[k];
        const std::string who = "material " + std::to_string(k) + " ('" + mi.name + "')";
        const size_t n = mi.mix_children.size();
        if (n < 1 || n > size_t(kMixLeaves) || mi.mix_weights.size() != n) {
            throw std::invalid_argument(who + ": a mix needs 1 to " + std::to_string(kMixLeaves) +
                                        " leaves, each with a weight");
        }
        m.mix_count = int32_t(n);
        for (size_t i = 0; i < n; ++i) {
            const int c = mi.mix_children[i];
            if (c < 0 || size_t(c) >= materials_.size() || materials_[c].type == kMaterialMix) {
                throw std::invalid_argument(who + ": mix leaf " + std::to_string(c) +
                                            " is not a material of the scene (or is a mix)");
            }
            const float w = mi.mix_weights[i];
            m.mix_child[i] = c;
            m.mix_weight[i] = finite_in(w, 0.0f, kInf, 0.0f);
            m.emission += materials_[c].emission * m.mix_weight[i];
            // one coat normal per hit: the first leaf with its own
            if ((materials_[c].tex_flags & kCoatNormal) && !(m.tex_flags & kCoatNormal)) {
                m.tex_flags |= kCoatNormal;
                m.tex_coat_normal = materials_[c].tex_coat_normal;
                m.coat_normal_strength = materials_[c].coat_normal_strength;
            }
            // one shading frame per hit: the first anisotropic leaf's tangent serves them all
            if (materials_[c].anisotropy > 0.0f && !(m.anisotropy > 0.0f)) {
                m.anisotropy = materials_[c].anisotropy;
                m.aniso_rotation = materials_[c].aniso_rotation;
                m.aniso_uv_tangent = materials_[c].aniso_uv_tangent;
            }
        }
        m.tex_flags |= kMixResolve;
        if (mi.tex_mix >= 0) {
            if (size_t(mi.tex_mix) >= textures_in_count_ || n != 2) {
                throw std::invalid_argument(who + ": a mix factor texture needs a valid texture "
                                            "and exactly two leaves");
            }
            m.tex_mix = mi.tex_mix;
            m.tex_flags |= kTexMix;
        }
    }
}

void HostScene::add_textures(const SceneInput& in) {
    srgb_lut_.resize(256);
    for (int i = 0; i < 256; ++i) srgb_lut_[i] = srgb_decode(float(i) / 255.0f);
    for (size_t k = 0; k < in.textures.size(); ++k) {
        const TextureInput& ti = in.textures[k];
        const std::string who = "texture " + std::to_string(k) + " ('" + ti.name + "')";
        if (ti.width <= 0 || ti.height <= 0 || ti.width > 65536 || ti.height > 65536) {
            throw std::invalid_argument(who + ": size must be between 1 and 65536 texels, got " +
                                        std::to_string(ti.width) + "x" + std::to_string(ti.height));
        }
        Texture t{};
        t.width = ti.width;
        t.height = ti.height;
        const size_t n = size_t(ti.width) * size_t(ti.height) * 4;
        if (ti.format == "srgb" || ti.format == "linear") {
            t.format = ti.format == "srgb" ? kTexRgba8Srgb : kTexRgba8Linear;
            if (ti.bytes.size() != n)
                throw std::invalid_argument(who + ": expected " + std::to_string(n) +
                                            " bytes (RGBA), got " + std::to_string(ti.bytes.size()));
        } else if (ti.format == "float") {
            t.format = kTexRgba32F;
            if (ti.floats.size() != n)
                throw std::invalid_argument(who + ": expected " + std::to_string(n) +
                                            " floats (RGBA), got " + std::to_string(ti.floats.size()));
        } else {
            throw std::invalid_argument(who + ": unknown format '" + ti.format +
                                        "' (srgb, linear, float)");
        }
        t.wrap = name_index(ti.wrap, {"repeat", "extend", "clip", "mirror"}, who, "wrap");
        t.interp = name_index(ti.interpolation, {"linear", "closest"}, who, "interpolation");
        t.output = name_index(ti.output, {"color", "alpha", "red", "green", "blue"}, who,
                              "output");
        for (int i = 0; i < 6; ++i) {
            if (!std::isfinite(ti.uv[i]))
                throw std::invalid_argument(who + ": uv transform must be finite");
            t.uv[i] = ti.uv[i];
        }
        // 16-byte aligned start: float texels are read as float
        texels_.resize((texels_.size() + 15) & ~size_t(15));
        t.offset = texels_.size();
        if (t.format == kTexRgba32F) {
            texels_.resize(t.offset + n * sizeof(float));
            float* dst = reinterpret_cast<float*>(texels_.data() + t.offset);
            size_t bad = 0;
            for (size_t i = 0; i < n; ++i) {
                float v = ti.floats[i];
                if (!std::isfinite(v)) { v = 0.0f; ++bad; }
                dst[i] = v;
            }
            if (bad) warnings_.push_back(who + ": " + std::to_string(bad) +
                                         " non-finite texel values read as 0");
        } else {
            texels_.insert(texels_.end(), ti.bytes.begin(), ti.bytes.end());
        }
        textures_.push_back(t);
        // the mean colour (decoded), for the light power of emission-textured meshes
        double sum[3] = {0.0, 0.0, 0.0};
        const size_t texels = size_t(t.width) * size_t(t.height);
        for (size_t i = 0; i < texels; ++i)
            for (int c = 0; c < 3; ++c) {
                double v;
                if (t.format == kTexRgba32F)
                    v = reinterpret_cast<const float*>(texels_.data() + t.offset)[4 * i + c];
                else if (t.format == kTexRgba8Srgb)
                    v = srgb_lut_[texels_[t.offset + 4 * i + c]];
                else
                    v = texels_[t.offset + 4 * i + c] / 255.0;
                sum[c] += v > 0.0 ? v : 0.0;
            }
        texture_mean_.push_back(Vec3{float(sum[0] / texels), float(sum[1] / texels),
                                     float(sum[2] / texels)});
    }
}

// Emission-textured materials emit the texture's mean x their multiplier on average: that is
// their constant emission (light selection, "is this an emitter"); hits and light samples
// read the texture itself.
void HostScene::finish_emission_textures() {
    for (Material& m : materials_)
        if (m.tex_flags & kTexEmission) m.emission = texture_mean_[m.tex_emission] * m.emission_scale;
}

void HostScene::add_meshes(const SceneInput& in) {
    bool any_normals = false, any_uvs = false, any_tangents = false;
    for (const MeshInput& m : in.meshes) {
        any_normals |= !m.normals.empty();
        any_uvs |= !m.uvs.empty();
        any_tangents |= !m.tangents.empty();
    }
    for (const MeshInput& m : in.meshes) {
        const size_t nv = m.positions.size() / 3, nt = m.indices.size() / 3;
        if (m.positions.size() % 3 || m.indices.size() % 3) {
            throw std::invalid_argument("mesh '" + m.name + "': positions and indices need 3 values each");
        }
        if (!m.normals.empty() && m.normals.size() != 3 * nv) {
            throw std::invalid_argument("mesh '" + m.name + "': normals must match positions");
        }
        if (!m.uvs.empty() && m.uvs.size() != 2 * nv) {
            throw std::invalid_argument("mesh '" + m.name + "': uvs must have one pair per vertex");
        }
        if (!m.tangents.empty() && m.tangents.size() != 4 * nv) {
            throw std::invalid_argument("mesh '" + m.name + "': tangents need 4 values per vertex");
        }
        if (m.material_ids.size() != nt) {
            throw std::invalid_argument("mesh '" + m.name + "': one material id per triangle needed");
        }
        const uint32_t base = uint32_t(positions_.size());
        MeshRange range{int32_t(tri_material_.size()), 0, int32_t(base), int32_t(nv)};
        add_mesh_attributes(m, nv, size_t(num_attribute_channels_), attributes_);
        for (size_t v = 0; v < nv; ++v) {
            positions_.push_back({m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]});
            if (any_normals) {
                normals_.push_back(m.normals.empty() ? Vec3{0, 0, 0}
                                                     : Vec3{m.normals[3 * v], m.normals[3 * v + 1],
                                                            m.normals[3 * v + 2]});
            }
            if (any_uvs) {
                uvs_.push_back(m.uvs.empty() ? Vec2{0, 0} : Vec2{m.uvs[2 * v], m.uvs[2 * v + 1]});
            }
            if (any_tangents) {  // a mesh without: zero, i.e. the uv-derived tangent per triangle
                for (int c = 0; c < 4; ++c) {
                    float x = m.tangents.empty() ? 0.0f : m.tangents[4 * v + c];
                    tangents_.push_back(std::isfinite(x) ? x : 0.0f);
                }
            }
        }
        const uint8_t flags = uint8_t((m.visible_camera ? kVisibleCamera : 0) |
                                      (m.cast_shadow ? kCastShadow : 0) |
                                      (m.shadow_catcher ? kShadowCatcher : 0));
        size_t far = 0, huge = 0;  // a (finite) vertex beyond kMaxCoordinate; edges > kMaxEdge
        double far_max = 0.0, huge_max = 0.0;
        for (size_t t = 0; t < nt; ++t) {
            bool is_far = false;
            for (int k = 0; k < 3; ++k) {
                uint32_t idx = m.indices[3 * t + k];
                if (idx >= nv) {
                    throw std::invalid_argument("mesh '" + m.name + "': vertex index " +
                                                std::to_string(idx) + " out of range");
                }
                const Vec3 p = positions_[base + idx];
                if (is_finite(p) && !within_limit(p)) {
                    is_far = true;
                    far_max = std::max(far_max, double(distance_from_origin(p)));
                }
            }
            if (is_far) {
                ++far;
                continue;
            }
            const double edge = max_edge(positions_[base + m.indices[3 * t]],
                                         positions_[base + m.indices[3 * t + 1]],
                                         positions_[base + m.indices[3 * t + 2]]);
            if (edge > kMaxEdge) {  // kept: where the float tests find it, it renders right
                ++huge;
                huge_max = std::max(huge_max, edge);
            }
            for (int k = 0; k < 3; ++k) indices_.push_back(base + m.indices[3 * t + k]);
            uint32_t mat = m.material_ids[t];
            if (mat >= materials_.size()) {
                throw std::invalid_argument("mesh '" + m.name + "': material id " +
                                            std::to_string(mat) + " out of range");
            }
            tri_material_.push_back(mat);
            const Material& mm = materials_[mat];
            const bool alpha = mm.transparency > 0.0f || (mm.tex_flags & kTexAlpha) ||
                               program_has_target(programs_.data(), mm, kTargetAlpha);
            tri_flags_.push_back(uint8_t(flags | (alpha ? kAlphaTested : 0) |
                                         (mm.holdout ? kHoldout : 0)));
        }
        range.tri_count = int32_t(tri_material_.size()) - range.tri_begin;
        mesh_ranges_.push_back(range);
        if (far) {
            warnings_.push_back("mesh '" + m.name + "': " + std::to_string(far) + " of " +
                                std::to_string(nt) + " triangle(s) reach " +
                                format_metres(far_max) + " m from the origin, beyond the " +
                                format_metres(kMaxCoordinate) +
                                " m the ray queries can take; they were left out");
        }
        if (huge) {
            warnings_.push_back("mesh '" + m.name + "': " + std::to_string(huge) +
                                " triangle(s) with edges up to " + format_metres(huge_max) +
                                " m, beyond the " + format_metres(kMaxEdge) +
                                " m the float ray-triangle tests handle: rays may miss them");
        }
    }
    tri_light_.assign(tri_material_.size(), -1);
}

void HostScene::add_lights(const SceneInput& in) {
    std::vector<float> power;
    // scene extent, for the power of distant lights
    Vec3 lo = vec3(kInf), hi = vec3(-kInf);
    for (const Vec3& p : positions_) {
        if (!within_limit(p)) continue;  // non-finite or far: no triangle of the scene uses it
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    float radius = lo.x <= hi.x ? 0.5f * length(hi - lo) : 1.0f;
    view_.scene_center = lo.x <= hi.x ? (lo + hi) * 0.5f : vec3(0.0f);
    view_.scene_radius = std::max(radius, 1e-3f);
    view_.offset_scale = std::min(1.0f, view_.scene_radius);
    // the pure light tracer's sun and world paths leave the disk of the sphere about the same
    // centre through the farthest vertex: no larger than the box's (kept where they round alike,
    // a box's corners), a third of its area about a ball (light_path.h, kTightDisk)
    float reach = 0.0f;
    for (const Vec3& p : positions_) {
        if (within_limit(p)) reach = std::max(reach, length(p - view_.scene_center));
    }
    view_.emit_radius = lo.x <= hi.x ? std::max(std::min(view_.scene_radius,
                                                         reach * (1.0f + 1e-5f)), 1e-3f)
                                     : view_.scene_radius;  // no geometry: as the box's
    const float disk_area = kPi * view_.scene_radius * view_.scene_radius;

    for (size_t k = 0; k < in.lights.size(); ++k) {
        const LightInput& li = in.lights[k];
        if (!light_within_limit(li, k, warnings_)) continue;
        Light l{};
        l.triangle = -1;
        l.visible_camera = li.visible_camera ? 1 : 0;
        const Vec3 pw = sanitize_color(li.power, 1e30f);
        if (li.type == "point" || li.type == "spot") {
            l.type = li.type == "point" ? kLightPoint : kLightSpot;
            l.frame = rigid(li.to_world);
            l.position = li.type == "point" ? li.position : l.frame.origin();
            l.radius = finite_in(li.radius, 0.0f, kInf, 0.0f);
            l.soft_falloff = li.soft_falloff ? 1 : 0;
            l.intensity = pw * (0.25f * kInvPi);                 // W/sr
            if (l.radius > 0.0f) l.radiance = l.intensity * (1.0f / (kPi * l.radius * l.radius));
            float half = 0.5f * clampf(li.spot_size, 1e-4f, kPi);
            l.cos_half_spot = cosf(half);
            l.spot_smooth = (1.0f - l.cos_half_spot) * clampf(li.spot_blend, 0.0f, 1.0f);
            power.push_back(luminance(pw));
        } else if (li.type == "area") {
            l.type = kLightArea;
            l.frame = rigid(li.to_world);
            bool ellipse = li.shape == "disk" || li.shape == "ellipse";
            bool square = li.shape == "square" || li.shape == "disk";
            l.shape = ellipse ? kShapeEllipse : kShapeRectangle;
            l.half_x = 0.5f * std::fabs(li.size_x);
            l.half_y = 0.5f * std::fabs(square ? li.size_x : li.size_y);
            l.area = ellipse ? kPi * l.half_x * l.half_y : 4.0f * l.half_x * l.half_y;
            if (!(l.area > 0.0f) || !std::isfinite(l.area)) {
                warnings_.push_back(light_label(li, k) + ": an area light of zero (or " +
                                    "non-finite) size was skipped");
                continue;
            }
            l.radiance = pw * (1.0f / (kPi * l.area));
            power.push_back(luminance(pw));
        } else if (li.type == "sun") {
            l.type = kLightSun;
            l.direction = normalize(li.direction);
            const Vec3 s = sanitize_color(li.strength, 1e30f);
            float half = 0.5f * clampf(std::isfinite(li.angle) ? li.angle : 0.0f, 0.0f, kPi);
            if (half < 1e-5f) {
                l.cos_sun = 1.0f;
                l.intensity = s;
            } else {
                l.cos_sun = cosf(half);
                float sin2 = 1.0f - l.cos_sun * l.cos_sun;
                l.radiance = s * (1.0f / (kPi * sin2));
            }
            power.push_back(luminance(s) * disk_area);
            if (li.of_world) {  // the world's disc: the camera sees it where it sees the world
                l.of_world = 1;
                l.visible_camera = in.world_visible_camera && !in.film_transparent ? 1 : 0;
            }
        } else {
            warnings_.push_back("unknown light type '" + li.type + "' was skipped");
            continue;
        }
        if (power.back() <= 0.0f || !std::isfinite(power.back())) {
            power.pop_back();
            continue;
        }
        lights_.push_back(l);
    }
    // emissive triangles
    for (size_t t = 0; t < tri_material_.size(); ++t) {
        const Material& m = materials_[tri_material_[t]];
        if (is_black(m.emission)) continue;
        Vec3 a = positions_[indices_[3 * t]], b = positions_[indices_[3 * t + 1]],
             c = positions_[indices_[3 * t + 2]];
        // in double: the float cross product's squared length overflows for edges over ~4e9 m
        float area = float(0.5 * triangle_area2(a, b, c));
        if (!(area > 0.0f) || !std::isfinite(area)) continue;
        Light l{};
        l.type = kLightTriangle;
        l.triangle = int32_t(t);
        l.radiance = m.emission;
        l.area = area;
        l.visible_camera = 1;
        tri_light_[t] = int32_t(lights_.size());
        lights_.push_back(l);
        power.push_back(luminance(m.emission) * area * 2.0f * kPi);
    }
    Vec3 world = sanitize_color(in.world_color, 1e30f);
    if (in.world_map.width > 0) {  // an environment map replaces the constant colour
        env_ = build_envmap_cached(in.world_map, warnings_);  // once per content
        world = env_->view.width > 0 ? env_->mean : vec3(0.0f);
    }
    view_.world_color = world;
    if (!is_black(world)) {
        Light l{};
        l.type = kLightWorld;
        l.triangle = -1;
        l.radiance = world;  // with a map: its mean (the light's power), SceneView::env per ray
        l.visible_camera = in.world_visible_camera && !in.film_transparent ? 1 : 0;
        view_.world_light = int32_t(lights_.size());
        lights_.push_back(l);
        power.push_back(luminance(world) * kPi * 4.0f * disk_area);
    }
    double total = 0.0;
    for (float p : power) total += p;
    double acc = 0.0;
    for (size_t k = 0; k < lights_.size(); ++k) {
        lights_[k].pick_pdf = float(power[k] / total);
        acc += power[k];
        light_cdf_.push_back(float(acc / total));
    }
    if (!light_cdf_.empty()) light_cdf_.back() = 1.0f;
    // Next-event estimation leaves out a constant world: BSDF sampling alone is the better
    // strategy there (its integrand is the BSDF times visibility), and saves the shadow ray.
    // Cycles' "Auto" world sampling does the same for a solid colour (its manual: importance
    // sampling "for non-solid colors is recommended"). A map (HDRI, sky) is sampled.
    const bool world_map = env_->view.width > 0;
    std::vector<double> weight(lights_.size());
    for (size_t k = 0; k < lights_.size(); ++k)
        weight[k] = lights_[k].type == kLightWorld && !world_map ? 0.0 : double(power[k]);
    has_nee_lights_ = build_pick_cdf(weight, nee_cdf_,
                                     [&](size_t k, float pdf) { lights_[k].nee_pdf = pdf; });
    // Light sub-paths (bdpt, lvc, cis) start by power too, but never on a receiver-dependent
    // light (soft-falloff point/spot): it has no emission distribution (docs/lvc_notes.md).
    for (size_t k = 0; k < lights_.size(); ++k)
        weight[k] = light_receiver_dependent(lights_[k]) ? 0.0 : double(power[k]);
    has_emitters_ = build_pick_cdf(weight, emit_cdf_,
                                   [&](size_t k, float pdf) { lights_[k].emit_pick_pdf = pdf; });
    // Next-event estimation picks by the light tree where there is a choice (a scene with one
    // light keeps light_cdf); LANTERN_LIGHT_TREE=0 keeps the global CDF, for benchmarks.
    const char* tree_env = std::getenv("LANTERN_LIGHT_TREE");
    light_tree_on_ = lights_.size() >= 2 && !(tree_env && std::string(tree_env) == "0");
    for (Light& l : lights_) l.tree_leaf = -1;
    if (light_tree_on_) build_light_tree(lights_, positions_, indices_, light_tree_);
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
    v.tri_light = tri_light_.data();
    v.num_triangles = int32_t(tri_material_.size());
    v.materials = materials_.data();
    v.material_tables = material_tables_.data();
    v.num_materials = int32_t(materials_.size());
    v.material_bits = 0;
    for (const Material& m : materials_) {
        if (m.tex_flags & kMaterialResolve) v.material_bits |= kSceneResolve;
        if ((m.tex_flags & (kTexNormal | kCoatNormal | kTexBump)) || m.anisotropy > 0.0f)
            v.material_bits |= kSceneFrames;
        if (m.tex_flags & kTexProgram) v.material_bits |= kScenePrograms;
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

}  // namespace lantern

namespace lantern {

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
}

}  // namespace lantern

namespace lantern {

namespace {

bool same3(Vec3 a, Vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

// What the triangles, the lights and the acceleration structure take from a material: its
// emission (light list and power), transparency and alpha texture (alpha-tested triangles),
// the textures it reads and the mix leaves it points at.
bool same_use(const Material& a, const Material& b) {
    if (!same3(a.emission, b.emission) || !same3(a.emission_scale, b.emission_scale)) return false;
    if (a.transparency != b.transparency || a.tex_flags != b.tex_flags) return false;
    if (a.holdout != b.holdout) return false;  // a triangle flag
    if ((a.type == kMaterialMix) != (b.type == kMaterialMix) || a.mix_count != b.mix_count)
        return false;
    for (int i = 0; i < kMixLeaves; ++i) {
        if (a.mix_child[i] != b.mix_child[i]) return false;
    }
    return a.tex_base_color == b.tex_base_color && a.tex_roughness == b.tex_roughness &&
           a.tex_metallic == b.tex_metallic && a.tex_alpha == b.tex_alpha &&
           a.tex_normal == b.tex_normal && a.tex_emission == b.tex_emission &&
           a.tex_coat_normal == b.tex_coat_normal && a.tex_mix == b.tex_mix;
}

}  // namespace

// A material edit without a rebuild (Session::update_materials): in's materials and textures,
// converted and checked as a new scene's would be, replace these in place (the views of the
// backends point at the same storage) when nothing else depends on what changed.
bool HostScene::update_materials(const SceneInput& in) {
    SceneInput probe;  // no geometry: only the materials and textures are converted
    probe.width = view_.camera.width;
    probe.height = view_.camera.height;
    probe.filter_width = view_.camera.filter_width;
    probe.materials = in.materials;
    probe.textures = in.textures;
    const HostScene next(probe);
    if (next.materials_.size() != materials_.size() || next.textures_.size() != textures_.size() ||
        next.material_tables_.size() != material_tables_.size() ||
        next.texels_ != texels_ || next.view_.material_bits != view_.material_bits) {
        return false;
    }
    if (!textures_.empty() &&
        std::memcmp(next.textures_.data(), textures_.data(), textures_.size() * sizeof(Texture)))
        return false;
    for (size_t k = 0; k < materials_.size(); ++k) {
        if (!same_use(materials_[k], next.materials_[k])) return false;
    }
    std::copy(next.materials_.begin(), next.materials_.end(), materials_.begin());
    std::copy(next.material_tables_.begin(), next.material_tables_.end(),
              material_tables_.begin());
    point_material_tables();  // the copies point at next's tables
    return true;
}

}  // namespace lantern
