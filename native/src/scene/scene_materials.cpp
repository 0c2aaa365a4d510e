// HostScene's materials after conversion: the lobe tables (multiple-scattering compensation,
// layer albedos, the roughness rows for a roughness per hit), mix leaves checked, textures
// decoded with their mean colour (emission), and a material edit in place without a rebuild.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <vector>

#include "bsdf/material.h"
#include "scene/scene.h"
#include "scene/scene_checks.h"

namespace lantern {

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


// What fill_lobe_tables computes for one material: the fields of its tables (multiple-
// scattering compensation, the principled layer's albedo) and of the material that they set,
// and with a roughness per hit its kRoughRows roughness rows.
struct LobeTables {
    MaterialTables tab;
    Vec3 fms_metal, fms_spec, metal_favg0, metal_favg1;
    float e_avg = 0.0f;
    std::vector<MaterialTables> rows;
};

LobeTables compute_lobe_tables(const Material& in, const MaterialTables& tab_in, bool with_rows) {
    LobeTables out;
    out.tab = tab_in;
    MaterialTables& tab = out.tab;
    Material m = in;
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
    out.fms_metal = m.fms_metal;
    out.fms_spec = m.fms_spec;
    out.metal_favg0 = m.metal_favg0;
    out.metal_favg1 = m.metal_favg1;
    out.e_avg = m.e_avg;
    if (!with_rows) return out;
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
        out.rows.push_back(row);
    }
    return out;
}

// compute_lobe_tables, kept per process: a pure function of the material's fields and of its
// tables' fields set before (the sheen's fit), which sessions repeat for the same scene (every
// re-export of the viewport, every seed of a test, a farm's frames): a principled material's
// tables took 30-40 ms each (quadratures), a conductor's ~13. Keyed on those bytes (the tables
// pointer left out; padding that differs costs a miss, never a wrong table); forgotten whole
// past kLobeMemoBytes.
constexpr size_t kLobeMemoBytes = size_t(64) << 20;

std::shared_ptr<const LobeTables> cached_lobe_tables(const Material& m, const MaterialTables& tab,
                                                     bool with_rows) {
    static_assert(std::is_trivially_copyable_v<Material> &&
                      std::is_trivially_copyable_v<MaterialTables>,
                  "the lobe tables' key is the material's bytes");
    Material keyed = m;
    keyed.tables = nullptr;
    std::string key(sizeof(Material) + sizeof(MaterialTables) + 1, '\0');
    std::memcpy(key.data(), &keyed, sizeof(Material));
    std::memcpy(key.data() + sizeof(Material), &tab, sizeof(MaterialTables));
    key.back() = with_rows ? 1 : 0;
    static std::mutex lock;
    static std::unordered_map<std::string, std::shared_ptr<const LobeTables>> memo;
    static size_t bytes = 0;
    {
        std::lock_guard<std::mutex> hold(lock);
        auto it = memo.find(key);
        if (it != memo.end()) return it->second;
    }
    auto made = std::make_shared<const LobeTables>(compute_lobe_tables(m, tab, with_rows));
    const size_t size = key.size() + sizeof(LobeTables) + made->rows.size() * sizeof(MaterialTables);
    std::lock_guard<std::mutex> hold(lock);
    if (bytes + size > kLobeMemoBytes) {
        memo.clear();
        bytes = 0;
    }
    if (memo.emplace(std::move(key), made).second) bytes += size;
    return made;
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
        const bool rows_read = m.multiscatter || m.type == kMaterialPrincipled;
        const bool with_rows = rows_read && roughness_per_hit(m, programs_);
        const std::shared_ptr<const LobeTables> made = cached_lobe_tables(m, tab, with_rows);
        tab = made->tab;
        m.tables = &tab;
        m.fms_metal = made->fms_metal;
        m.fms_spec = made->fms_spec;
        m.metal_favg0 = made->metal_favg0;
        m.metal_favg1 = made->metal_favg1;
        m.e_avg = made->e_avg;
        tab.rough_rows = with_rows ? int32_t(own + rows.size() - k) : 0;
        rows.insert(rows.end(), made->rows.begin(), made->rows.end());
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
            // a strand whose mix holds the hair lobe is a tube vertex: the lobe in the surface
            // measure (bsdf/hair_lobe.h; a hair material also used alone stays pt's: allocation)
            if (materials_[c].type == kMaterialHair) materials_[c].tex_flags |= kHairTube;
            if (materials_[c].subsurface > 0.0f) {  // pt's walk starts at a top-level material
                materials_[c].subsurface = 0.0f;
                warnings_.push_back(who + ": subsurface scattering of a mix leaf is rendered as "
                                          "its diffuse base");
            }
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
    if (!media_.empty() || !in.media.empty()) return false;  // media: a new scene
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
    set_hair_reverse(hair_reverse_);
    std::copy(next.material_tables_.begin(), next.material_tables_.end(),
              material_tables_.begin());
    point_material_tables();  // the copies point at next's tables
    return true;
}



void HostScene::set_hair_reverse(bool on) {
    hair_reverse_ = on;
    for (Material& m : materials_)
        if (m.type == kMaterialHair)
            m.tex_flags = on ? (m.tex_flags | kHairReverse)
                             : (m.tex_flags & ~uint32_t(kHairReverse));
}

}  // namespace lantern
