// Counter-based random numbers: a pure function of (pixel, sample, dimension), so an image
// never depends on thread count, scheduling order or tile size.
#pragma once

#include <array>
#include <cstdint>

namespace tracer {

// PCG-RXS-M-XS 32-bit output permutation applied to one LCG step (Jarzynski & Olano 2020,
// "Hash Functions for GPU Rendering": the best quality/speed trade-off of the hashes surveyed).
constexpr uint32_t pcg_hash(uint32_t input) {
  const uint32_t state = input * 747796405u + 2891336453u;
  const uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

// Uniform float in [0, 1) from the top 24 bits.
constexpr float to_unit_float(uint32_t bits) { return static_cast<float>(bits >> 8) * 0x1p-24f; }

// Random stream for one (pixel, sample): draw(k) is the k-th dimension.
struct SampleRng {
  uint32_t key;
  constexpr SampleRng(uint32_t pixel, uint32_t sample, uint32_t seed = 0)
      : key(pcg_hash(pcg_hash(pixel ^ (seed * 0x9e3779b9u)) + sample)) {}
  constexpr float draw(uint32_t dimension) const { return to_unit_float(pcg_hash(key + dimension * 0x68e31da4u)); }
  // PixelSampler's interface: dimension d of set `set` is draw(4 set + d), unstratified.
  template <int N>
  constexpr std::array<float, N> get(uint32_t set) const {
    std::array<float, N> u{};
    for (int d = 0; d < N; ++d) u[d] = draw(4 * set + uint32_t(d));
    return u;
  }
};

}  // namespace tracer
