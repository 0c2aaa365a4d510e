// Host side of the world's environment map (scene/envmap.h): clean the texels, build the
// importance distribution once per scene, and keep the buffers the EnvMap view points into.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "scene/envmap.h"

namespace lantern {

// An environment map as the scene describes it: linear radiance pixels (width x height x
// channels, channels 3 or 4, rows bottom to top), times `strength`; `to_map` (row-major 3x3)
// takes a world direction to the vector the texture reads (Texture Coordinate and Mapping).
struct EnvMapInput {
    std::string name;
    int width = 0, height = 0, channels = 3;
    std::vector<float> pixels;
    Vec3 strength{1.0f, 1.0f, 1.0f};
    std::string projection = "equirectangular";  // equirectangular | mirror_ball
    float to_map[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
};

struct EnvMapStorage {
    std::vector<float> texels, marginal, conditional;
    EnvMap view;          // points into the vectors above; width 0 when there is no map
    Vec3 mean{0, 0, 0};   // mean radiance over the sphere (solid-angle weighted)
};

// Builds `out` from `in`; bad texels (NaN, Inf, negative) become 0 with a warning, a singular
// mapping becomes the identity with a warning. Throws std::invalid_argument for pixel arrays
// that do not match their size. An all-black map leaves out.view.width 0.
void build_envmap(const EnvMapInput& in, EnvMapStorage& out, std::vector<std::string>& warnings);

// build_envmap once per content: the same pixels, strength, projection and mapping (a viewport
// restart, another Session of the same export) return the build already made, and its
// warnings again. The last kEnvMapCacheSize builds are kept; thread-safe.
constexpr int kEnvMapCacheSize = 2;
std::shared_ptr<const EnvMapStorage> build_envmap_cached(const EnvMapInput& in,
                                                         std::vector<std::string>& warnings);
// Builds made (not found in the cache) since the process started: for tests.
int64_t envmap_builds();

}  // namespace lantern
