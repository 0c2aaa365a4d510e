// A Principled Hair material (MaterialInput type "hair") as the fields bsdf/hair_lobe.h reads:
// the absorption from the node's parametrisation (bsdf/hair.h, as Cycles' Chiang model),
// Roughness, Radial Roughness, Coat, IOR and Offset, each sanitised (NaN: the node's default).
#include <cmath>
#include <stdexcept>

#include "bsdf/hair.h"
#include "scene/scene.h"

namespace lantern {

namespace {
float finite_or(float v, float lo, float hi, float fallback) {
    return std::isfinite(v) ? std::min(std::max(v, lo), hi) : fallback;
}
Vec3 finite_rgb(Vec3 v, float lo, float hi, Vec3 fallback) {
    if (!is_finite(v)) return fallback;
    return vec3(std::min(std::max(v.x, lo), hi), std::min(std::max(v.y, lo), hi),
                std::min(std::max(v.z, lo), hi));
}
}  // namespace

void set_hair_material(Material& m, const MaterialInput& mi) {
    m.type = kMaterialHair;
    const float radial = finite_or(mi.radial_roughness, 0.0f, 1.0f, 0.3f);
    Vec3 sigma;
    if (mi.hair_parametrization == "melanin") {
        sigma = hair_sigma_from_melanin(finite_or(mi.melanin, 0.0f, 1.0f, 0.8f),
                                        finite_or(mi.melanin_redness, 0.0f, 1.0f, 1.0f),
                                        finite_rgb(mi.hair_tint, 0.0f, 1.0f, vec3(1.0f)), radial);
    } else if (mi.hair_parametrization == "color") {
        sigma = hair_sigma_from_color(finite_rgb(mi.base_color, 0.0f, 1.0f, vec3(0.8f)), radial);
    } else if (mi.hair_parametrization == "absorption") {
        sigma = finite_rgb(mi.absorption, 0.0f, 1e4f, vec3(0.245531f, 0.52f, 1.365f));
    } else {
        throw std::invalid_argument("material '" + mi.name + "': unknown hair parametrization '" +
                                    mi.hair_parametrization + "' (melanin, color, absorption)");
    }
    // bsdf/hair_lobe.h's fields: base_color the absorption per unit radius, roughness,
    // coat_roughness the radial roughness, coat_weight the coat, aniso_rotation the offset
    m.base_color = sigma;
    m.roughness = finite_or(mi.roughness, 0.0f, 1.0f, 0.3f);
    m.coat_roughness = radial;
    m.coat_weight = finite_or(mi.hair_coat, 0.0f, 1.0f, 0.0f);
    m.aniso_rotation = finite_or(mi.hair_offset, -0.5f * kPi, 0.5f * kPi, 0.034906585f);
    m.ior = std::isfinite(mi.ior) ? std::min(std::max(mi.ior, 1.0001f), 100.0f) : 1.55f;
}

}  // namespace lantern
