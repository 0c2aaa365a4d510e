// Counter-based random numbers: every path owns a stream derived from (seed, iteration, path),
// so an image does not depend on how threads or GPU blocks are scheduled.
#pragma once

#include "core/math.h"

namespace lantern {

LANTERN_HD inline uint64_t mix64(uint64_t z) {  // SplitMix64 finaliser
    z += 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

// PCG32 (O'Neill 2014): 64-bit state, 32-bit output.
struct Rng {
    uint64_t state = 0;
    uint64_t inc = 1;

    LANTERN_HD static Rng for_path(uint64_t seed, uint64_t iteration, uint64_t path) {
        Rng r;
        r.inc = (mix64(seed * 0x632BE59BD9B4E019ull + iteration) << 1u) | 1u;
        r.state = mix64(mix64(seed ^ 0xA0761D6478BD642Full) + iteration * 0xE7037ED1A0B428DBull
                        + path);
        r.next();
        return r;
    }
    LANTERN_HD uint32_t next() {
        uint64_t old = state;
        state = old * 6364136223846793005ull + inc;
        uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
        uint32_t rot = uint32_t(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31));
    }
    // Uniform in [0, 1): 24 random bits, never rounds up to 1.
    LANTERN_HD float uniform() { return float(next() >> 8) * 0x1p-24f; }
    LANTERN_HD Vec2 uniform2() {
        float a = uniform();
        return {a, uniform()};
    }
};

}  // namespace lantern
