// The numbers every stage draws: a low-discrepancy stream (core/sampler.h) that hands out the
// dimensions of one sample in order (which event takes which: core/sample_dims.h). Stateless
// apart from (seed, index, next dimension), so an image does not depend on how threads or GPU
// blocks are scheduled, and the same seed, settings and backend give the same bits.
// Pcg32 is the pseudo-random stream Rng was before issue 14, kept for Monte Carlo checks in tests
// that want a plain random source (and, with -DLANTERN_RNG_PCG, as Rng for bench/qmc_noise.py).
#pragma once

#include "core/sampler.h"

namespace lantern {

// PCG32 [O'Neill 2014]: 64-bit state, 32-bit output; the same bits as Rng before issue 14.
struct Pcg32 {
    uint64_t state = 0;
    uint64_t inc = 1;
    uint64_t key = 0;  // the stream's starting state, never changed by draws (motion_time's)

    LANTERN_HD static Pcg32 for_path(uint64_t seed, uint64_t iteration, uint64_t path) {
        Pcg32 r;
        r.inc = (mix64(seed * 0x632BE59BD9B4E019ull + iteration) << 1u) | 1u;
        r.state = mix64(mix64(seed ^ 0xA0761D6478BD642Full) + iteration * 0xE7037ED1A0B428DBull
                        + path);
        r.key = r.state;
        r.next();
        return r;
    }
    // Bench only: the camera streams of the old Rng (one per path of an iteration).
    LANTERN_HD static Pcg32 for_pixel(uint64_t seed, uint64_t pixel, uint64_t sample) {
        return for_path(seed, sample, pixel);
    }
    LANTERN_HD static Pcg32 for_camera(uint64_t seed, uint64_t iteration, int, int64_t path) {
        return for_path(seed, iteration, uint64_t(path));
    }
    LANTERN_HD static Pcg32 hashed(Pcg32 r) { return r; }  // (Rng::hashed's twin: no change)
    LANTERN_HD uint32_t next() {
        uint64_t old = state;
        state = old * 6364136223846793005ull + inc;
        uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
        uint32_t rot = uint32_t(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31));
    }
    // Uniform in [0, 1): 24 random bits, never rounds up to 1.
    LANTERN_HD float uniform() { return bits_to_unit(next()); }
    LANTERN_HD Vec2 uniform2() {
        float a = uniform();
        return {a, uniform()};
    }
};

#ifndef LANTERN_RNG_PCG
struct Rng {
    uint32_t seed = 0;    // the stream's scramble: seed, salt and pixel (or iteration), hashed
    uint32_t rindex = 0;  // the sample index within the scramble's sequence, bit-reversed
    uint32_t dim = 0;     // next dimension to hand out

    // Camera paths: sample `sample` of `pixel` (iteration x spp_per_iteration + its number in
    // the iteration), one scramble per pixel, so pixels are decorrelated and a pixel's samples
    // are stratified over the whole render, progressively.
    LANTERN_HD static Rng for_pixel(uint64_t seed, uint64_t pixel, uint64_t sample) {
        return make(stream_seed(seed, pixel, 0x5049584Cull + (sample >> 32)), sample);
    }
    // Camera path `path` of an iteration (pixel path / spp_per_iteration, the pixel's sample
    // iteration x spp_per_iteration + path % spp_per_iteration).
    LANTERN_HD static Rng for_camera(uint64_t seed, uint64_t iteration, int spp_per_iteration,
                                     int64_t path) {
        const uint64_t spp = uint64_t(spp_per_iteration > 0 ? spp_per_iteration : 1);
        return for_pixel(seed, uint64_t(path) / spp, iteration * spp + uint64_t(path) % spp);
    }
    // Light paths (and any stream numbered within an iteration): path `path` of the iteration's
    // sequence, scrambled per iteration, so the iteration's paths are stratified as one set.
    LANTERN_HD static Rng for_path(uint64_t seed, uint64_t iteration, uint64_t path) {
        return make(stream_seed(seed, iteration, 0x50415448ull + (path >> 32)), path);
    }
    // The same stream with every number hashed (its dimensions start at kQmcDims): for draws
    // that stratification cannot help, such as picks from a light-vertex cache that is rebuilt
    // every iteration (the same pick of sample k and sample k + 1 addresses different caches).
    LANTERN_HD static Rng hashed(Rng r) {
        r.dim = kQmcDims;
        return r;
    }
    LANTERN_HD uint32_t index() const { return reverse_bits32(rindex); }
    // 32 uniform bits (one dimension).
    LANTERN_HD uint32_t next() { return sample_bits(rindex, seed, dim++); }
    // Uniform in [0, 1): 24 bits, never rounds up to 1 (one dimension).
    LANTERN_HD float uniform() { return bits_to_unit(next()); }
    // A stratified pair: starts at an even dimension (skipping one if needed), so the pair is
    // always the two dimensions of one padded 2D Sobol' set; its shuffled index is made once.
    LANTERN_HD Vec2 uniform2() {
        const uint32_t d = dim + (dim & 1u);
        dim = d + 2u;
        if (d >= kQmcDims)
            return {bits_to_unit(sample_hashed(rindex, seed, d)),
                    bits_to_unit(sample_hashed(rindex, seed, d + 1u))};
        const uint32_t s = sobol_shuffled(rindex, seed, d >> 1);
        return {bits_to_unit(sobol_owen(s, seed, d)), bits_to_unit(sobol_owen(s, seed, d + 1u))};
    }

  private:
    LANTERN_HD static Rng make(uint32_t seed, uint64_t index) {
        Rng r;
        r.seed = seed;
        r.rindex = reverse_bits32(uint32_t(index));
        r.dim = 0;
        return r;
    }
};
#else
using Rng = Pcg32;  // bench/qmc_noise.py's reference build
#endif

}  // namespace lantern
