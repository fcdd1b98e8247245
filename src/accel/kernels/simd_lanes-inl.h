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

#include "accel/kernels/lane_kernels.hpp"

// The leaf actions the traversals hand their walkers are lambdas, which always_inline on the
// walker does not reach: without this they are called per leaf (measured: 8 more instructions per
// AO ray, docs/bench/LOG.md).
#ifndef TRACER_INLINE_LAMBDA
#define TRACER_INLINE_LAMBDA __attribute__((always_inline))
#endif

HWY_BEFORE_NAMESPACE();
namespace tracer {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// The kernels, compiled for this target.
#include "accel/kernels/lane_kernels-inl.h"  // NOLINT(build/include): a per-target copy, see that file

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

// The slab test's near and far planes of the box [lo, hi] for the rays of lanes [i, i + N): each
// ray enters a slab at hi where its direction is negative (nx, ny, nz: -1 there, else 0) and at lo
// elsewhere. Written once for every traversal that follows several rays as lanes.
template <class D>
HWY_INLINE void NearFarPlanes(D d, const int32_t* nx, const int32_t* ny, const int32_t* nz, size_t i,
                              const Lanes3<hn::Vec<D>>& lo, const Lanes3<hn::Vec<D>>& hi, Lanes3<hn::Vec<D>>& near,
                              Lanes3<hn::Vec<D>>& far) {
  const hn::RebindToSigned<D> di;
  const auto negx = hn::RebindMask(d, hn::Lt(hn::Load(di, nx + i), hn::Zero(di)));
  const auto negy = hn::RebindMask(d, hn::Lt(hn::Load(di, ny + i), hn::Zero(di)));
  const auto negz = hn::RebindMask(d, hn::Lt(hn::Load(di, nz + i), hn::Zero(di)));
  near = {hn::IfThenElse(negx, hi.x, lo.x), hn::IfThenElse(negy, hi.y, lo.y), hn::IfThenElse(negz, hi.z, lo.z)};
  far = {hn::IfThenElse(negx, lo.x, hi.x), hn::IfThenElse(negy, lo.y, hi.y), hn::IfThenElse(negz, lo.z, hi.z)};
}

}  // namespace HWY_NAMESPACE
}  // namespace tracer
HWY_AFTER_NAMESPACE();

#endif  // include guard toggle
