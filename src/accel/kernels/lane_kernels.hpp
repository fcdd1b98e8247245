// The ray/box slab test and the watertight ray/triangle test, each written once over a lane type,
// as Embree writes its tests once over vfloat<M>: lane_kernels-inl.h holds them. `L` is
// ScalarLanes (below: one float per value) or SimdLanes<D> (simd_lanes-inl.h: a Highway vector),
// and its lanes are whatever the caller makes them: several children of a wide node or several
// triangles of a leaf pack against one ray, or several rays (a packet, a bundle) against one box
// or triangle. Every caller loads its operands its own way and then runs these operations in this
// order, which is why every accelerator, traversal and SIMD target finds the same hits bit for bit.
#pragma once

#include "math/ray.hpp"

namespace tracer {

// One value per lane type: the scalar instance of the lane operations the kernels use besides
// arithmetic and comparisons (which both kinds of lane spell as operators).
struct ScalarLanes {
  using V = float;
  using M = bool;
  static V splat(float x) { return x; }
  static M and_(M a, M b) { return a & b; }
  static M or_(M a, M b) { return a | b; }
  static M and_not(M not_this, M b) { return !not_this & b; }
  // max(a, b) and min(a, b) that keep b when a is NaN (maxss/minss do exactly this).
  static V max_or_second(V a, V b) { return a > b ? a : b; }
  static V min_or_second(V a, V b) { return a < b ? a : b; }
};

// The kept-alive margin of the slab test's far distances (see RayBoxTest, which states why).
struct SlabGuards {
  // Boxes are also kept when entered up to ~16 ulps beyond tfar: a box's entry distance and a
  // triangle's t round differently, and a triangle hit at exactly the current closest t must
  // still be reached so ties resolve the same way as in brute force.
  static constexpr float kTieGuard = 1.0f + 0x1p-20f;
  // 1 + 2*gamma(3) (Ize 2013), folded into a second reciprocal: rounding never culls a box the ray touches.
  static constexpr float kFarGuard = 1.0f + 2.0f * 3.0f * 0x1p-24f / (1.0f - 3.0f * 0x1p-24f);
};

// The kernels for scalar code (SIMD code gets its own per-target copy through simd_lanes-inl.h).
#include "accel/kernels/lane_kernels-inl.h"  // IWYU pragma: export

}  // namespace tracer
