// An environment map: the radiance arriving from infinitely far away in every direction, as an
// equirectangular (latitude-longitude) image, and a way to pick directions in proportion to it.
// Direction (x, y, z), y up: column u = atan2(z, x) / 2pi (turned by the rotation about +y),
// row v = acos(y) / pi from the top. Radiance is constant over a texel, and directions are drawn
// from that same piecewise-constant function times sin(theta) (each row's solid angle), so the
// density sample() gives is exactly the one pdf() returns (pbrt-v4's ImageInfiniteLight).
#pragma once

#include <vector>

#include "base/errors.hpp"
#include "math/distribution.hpp"
#include "math/vec.hpp"
#include "scene/value_limits.hpp"

namespace tracer {

// The largest radiance a texel keeps: the one limit of every radiance (scene/value_limits.hpp).
inline constexpr float kMaxEnvironmentRadiance = kMaxEmission;

class EnvironmentMap {
 public:
  EnvironmentMap() = default;
  // `texels`: width x height linear RGB, rows from the top (+y); negative or non-finite values
  // become 0, values above kMaxEnvironmentRadiance become it. `rotation_degrees` turns the map about
  // +y (any finite angle). `cancel` is polled once a row while the sampling distribution is built.
  EnvironmentMap(int width, int height, std::vector<Vec3> texels, double rotation_degrees = 0.0,
                 CancelFlag cancel = nullptr);
  bool empty() const { return texels_.empty(); }
  // Texel values that were negative or not finite (read as 0), or above kMaxEnvironmentRadiance.
  size_t zeroed_values() const { return zeroed_; }
  size_t clamped_values() const { return clamped_; }
  // Whether no texel gives light: the map lights nothing.
  bool black() const { return black_; }
  const std::vector<Vec3>& texels() const { return texels_; }
  float rotation_turns() const { return rotation_; }
  int width() const { return width_; }
  int height() const { return height_; }
  Vec3 radiance(Vec3 dir) const;
  // A unit direction drawn with density proportional to luminance, and that density per unit
  // solid angle; false (pdf 0) for a black map.
  bool sample(float u1, float u2, Vec3& dir, float& pdf) const;
  float pdf(Vec3 dir) const;

 private:
  Vec2 to_uv(Vec3 dir) const;
  Vec3 from_uv(Vec2 uv) const;
  int width_ = 0, height_ = 0;
  float rotation_ = 0.0f;  // in turns
  size_t zeroed_ = 0, clamped_ = 0;
  bool black_ = true;
  std::vector<Vec3> texels_;
  Distribution2D distribution_;
};

}  // namespace tracer
