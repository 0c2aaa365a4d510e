// What a scene says about its participating media (host side; docs/volumes.md): homogeneous
// coefficients per RGB channel in Blender's units, attached to materials (the medium inside
// their mesh) and to the world (the medium everywhere else).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/math.h"

namespace lantern {

struct MediumInput {
    std::string name;
    Vec3 sigma_a{0.0f, 0.0f, 0.0f};  // absorption, 1/m
    Vec3 sigma_s{0.0f, 0.0f, 0.0f};  // scattering, 1/m
    Vec3 emission{0.0f, 0.0f, 0.0f}; // radiance added per metre (Cycles' volume emission)
    float g = 0.0f;                  // Henyey-Greenstein anisotropy
    // a Volume object's fire (scene/medium_fire.h), read with the material's temperature and
    // flame grids: Principled Volume's Blackbody Intensity, Temperature socket and Blackbody
    // Tint (times the shader's weight); the emission per unit of the flame grid
    float blackbody_intensity = 0.0f;
    float temperature = 0.0f;
    Vec3 blackbody_tint{1.0f, 1.0f, 1.0f};
    Vec3 flame_emission{0.0f, 0.0f, 0.0f};
    // a Volume object's colour grid (Principled Volume's Color Attribute; scene/medium_hetero.h),
    // read with the material's color_grid: the scattering Color x Density that the grid's colour
    // c multiplies, the absorption max(1 - sqrt(Absorption Color), 0) x Density that
    // max(1 - color_base c, 0) multiplies, and the Color socket (the parts not in sigma_a / _s)
    Vec3 color_scatter{0.0f, 0.0f, 0.0f};
    Vec3 color_absorb{0.0f, 0.0f, 0.0f};
    Vec3 color_base{1.0f, 1.0f, 1.0f};
    // an Absorption Color graph on one shader beside a Color graph on another (scene/medium.h
    // Medium::absorb_alone): the absorption its factor multiplies alone
    Vec3 absorb_alone{0.0f, 0.0f, 0.0f};
};

// A Volume object's density grid (docs/volumes.md, scene/medium_grid.h): a dense block of
// voxels, x fastest, and the map from its index space (voxel centres at integers) to the world.
struct GridInput {
    std::string name;
    int32_t dims[3] = {0, 0, 0};
    float index_to_world[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};  // rows
    int32_t channels = 1;  // 3: a colour grid (3 floats per voxel)
    std::vector<float> voxels;
};

struct SceneInput;
// What in the scene is a participating medium, in words ("the world's volume", "a volume
// (material 'fog')"); empty: none. Integrators other than pt name it when they hand over.
std::string media_reason(const SceneInput& in);
// What lt cannot render of the media: an emissive one (it starts no light paths in media; bdpt,
// lvc and cis gather the emission on their camera paths); empty: none.
std::string emissive_media_reason(const SceneInput& in);

}  // namespace lantern
