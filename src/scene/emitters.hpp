// The emissive triangles as area lights for the path integrator: each with its true area and
// normal, chosen in proportion to its power (luminance of its mean emission, textured or not,
// times area: a triangle over black texels is none of them), then a direction toward
// it uniformly in the solid angle it subtends where that angle is large (math/spherical_triangle.hpp),
// else a point on it uniformly by area. Emission is one-sided, from the face the winding makes the front
// (counter-clockwise seen from the lit side), as in pbrt and the measured Cornell box: a lamp mounted just below a
// ceiling must not light the gap above it.
#pragma once

#include <cstdint>
#include <vector>

#include "math/vec.hpp"

namespace tracer {

struct Scene;
struct Triangle;

struct EmitterSample {
  Vec3 point;  // on the emitter
  Vec3 wi;     // unit direction from the shading point to `point`
  float distance;
  Vec3 radiance;  // what the emitter emits at `point` (scene/emission.hpp)
  float pdf;      // solid-angle density at the shading point (selection times area density)
};

class Emitters {
 public:
  Emitters() = default;
  // Every non-degenerate triangle with an emissive material. `solid_angle` false: every point by
  // area (the estimator before solid-angle sampling, which tests compare against).
  explicit Emitters(const Scene& scene, bool solid_angle = true);
  bool empty() const { return keys_.empty(); }
  size_t size() const { return keys_.size(); }
  // A point on an emitter seen from `from`, by three uniform numbers; false if it has no solid
  // angle there (seen edge-on or from behind, or `from` lies on it).
  bool sample(const Scene& scene, Vec3 from, float u_select, float u1, float u2, EmitterSample& out) const;
  // The solid-angle density with which sample() picks the point `to` on scene triangle `tri`
  // (placed by instance `inst`, kInvalidIndex in a flat scene) from `from`: 0 when it is not one
  // of the emitters.
  float pdf(const Scene& scene, uint32_t tri, uint32_t inst, Vec3 from, Vec3 to) const;
  uint64_t memory_bytes() const { return keys_.capacity() * (sizeof(uint64_t) + 3 * sizeof(float)); }

  // Solid angles within which a triangle is sampled by solid angle: below, its directions are
  // nearly parallel and area sampling is as good (and the spherical angles lose precision);
  // above, nearly a hemisphere, where the spherical triangle's arcs degenerate (pbrt-v4's bounds).
  static constexpr double kMinSolidAngle = 3e-4, kMaxSolidAngle = 6.22;

 private:
  // An emitter's key: its instance + 1 (0 in a flat scene) above its scene triangle index.
  static uint64_t key(uint32_t tri, uint32_t inst) { return (uint64_t(inst + 1) << 32) | tri; }
  // Whether world triangle `t` is sampled by solid angle from `from` (its solid angle there).
  bool by_solid_angle(const Triangle& t, Vec3 from, double& omega) const;
  bool solid_angle_ = true;
  std::vector<uint64_t> keys_;  // key() of each emitter, ascending
  std::vector<float> cdf_;      // cdf_[i]: the probability of choosing one of keys_[0..i]
  std::vector<float> pmf_;      // probability of choosing keys_[i]
  std::vector<float> area_;
};

}  // namespace tracer
