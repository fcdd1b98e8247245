// Axis-aligned bounding box.
#pragma once

#include <limits>

#include "math/vec.hpp"

namespace tracer {

struct Aabb {
  Vec3 lo{std::numeric_limits<float>::infinity()};
  Vec3 hi{-std::numeric_limits<float>::infinity()};

  void extend(Vec3 p) {
    lo = min(lo, p);
    hi = max(hi, p);
  }
  void extend(const Aabb& b) {
    lo = min(lo, b.lo);
    hi = max(hi, b.hi);
  }
  bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  Vec3 extent() const { return hi - lo; }
  Vec3 center() const { return (lo + hi) * 0.5f; }
  // Half the surface area: the SAH only needs ratios, so the factor 2 is dropped.
  float half_area() const {
    if (empty()) return 0.0f;
    const Vec3 e = extent();
    return e.x * e.y + e.y * e.z + e.z * e.x;
  }
  bool contains(const Aabb& b) const {
    return lo.x <= b.lo.x && lo.y <= b.lo.y && lo.z <= b.lo.z && hi.x >= b.hi.x && hi.y >= b.hi.y && hi.z >= b.hi.z;
  }
};

}  // namespace tracer
