// An environment map: the radiance arriving from infinitely far away in every direction, as an
// equirectangular (latitude-longitude) image, and a way to pick directions in proportion to it.
// Direction (x, y, z), y up: column u = atan2(z, x) / 2pi (turned by the rotation about +y),
// row v = acos(y) / pi from the top. Radiance is constant over a texel, and directions are drawn
// from that same piecewise-constant function times sin(theta) (each row's solid angle), so the
// density sample() gives is exactly the one pdf() returns (pbrt-v4's ImageInfiniteLight).
#pragma once

#include <vector>

#include "math/distribution.hpp"
#include "math/vec.hpp"

namespace tracer {

class EnvironmentMap {
 public:
  EnvironmentMap() = default;
  // `texels`: width x height linear RGB, rows from the top (+y); negative or non-finite values
  // become 0. `rotation_degrees` turns the map about +y.
  EnvironmentMap(int width, int height, std::vector<Vec3> texels, float rotation_degrees = 0.0f);
  bool empty() const { return texels_.empty(); }
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
  std::vector<Vec3> texels_;
  Distribution2D distribution_;
};

}  // namespace tracer
