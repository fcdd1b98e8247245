// The SIMD lane type of the kernels in lane_kernels.hpp (SimdLanes<D>: a Highway vector per
// value), and lane masks as plain bit sets for the traversals that follow up to 16 rays as lanes.
// Per-target code: include it after foreach_target.h; the guard toggles per target as Highway's
// -inl.h convention requires.
#if defined(TRACER_ACCEL_SIMD_LANES_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef TRACER_ACCEL_SIMD_LANES_INL_H_
#undef TRACER_ACCEL_SIMD_LANES_INL_H_
#else
#define TRACER_ACCEL_SIMD_LANES_INL_H_
#endif

#include <hwy/highway.h>

#include <cstdint>

#include "accel/lane_kernels.hpp"

HWY_BEFORE_NAMESPACE();
namespace tracer {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// The kernels, compiled for this target.
#include "accel/lane_kernels-inl.h"  // NOLINT(build/include): a per-target copy, see that file

// lane_kernels.hpp's lane operations on Highway vectors of tag D.
template <class D>
struct SimdLanes {
  using V = hn::Vec<D>;
  using M = hn::Mask<D>;
  static V splat(float x) { return hn::Set(D(), x); }
  static M and_(M a, M b) { return hn::And(a, b); }
  static M or_(M a, M b) { return hn::Or(a, b); }
  static M and_not(M not_this, M b) { return hn::AndNot(not_this, b); }
  // maxps/minps return their second operand whenever either is NaN, which is exactly the slab
  // test's rule, in one instruction instead of a compare and a blend; other targets spell it out.
  static V max_or_second(V a, V b) {
#if HWY_ARCH_X86 && HWY_TARGET != HWY_EMU128 && HWY_TARGET != HWY_SCALAR
    return hn::Max(a, b);
#else
    return hn::IfThenElse(a > b, a, b);
#endif
  }
  static V min_or_second(V a, V b) {
#if HWY_ARCH_X86 && HWY_TARGET != HWY_EMU128 && HWY_TARGET != HWY_SCALAR
    return hn::Min(a, b);
#else
    return hn::IfThenElse(a < b, a, b);
#endif
  }
};

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
