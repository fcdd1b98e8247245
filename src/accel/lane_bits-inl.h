// Lane masks as plain bit sets, for the kernels that follow up to 16 rays as SIMD lanes
// (wide_bvh_packets.cpp, bvh_bundles.cpp). Per-target code: include it after foreach_target.h;
// the guard toggles per target as Highway's -inl.h convention requires.
#if defined(TRACER_ACCEL_LANE_BITS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef TRACER_ACCEL_LANE_BITS_INL_H_
#undef TRACER_ACCEL_LANE_BITS_INL_H_
#else
#define TRACER_ACCEL_LANE_BITS_INL_H_
#endif

#include <hwy/highway.h>

#include <cstdint>

HWY_BEFORE_NAMESPACE();
namespace tracer {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// The lanes set in `m`, as the low bits of the result (a vector holds at most 16 float lanes).
template <class D>
HWY_INLINE uint32_t Bits(D d, hn::Mask<D> m) {
  uint8_t bytes[8] = {0};
  hn::StoreMaskBits(d, m, bytes);
  return uint32_t(bytes[0]) | uint32_t(bytes[1]) << 8;
}

// The mask whose lanes are the low bits of `bits`.
template <class D>
HWY_INLINE hn::Mask<D> LaneMask(D d, uint32_t bits) {
  const uint8_t bytes[8] = {uint8_t(bits), uint8_t(bits >> 8), 0, 0, 0, 0, 0, 0};
  return hn::LoadMaskBits(d, bytes);
}

// Bits [first, first + lanes) of `mask`, shifted down: one vector's share of a 16-lane set.
HWY_INLINE uint32_t ChunkBits(uint32_t mask, size_t first, size_t lanes) {
  return (mask >> first) & (lanes >= 32 ? ~0u : (1u << lanes) - 1u);
}

}  // namespace HWY_NAMESPACE
}  // namespace tracer
HWY_AFTER_NAMESPACE();

#endif  // include guard toggle
