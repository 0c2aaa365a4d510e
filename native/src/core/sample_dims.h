// Which dimension of a sample each event takes: the reference table for core/rng.h. Stages draw
// in program order through Rng; uniform2() starts at an even dimension, so a pair is always one
// padded 2D Sobol' set. Past kQmcDims (core/sampler.h) numbers are hashed, not stratified.
#pragma once

#include <cstdint>

namespace lantern {

// ---- Streams: which sequence and scramble a path draws from ----
//   pt camera path, bdpt/lvc/cis camera path   Rng::for_camera(seed, ...)          pixel scramble
//   bdpt/lvc/cis connections at camera depth k  Rng::for_camera(seed ^ "CONN" ^ k<<40, ...)
//   pt AOV pass sample k of a pixel             Rng::for_pixel(seed ^ kAovStream, pixel, k)
//   lt light path                               Rng::for_path(seed ^ "LT", iteration, path)
//   bdpt/lvc/cis light path (and the pilot pass, iteration ~0)
//                                               Rng::for_path(seed ^ "LVC", iteration, path)
// A camera path's sample index is iteration x spp_per_iteration + its sample in the iteration;
// a light path's is its number within the iteration (scrambled per iteration).

// ---- Camera paths (pt, and the camera side of bdpt / lvc / cis) ----
//   dims 0, 1         pixel filter offset (camera.h; a lens or time sample would follow)
//   per bounce b = 1, 2, ... starting at kCameraBounce0 + (b - 1) * kCameraBounceDims:
//     +0, +1          light pick (x; y unused), next-event estimation
//     +2, +3          point on the light
//     +4, +5          BSDF direction
//     +6              BSDF lobe choice
//     +7              Russian roulette (only at depth >= rr_depth; otherwise unused)
//   A delta material still consumes +0..+3 (bdpt) or draws them unused (pt), so the table does
//   not shift. Emission and misses draw nothing. Fixed per bounce: bounce 8 onwards (dim 58+)
//   is partly or wholly past kQmcDims and hashed.
constexpr uint32_t kCameraBounce0 = 2;
constexpr uint32_t kCameraBounceDims = 8;

// ---- Light paths (lt, and the light pass of bdpt / lvc / cis) ----
//   dim 0             light pick by power
//   dims 2, 3         point on the light (dim 1 unused: the pair starts even)
//   dims 4, 5         emitted direction
//   per bounce b = 1, 2, ... starting at kLightBounce0 + (b - 1) * kLightBounceDims:
//     +0, +1          BSDF direction
//     +2              BSDF lobe choice
//     +3              Russian roulette (only at depth >= rr_depth)
//   Connections to the camera (lt) draw nothing while the camera is a pinhole.
constexpr uint32_t kLightPick = 0;
constexpr uint32_t kLightBounce0 = 6;
constexpr uint32_t kLightBounceDims = 4;

// ---- Connections of a camera vertex (lvc, cis; bdpt draws none), own stream per depth ----
//   lvc: dims 0 .. N-1   N uniform cache picks (N = connections)
//   cis: dims 0 .. M-1   M uniform candidates, then M .. M+N-1 the N resampled picks
//   Counts vary with the settings, never with the path.

}  // namespace lantern
