// Which dimension of a sample each event takes: the reference table for core/rng.h. Stages draw
// in program order through Rng; uniform2() starts at an even dimension, so a pair is always one
// padded 2D Sobol' set. Dimensions below kQmcDims (core/sampler.h) are scrambled Sobol', later
// ones hashed. The table is program order written down: change a stage's draws, change it here.
#pragma once

#include <cstdint>

namespace lantern {

// ---- Streams: which sequence and scramble a path draws from (seed, salt, key; index) ----
//   pt camera path, bdpt/lvc/cis camera path   Rng::for_camera(seed, ...)     key pixel
//   lvc/cis connections at camera depth k      Rng::hashed(Rng::for_camera(seed ^ "CONN" ^ k << 40,
//                                              ...)), all numbers hashed
//   pt AOV pass, sample k of a pixel           Rng::for_pixel(seed ^ kAovStream, pixel, k)
//   lt light path                              Rng::for_path(seed ^ "LT", iteration, path)
//   bdpt/lvc/cis light path (and the pilot pass, iteration ~0)
//                                              Rng::for_path(seed ^ "LVC", iteration, path)
// A camera stream's sample index is iteration x spp_per_iteration + its sample in the iteration
// (so 16 iterations of 1 spp draw what one of 16 spp draws); a light path's is its number within
// the iteration, its key the iteration. Tests' own Monte Carlo checks draw from Pcg32 instead.

// ---- Camera paths (pt, and the camera side of bdpt / lvc / cis) ----
//   dims 0, 1         pixel filter offset (camera.h)
//   dims 2, 3         lens point, only with an aperture (camera.h: lens_radius > 0); the
//                     bounces then start 2 later. (The motion blur time takes no dimension:
//                     "Motion blur" below.)
//   per bounce b = 1, 2, ... from camera_bounce_dim(aperture, b):
//     +0, +1          light pick (x; y unused), next-event estimation
//     +2, +3          point on the light (area, sphere, spot, sun disk, env map, mesh triangle)
//     +4, +5          BSDF direction
//     +6              BSDF lobe choice
//     +7              Russian roulette (only at depth >= rr_depth; otherwise skipped)
//   Fixed per bounce: a delta material still consumes +0..+3 (bdpt) or draws them unused (pt);
//   emission and misses draw nothing. With kQmcDims 34, bounces 1-4 are Sobol' (of a pinhole).
//   The light pick walks the light tree (scene/light_tree.h) with +0 alone, rescaled per level.
//   pt with resampled direct light (PtSettings::light_candidates M > 1, integrator/
//   nee_resample.h): +1 chooses among the candidates, and 3 (M - 1) single numbers (pick, point)
//   for candidates 2..M follow +3, always drawn, so the BSDF pair and what follows it start
//   3 (M - 1) dims later, rounded up to even by uniform2(); the table below is that of M = 1.
//   To add draws to a bounce, better put them after +7 as whole pairs and raise
//   kCameraBounceDims by their count rounded up to even.
constexpr uint32_t kCameraFilter = 0;
constexpr uint32_t kCameraLens = 2;
constexpr uint32_t kCameraBounce0 = 2;  // of a pinhole; + 2 with an aperture
constexpr uint32_t kCameraBounceDims = 8;
constexpr uint32_t kBounceLightPick = 0;
constexpr uint32_t kBounceLightPoint = 2;
constexpr uint32_t kBounceBsdfDir = 4;
constexpr uint32_t kBounceLobe = 6;
constexpr uint32_t kBounceRoulette = 7;
constexpr uint32_t camera_bounce_dim(bool aperture, uint32_t bounce) {
    return kCameraBounce0 + (aperture ? 2u : 0u) + (bounce - 1u) * kCameraBounceDims;
}

// ---- Light paths (lt, and the light pass of bdpt / lvc / cis) ----
//   dim 0             light pick by power
//   dims 2, 3         point on the light (dim 1 unused: the pair starts even)
//   dims 4, 5         emitted direction (env map and sun: through the scene's disk)
//   then, per vertex from dim 6 on, in order:
//     (a lens pair, only with an aperture, for each connection to the camera: at the emitter
//      when it is visible to the camera (lt), at each vertex the camera sees (lt, bdpt))
//     +0, +1          BSDF direction
//     +2              BSDF lobe choice
//     +3              Russian roulette (only at depth >= rr_depth)
//   With a pinhole a bounce is 4 dims from kLightBounce0; with an aperture its place depends on
//   which connections were made (distinct dimensions all the same).
constexpr uint32_t kLightPathPick = 0;
constexpr uint32_t kLightPathPoint = 2;
constexpr uint32_t kLightPathDirection = 4;
constexpr uint32_t kLightBounce0 = 6;
constexpr uint32_t kLightBounceDims = 4;

// ---- Connections of a camera vertex (lvc, cis; bdpt draws none), own stream per depth ----
//   Rng::hashed: every number past kQmcDims. The cache is rebuilt every iteration, so the same
//   pick in a pixel's next sample addresses another cache: nothing for Sobol' to stratify, and
//   a hashed number costs a third of a scrambled one (bench/results/2026-12-01-qmc/).
//   lvc: +0 .. N-1       N uniform cache picks (N = connections), one number each
//   cis: +0 .. M-1       M uniform candidates, then M .. M+N-1 the N resampled picks
//   Counts vary with the settings, never with the path.

// ---- Motion blur (scene/motion.h), apart from the table above ----
//   A camera path's shutter time is no dimension of its stream: motion_time(rng) reads the
//   path's (scramble, index) under a salt of its own (1D Owen-scrambled Sobol', stratified per
//   pixel), so no draw above moves and scenes without motion keep their bits.

// ---- AOV pass (aov.cpp: depth, normal, albedo features) ----
//   dims 0, 1 the pixel filter, 2, 3 the lens (with an aperture), then three single numbers per
//   bounce through mirrors and clear glass (direction x, y, lobe), in order: the first bounce's
//   direction is a pair, later ones straddle pairs (features only, not the image).

}  // namespace lantern
