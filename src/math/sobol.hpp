// Stratified, low-discrepancy samples: Owen-scrambled Sobol points, shuffled and padded four
// dimensions at a time, after Brent Burley, "Practical Hash-based Owen Scrambling", JCGT 9(4),
// 2020 (the sampler Cycles calls Sobol-Burley).
//
// A pixel's sample k is point k of an Owen-scrambled 4D Sobol sequence whose order is itself
// Owen-scrambled; each group of four dimensions of a path takes its own scrambles (seeded by the
// pixel and the group), so groups are independent of each other ("padding") while the first 2^m
// samples of any group are stratified as a (0,m,2)-net in its first two dimensions. Everything is
// a pure function of (pixel, sample, group, seed): the image does not depend on threads, tiles,
// passes or ranks, and passes of samples [a, b) and [b, c) add up to [a, c).
#pragma once

#include <array>
#include <bit>
#include <cstdint>

#include "math/rng.hpp"

namespace tracer {

namespace sobol_detail {

constexpr uint32_t reverse_bits(uint32_t x) {
  x = __builtin_bswap32(x);  // std::byteswap is C++23
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  return ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
}

// Laine and Karras' hash-based permutation with Burley's constants: each output bit depends only
// on the input bits below it, so applied to bit-reversed values it is a nested uniform (Owen)
// scramble of the bits from the most significant down.
constexpr uint32_t laine_karras(uint32_t x, uint32_t seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}

// The generator matrices of Sobol dimensions 0-3 (Joe and Kuo's primitive polynomials and
// initial direction numbers: x+1; x^2+x+1 with m = 1,3; x^3+x+1 with m = 1,3,1), each column
// bit-reversed and the columns stored in reverse order: row p holds what bit 31-p of the index
// contributes, so the sum can be formed directly from a bit-reversed index.
struct Matrices {
  std::array<std::array<uint32_t, 4>, 32> rows{};
};

constexpr std::array<uint32_t, 32> directions(uint32_t s, uint32_t a, std::array<uint32_t, 3> m) {
  std::array<uint32_t, 33> v{};  // v[i]: direction number i (1-based) as a 32-bit fraction
  if (s == 0) {                  // dimension 0: the van der Corput sequence
    for (uint32_t i = 1; i <= 32; ++i) v[i] = 1u << (32 - i);
  } else {
    for (uint32_t i = 1; i <= s; ++i) v[i] = m[i - 1] << (32 - i);
    for (uint32_t i = s + 1; i <= 32; ++i) {
      v[i] = v[i - s] ^ (v[i - s] >> s);
      for (uint32_t k = 1; k < s; ++k) v[i] ^= ((a >> (s - 1 - k)) & 1u) * v[i - k];
    }
  }
  std::array<uint32_t, 32> out{};
  for (uint32_t b = 0; b < 32; ++b) out[b] = v[b + 1];  // index bit b adds direction b+1
  return out;
}

constexpr Matrices make_matrices() {
  const std::array<uint32_t, 32> dims[4] = {directions(0, 0, {}), directions(1, 0, {1, 0, 0}),
                                            directions(2, 1, {1, 3, 0}), directions(3, 1, {1, 3, 1})};
  Matrices m;
  for (uint32_t p = 0; p < 32; ++p) {
    for (int d = 0; d < 4; ++d) m.rows[p][d] = reverse_bits(dims[d][31 - p]);
  }
  return m;
}

inline constexpr Matrices kMatrices = make_matrices();

// The same sums for the top kIndexBits of a bit-reversed index, five bits at a time: chunk c,
// value v gives the XOR of the rows its bits select (2 KiB, one load per chunk instead of a loop
// whose every exit is a branch miss).
inline constexpr uint32_t kChunkBits = 5, kChunks = 4, kIndexBits = kChunkBits * kChunks;

struct ChunkTables {
  std::array<std::array<std::array<uint32_t, 4>, 1u << kChunkBits>, kChunks> sums{};
};

constexpr ChunkTables make_chunk_tables() {
  ChunkTables t;
  for (uint32_t c = 0; c < kChunks; ++c) {
    for (uint32_t v = 0; v < (1u << kChunkBits); ++v) {
      for (uint32_t j = 0; j < kChunkBits; ++j) {
        if (!((v >> j) & 1u)) continue;
        for (int d = 0; d < 4; ++d) t.sums[c][v][d] ^= kMatrices.rows[32 - kIndexBits + c * kChunkBits + j][d];
      }
    }
  }
  return t;
}

inline constexpr ChunkTables kChunkTables = make_chunk_tables();

}  // namespace sobol_detail

// Point `index` of Sobol dimension `dim` (0-3), unscrambled: for tests and as the definition.
constexpr uint32_t sobol_point(uint32_t index, int dim) {
  uint32_t x = 0;
  const uint32_t reversed = sobol_detail::reverse_bits(index);
  for (uint32_t p = 0; p < 32; ++p) {
    if ((reversed >> p) & 1u) x ^= sobol_detail::kMatrices.rows[p][dim];
  }
  return sobol_detail::reverse_bits(x);
}

// Burley's hash_combine: a seed per dimension from the set's seed, cheaply.
constexpr uint32_t combine_seed(uint32_t seed, uint32_t v) {
  return seed ^ (v + 0x9e3779b9u + (seed << 6) + (seed >> 2));
}

// Dimensions 0..N-1 (N <= 4) of sample `index` of the sequence scrambled by `seed`, as 32-bit
// fractions. The cost is one hash per dimension: the index's shuffle is itself an Owen scramble
// of the van der Corput sequence (dimension 0), so that dimension needs nothing more.
// `reversed` is reverse_bits(index), which every set of a sample shares.
template <int N>
constexpr std::array<uint32_t, N> sobol_burley_bits(uint32_t index, uint32_t reversed, uint32_t seed) {
  static_assert(N >= 1 && N <= 4);
  using namespace sobol_detail;
  // The shuffled index j, bit-reversed (bit p of r is bit 31-p of j). Dimension 0's point of j
  // is reverse(j) = r.
  const uint32_t r = laine_karras(reversed, seed);
  std::array<uint32_t, N> x{};
  x[0] = r;
  if constexpr (N > 1) {
    std::array<uint32_t, 4> sum{};
    for (uint32_t c = 0; c < kChunks; ++c) {
      const auto& part = kChunkTables.sums[c][(r >> (32 - kIndexBits + c * kChunkBits)) & ((1u << kChunkBits) - 1)];
      for (int d = 1; d < N; ++d) sum[d] ^= part[d];
    }
    // Only the low kIndexBits of the shuffled index are summed while the index is below
    // 2^kIndexBits (--spp allows at most 2^20): the bits above would add one fixed point to every
    // sample of the pixel (the points are linear in the index's bits), a digital shift that the
    // Owen scramble below randomises anyway. Past that, the other bits are summed one by one.
    if (index >= (1u << kIndexBits)) {
      for (uint32_t rest = r & ((1u << (32 - kIndexBits)) - 1); rest; rest &= rest - 1) {
        for (int d = 1; d < N; ++d) sum[d] ^= kMatrices.rows[std::countr_zero(rest)][d];
      }
    }
    // sum holds the bit-reversed points: scramble there, then reverse once.
    for (int d = 1; d < N; ++d) x[d] = reverse_bits(laine_karras(sum[d], combine_seed(seed, uint32_t(d))));
  }
  return x;
}

template <int N>
constexpr std::array<uint32_t, N> sobol_burley_bits(uint32_t index, uint32_t seed) {
  return sobol_burley_bits<N>(index, sobol_detail::reverse_bits(index), seed);
}

// The samples of one pixel: dimension set `set` gives N <= 4 dimensions in [0, 1), stratified
// over the pixel's samples and independent of every other set's.
// Callers take only the dimensions they use: each costs a hash.
struct PixelSampler {
  uint32_t key, index, reversed;
  constexpr PixelSampler(uint32_t pixel, uint32_t sample, uint32_t seed = 0)
      : key(pcg_hash(pixel ^ (seed * 0x9e3779b9u))), index(sample), reversed(sobol_detail::reverse_bits(sample)) {}
  template <int N>
  constexpr std::array<float, N> get(uint32_t set) const {
    const std::array<uint32_t, N> bits = sobol_burley_bits<N>(index, reversed, pcg_hash(key + set * 0x68e31da4u));
    std::array<float, N> u{};
    for (int d = 0; d < N; ++d) u[d] = to_unit_float(bits[d]);
    return u;
  }
};

}  // namespace tracer
