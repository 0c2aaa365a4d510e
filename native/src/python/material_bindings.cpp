// The scene dict's "materials" (docs/scene_format.md) into SceneInput::materials: the
// Principled inputs, textures by index, a volume (its medium), mix leaves, Principled Hair.
#include "python/dict_get.h"

namespace lantern {

void get_materials(const nb::dict& scene, SceneInput& in) {
if (has(scene, "materials")) {
    for (nb::handle h : nb::cast<nb::list>(scene["materials"])) {
        nb::dict m = nb::cast<nb::dict>(h);
        MaterialInput mi;
        mi.name = get<std::string>(m, "name", "");
        mi.base_color = get_vec3(m, "base_color", mi.base_color);
        mi.emission = get_vec3(m, "emission", mi.emission);
        mi.type = get<std::string>(m, "type", mi.type);
        mi.roughness = get<float>(m, "roughness", mi.roughness);
        mi.diffuse_roughness = get<float>(m, "diffuse_roughness", mi.diffuse_roughness);
        mi.anisotropy = get<float>(m, "anisotropy", mi.anisotropy);
        mi.anisotropic_rotation = get<float>(m, "anisotropic_rotation",
                                             mi.anisotropic_rotation);
        mi.tangent = get<std::string>(m, "tangent", mi.tangent);
        mi.ior = get<float>(m, "ior", mi.ior);
        mi.specular_tint = get_vec3(m, "specular_tint", mi.specular_tint);
        // "eta" / "k" on a conductor switch it to the complex-IOR Fresnel
        mi.complex_fresnel = has(m, "eta") || has(m, "k");
        mi.eta = get_vec3(m, "eta", mi.eta);
        mi.k = get_vec3(m, "k", mi.k);
        mi.metallic = get<float>(m, "metallic", mi.metallic);
        mi.transmission = get<float>(m, "transmission", mi.transmission);
        mi.specular_level = get<float>(m, "specular_level", mi.specular_level);
        mi.multiscatter = get<bool>(m, "multiscatter", mi.multiscatter);
        mi.tint_reflection = get<bool>(m, "tint_reflection", mi.tint_reflection);
        mi.distribution = get<std::string>(m, "distribution", mi.distribution);
        mi.coat_weight = get<float>(m, "coat_weight", mi.coat_weight);
        mi.coat_roughness = get<float>(m, "coat_roughness", mi.coat_roughness);
        mi.coat_ior = get<float>(m, "coat_ior", mi.coat_ior);
        mi.coat_tint = get_vec3(m, "coat_tint", mi.coat_tint);
        mi.sheen_weight = get<float>(m, "sheen_weight", mi.sheen_weight);
        mi.thin_film_thickness = get<float>(m, "thin_film_thickness", mi.thin_film_thickness);
        mi.thin_film_ior = get<float>(m, "thin_film_ior", mi.thin_film_ior);
        mi.sheen_roughness = get<float>(m, "sheen_roughness", mi.sheen_roughness);
        mi.sheen_tint = get_vec3(m, "sheen_tint", mi.sheen_tint);
        mi.subsurface_weight = get<float>(m, "subsurface_weight", mi.subsurface_weight);
        mi.subsurface_radius = get_vec3(m, "subsurface_radius", mi.subsurface_radius);
        mi.subsurface_ior = get<float>(m, "subsurface_ior", mi.subsurface_ior);
        mi.subsurface_anisotropy =
            get<float>(m, "subsurface_anisotropy", mi.subsurface_anisotropy);
        mi.subsurface_method = get<std::string>(m, "subsurface_method", mi.subsurface_method);
        mi.tex_base_color = get<int>(m, "base_color_texture", -1);
        mi.tex_roughness = get<int>(m, "roughness_texture", -1);
        mi.tex_metallic = get<int>(m, "metallic_texture", -1);
        mi.tex_alpha = get<int>(m, "alpha_texture", -1);
        mi.tex_normal = get<int>(m, "normal_texture", -1);
        mi.tex_emission = get<int>(m, "emission_texture", -1);
        mi.normal_strength = get<float>(m, "normal_strength", mi.normal_strength);
        mi.tex_coat_normal = get<int>(m, "coat_normal_texture", -1);
        mi.coat_normal_strength = get<float>(m, "coat_normal_strength",
                                             mi.coat_normal_strength);
        mi.alpha = get<float>(m, "alpha", mi.alpha);
        mi.holdout = get<bool>(m, "holdout", false);
        if (has(m, "volume")) mi.medium = get_medium(m["volume"], mi.name, in);
        mi.volume_only = get<bool>(m, "volume_only", false);
        mi.density_grid = get<int>(m, "density_grid", -1);
        mi.temperature_grid = get<int>(m, "temperature_grid", -1);
        mi.flame_grid = get<int>(m, "flame_grid", -1);
        mi.color_grid = get<int>(m, "color_grid", -1);
        if (has(m, "mix")) {  // [[leaf, weight], ...]
            for (nb::handle e : nb::cast<nb::list>(m["mix"])) {
                auto pair = nb::cast<std::vector<float>>(e);
                if (pair.size() != 2)
                    throw std::invalid_argument("material '" + mi.name +
                                                "': mix entries are [leaf, weight]");
                mi.mix_children.push_back(int(pair[0]));
                mi.mix_weights.push_back(pair[1]);
            }
        }
        mi.tex_mix = get<int>(m, "mix_texture", -1);
        // Principled Hair (type "hair": scene/hair_build.cpp)
        mi.hair_parametrization =
            get<std::string>(m, "hair_parametrization", mi.hair_parametrization);
        mi.melanin = get<float>(m, "melanin", mi.melanin);
        mi.melanin_redness = get<float>(m, "melanin_redness", mi.melanin_redness);
        mi.hair_tint = get_vec3(m, "hair_tint", mi.hair_tint);
        mi.absorption = get_vec3(m, "absorption", mi.absorption);
        mi.radial_roughness = get<float>(m, "radial_roughness", mi.radial_roughness);
        mi.hair_coat = get<float>(m, "hair_coat", mi.hair_coat);
        mi.hair_offset = get<float>(m, "hair_offset", mi.hair_offset);
        mi.program_first = get<int>(m, "program_first", 0);
        mi.program_count = get<int>(m, "program_count", 0);
        in.materials.push_back(mi);
    }
}
}

}  // namespace lantern
