// A stateless low-discrepancy sampler: (sample index, stream key, dimension) -> [0, 1).
// Sobol' points, nested-uniform (Owen) scrambled by a hash, padded in 2D: dimensions (2g, 2g+1)
// are Sobol' dimensions 0 and 1 at an index shuffled per group g [Burley 2020, "Practical
// Hash-based Owen Scrambling", JCGT 9(4), sections 3-5]. Past kQmcDims, a plain hash.
#pragma once

#include "core/math.h"

namespace lantern {

// Dimensions served by scrambled Sobol' points; later ones are hashed (see core/sample_dims.h).
constexpr uint32_t kQmcDims = 64;

LANTERN_HD inline uint64_t mix64(uint64_t z) {  // SplitMix64 finaliser
    z += 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

LANTERN_HD inline uint32_t reverse_bits32(uint32_t x) {
#ifdef __CUDA_ARCH__
    return __brev(x);
#else
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4);
    x = ((x >> 8) & 0x00FF00FFu) | ((x & 0x00FF00FFu) << 8);
    return (x >> 16) | (x << 16);
#endif
}

// ---- Sobol' dimensions 0 and 1, as 32-bit fractions ----
// Dimension 0 is van der Corput's radical inverse: generator matrix = the bit reversal.
// Dimension 1 is Joe & Kuo's first entry (primitive polynomial x + 1, m_1 = 1): its direction
// numbers obey v_{k+1} = v_k ^ (v_k >> 1) from v_0 = 2^31, so v_k has fraction bit t exactly
// when t is a bit-subset of k (Lucas), and output bit t is the xor of index bits k over the
// supersets of t: a superset-sum over the five bits of the position, then the bit reversal.
LANTERN_HD inline uint32_t sobol_dim0(uint32_t i) { return reverse_bits32(i); }
LANTERN_HD inline uint32_t sobol_dim1(uint32_t i) {
    i ^= (i >> 1) & 0x55555555u;
    i ^= (i >> 2) & 0x33333333u;
    i ^= (i >> 4) & 0x0F0F0F0Fu;
    i ^= (i >> 8) & 0x00FF00FFu;
    i ^= (i >> 16) & 0x0000FFFFu;
    return reverse_bits32(i);
}
// The same from its direction numbers, one per index bit (the reference the tests compare to).
LANTERN_HD inline uint32_t sobol_dim1_reference(uint32_t i) {
    uint32_t r = 0, v = 0x80000000u;
    for (; i != 0; i >>= 1, v ^= v >> 1)
        if (i & 1u) r ^= v;
    return r;
}

// ---- Owen scrambling by a hash [Burley 2020, section 3] ----
// A bijection of 32-bit words in which bit j depends only on bits 0..j (every step is an addition
// or an xor with a product by an even constant), so applied to reversed bits it permutes each
// binary interval's two halves by a function of the interval: a nested uniform scramble (the
// paper's Laine-Karras-style hash and constants).
LANTERN_HD inline uint32_t lk_permute(uint32_t x, uint32_t seed) {
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}
LANTERN_HD inline uint32_t owen_scramble(uint32_t x, uint32_t seed) {
    return reverse_bits32(lk_permute(reverse_bits32(x), seed));
}

LANTERN_HD inline uint32_t hash_seed32(uint64_t key, uint64_t salt) {
    return uint32_t(mix64(key ^ mix64(salt)) >> 32);
}

// ---- The sampler: 32 uniform bits for (index, key, dim) ----
// Group g = dim / 2 draws Sobol' point shuffle_g(index), where shuffle_g is a nested uniform
// scramble of the index bits [Burley 2020, section 4]: it maps every aligned block of 2^k
// indices onto an aligned block, so the first 2^k samples of a pixel stay a (0, k, 2)-net in
// every pair while different pairs are decorrelated. Each dimension then gets its own scramble.
LANTERN_HD inline uint32_t sample_bits(uint32_t index, uint64_t key, uint32_t dim) {
    if (dim >= kQmcDims)
        return uint32_t(mix64(key ^ mix64((uint64_t(index) << 32) | dim)) >> 32);  // hashed
    const uint32_t group = dim >> 1;
    const uint32_t shuffled = owen_scramble(index, hash_seed32(key, 0x5348554600000000ull | group));
    const uint32_t x = (dim & 1u) ? sobol_dim1(shuffled) : sobol_dim0(shuffled);
    return owen_scramble(x, hash_seed32(key, 0x4F57454E00000000ull | dim));
}

// In [0, 1): 24 bits, never rounds up to 1.
LANTERN_HD inline float bits_to_unit(uint32_t b) { return float(b >> 8) * 0x1p-24f; }

LANTERN_HD inline float sample_1d(uint32_t index, uint64_t key, uint32_t dim) {
    return bits_to_unit(sample_bits(index, key, dim));
}

// The key of a stream: a camera path's is its pixel's (every sample of a pixel shares one
// scramble), a light path's its iteration's; the seed and a per-integrator salt always enter.
LANTERN_HD inline uint64_t stream_key(uint64_t seed, uint64_t a, uint64_t b) {
    return mix64(mix64(seed ^ 0xA0761D6478BD642Full) + a * 0xE7037ED1A0B428DBull + mix64(b));
}

}  // namespace lantern
