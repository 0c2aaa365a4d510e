// First-hit data passes for the compositor, with Cycles' meanings (measured with bpy 5.0.1):
// Depth (camera z of the first hit, from the first sample, which goes through the pixel centre
// as Cycles' sample 0 does; 1e10 on a miss), Normal (world-space shading normal facing the ray,
// mean over samples; 0 on a miss), Diffuse Color and Emission of the first hit, and the
// denoiser's features: Denoising Albedo and Denoising Normal (camera
// space, Cycles' axes: x right, y up, z forward) at the first surface that is not a mirror or
// clear glass (those are passed through, tinting the albedo), Denoising Depth there.
// A pass of its own over camera rays (the CPU accelerator), independent of the integrators.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace lantern {

struct AovSettings {
    int spp = 16;          // camera samples per pixel (the pixel filter as the render's)
    uint64_t seed = 0;
    int threads = 0;       // 0: every core
    int max_passthrough = 8;  // mirror / clear-glass hits followed for the denoising features
};

struct AovImages {
    int width = 0, height = 0;
    // top row first; 1 or 3 floats per pixel
    std::vector<float> depth, normal, diffuse_color, emission;
    std::vector<float> denoising_albedo, denoising_normal, denoising_depth;
    std::vector<std::string> warnings;
};

// Throws std::invalid_argument (from HostScene) for a scene that cannot be rendered.
AovImages render_aovs(const SceneInput& in, const AovSettings& settings);

}  // namespace lantern
