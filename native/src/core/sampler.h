// A stateless low-discrepancy sampler: (sample index, stream seed, dimension) -> 32 bits.
// Sobol' points, nested-uniform (Owen) scrambled by a hash, padded in 2D: dimensions (2g, 2g+1)
// are Sobol' dimensions 0 and 1 at an index shuffled per group g [Burley 2020, "Practical
// Hash-based Owen Scrambling", JCGT 9(4), sections 3-5]. Past kQmcDims, a plain hash.
#pragma once

#include "core/math.h"

namespace lantern {

// Dimensions served by scrambled Sobol' points; later ones are hashed: the camera's and the first
// four bounces' of a camera path (core/sample_dims.h), where stratification pays. 64 gave the
// same variance at equal spp, and a hashed number costs a third of a scrambled one
// (bench/results/2026-12-01-qmc/). Even.
constexpr uint32_t kQmcDims = 34;
static_assert(kQmcDims % 2 == 0, "scrambled dimensions come in pairs");

LANTERN_HD inline uint64_t mix64(uint64_t z) {  // SplitMix64 finaliser
    z += 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

// A 32-bit integer hash: two xorshift-multiply rounds (the "lowbias32" constants of Wellons'
// hash-prospector search). A bijection with full avalanche; 7 operations.
LANTERN_HD inline uint32_t hash32(uint32_t x) {
    x ^= x >> 16;
    x *= 0x7FEB352Du;
    x ^= x >> 15;
    x *= 0x846CA68Bu;
    return x ^ (x >> 16);
}

// The scramble seed j of a stream: one hash of the stream's seed and j.
LANTERN_HD inline uint32_t sub_seed(uint32_t seed, uint32_t j) {
    return hash32(seed ^ (j * 0x9E3779B9u));
}

#ifndef __CUDA_ARCH__
// The bit reversal of every byte (host): a reversal is then four lookups, half the instructions
// of the shift-and-mask steps (bench/sampler_bench.cpp).
struct ByteReversal {
    uint8_t r[256];
    constexpr ByteReversal() : r() {
        for (int b = 0; b < 256; ++b) {
            int v = 0;
            for (int k = 0; k < 8; ++k) v |= ((b >> k) & 1) << (7 - k);
            r[b] = uint8_t(v);
        }
    }
};
inline constexpr ByteReversal kByteReversal{};
#endif

LANTERN_HD inline uint32_t reverse_bits32(uint32_t x) {
#ifdef __CUDA_ARCH__
    return __brev(x);
#else
    const uint8_t* r = kByteReversal.r;
    return (uint32_t(r[x & 0xFFu]) << 24) | (uint32_t(r[(x >> 8) & 0xFFu]) << 16) |
           (uint32_t(r[(x >> 16) & 0xFFu]) << 8) | uint32_t(r[x >> 24]);
#endif
}

// ---- Sobol' dimensions 0 and 1, as 32-bit fractions ----
// Dimension 0 is van der Corput's radical inverse: generator matrix = the bit reversal.
// Dimension 1 is Joe & Kuo's first entry (primitive polynomial x + 1, m_1 = 1): its direction
// numbers obey v_{k+1} = v_k ^ (v_k >> 1) from v_0 = 2^31, so v_k has fraction bit t exactly
// when t is a bit-subset of k (Lucas), and output bit t is the xor of index bits k over the
// supersets of t: a superset-sum over the five bits of the position, then the bit reversal.
LANTERN_HD inline uint32_t sobol_superset(uint32_t i) {
    i ^= (i >> 1) & 0x55555555u;
    i ^= (i >> 2) & 0x33333333u;
    i ^= (i >> 4) & 0x0F0F0F0Fu;
    i ^= (i >> 8) & 0x00FF00FFu;
    return i ^ (i >> 16);
}
LANTERN_HD inline uint32_t sobol_dim0(uint32_t i) { return reverse_bits32(i); }
LANTERN_HD inline uint32_t sobol_dim1(uint32_t i) { return reverse_bits32(sobol_superset(i)); }
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

// ---- The sampler: 32 uniform bits of (index, seed, dim) ----
// Group g = dim / 2 draws Sobol' point s = shuffle_g(index), where shuffle_g is a nested uniform
// scramble of the index bits [Burley 2020, section 4]: it maps every aligned block of 2^k
// indices onto an aligned block, so the first 2^k samples of a pixel stay a (0, k, 2)-net in
// every pair while different pairs are decorrelated. Each dimension then gets its own scramble.
// Written with the reversals folded: sobol_dim0(s) = R(s), so owen(sobol_dim0(s)) =
// R(lk(s)); sobol_dim1(s) = R(superset(s)), so owen(sobol_dim1(s)) = R(lk(superset(s))); and
// s = R(lk(R(index))), with R(index) computed once per stream (`rindex`). Seeds: sub_seed(seed,
// 3g) shuffles group g, 3g + 1 and 3g + 2 scramble its two dimensions.
LANTERN_HD inline uint32_t sobol_shuffled(uint32_t rindex, uint32_t seed, uint32_t group) {
    return reverse_bits32(lk_permute(rindex, sub_seed(seed, 3u * group)));
}
LANTERN_HD inline uint32_t sobol_owen(uint32_t s, uint32_t seed, uint32_t dim) {
    const uint32_t x = (dim & 1u) ? sobol_superset(s) : s;
    return reverse_bits32(lk_permute(x, sub_seed(seed, 3u * (dim >> 1) + 1u + (dim & 1u))));
}
// Past kQmcDims: a hash of (seed, dim, index), independent across all three.
LANTERN_HD inline uint32_t sample_hashed(uint32_t rindex, uint32_t seed, uint32_t dim) {
    return hash32(sub_seed(seed, dim + 0x40000000u) ^ rindex);
}
// One dimension; `rindex` = reverse_bits32(index).
LANTERN_HD inline uint32_t sample_bits(uint32_t rindex, uint32_t seed, uint32_t dim) {
    if (dim >= kQmcDims) return sample_hashed(rindex, seed, dim);
    return sobol_owen(sobol_shuffled(rindex, seed, dim >> 1), seed, dim);
}

// In [0, 1): 24 bits, never rounds up to 1.
LANTERN_HD inline float bits_to_unit(uint32_t b) { return float(b >> 8) * 0x1p-24f; }

// The seed of a stream: a camera path's is its pixel's (every sample of a pixel shares one
// scramble), a light path's its iteration's; the seed and a per-integrator salt always enter.
// Hashed once, when the stream is made; the per-dimension seeds are then one hash32 each.
LANTERN_HD inline uint32_t stream_seed(uint64_t seed, uint64_t a, uint64_t b) {
    return uint32_t(
        mix64(mix64(seed ^ 0xA0761D6478BD642Full) + a * 0xE7037ED1A0B428DBull + mix64(b)) >> 32);
}

}  // namespace lantern
