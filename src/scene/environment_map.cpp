#include "scene/environment_map.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "math/sampling.hpp"

namespace tracer {

namespace {
constexpr float kPi = std::numbers::pi_v<float>;
}

EnvironmentMap::EnvironmentMap(int width, int height, std::vector<Vec3> texels, double rotation_degrees,
                               CancelFlag cancel)
    : width_(width), height_(height), texels_(std::move(texels)) {
  // Reduced in double, so a huge angle neither overflows a float nor loses the turn's fraction.
  const double turns = std::isfinite(rotation_degrees) ? std::fmod(rotation_degrees, 360.0) / 360.0 : 0.0;
  rotation_ = float(turns - std::floor(turns));
  if (rotation_ >= 1.0f) rotation_ = 0.0f;
  std::vector<float> weights(texels_.size());
  for (int y = 0; y < height_; ++y) {
    if ((y & 63) == 0) throw_if_cancelled(cancel);
    // The row's share of the sphere: sin(theta) at its centre (cells at the poles are small).
    const float sin_theta = std::sin(kPi * (float(y) + 0.5f) / float(height_));
    for (int x = 0; x < width_; ++x) {
      Vec3& t = texels_[size_t(y) * size_t(width_) + size_t(x)];
      for (float* c : {&t.x, &t.y, &t.z}) {
        if (!(std::isfinite(*c) && *c >= 0.0f)) {
          ++zeroed_;
          *c = 0.0f;
        } else if (*c > kMaxEnvironmentRadiance) {
          ++clamped_;
          *c = kMaxEnvironmentRadiance;
        }
      }
      const float w = luminance(t) * sin_theta;
      black_ = black_ && !(w > 0.0f);
      weights[size_t(y) * size_t(width_) + size_t(x)] = w;
    }
  }
  distribution_ = Distribution2D(weights, size_t(width_), size_t(height_), [cancel](size_t y) {
    if ((y & 63) == 0) throw_if_cancelled(cancel);
  });
}

Vec2 EnvironmentMap::to_uv(Vec3 d) const {
  float u = std::atan2(d.z, d.x) * (0.5f / kPi) - rotation_;
  u -= std::floor(u);
  const float v = std::acos(std::clamp(d.y, -1.0f, 1.0f)) / kPi;
  return {std::min(u, 0x1.fffffep-1f), std::min(v, 0x1.fffffep-1f)};
}

Vec3 EnvironmentMap::from_uv(Vec2 uv) const {
  const float phi = 2.0f * kPi * (uv.x + rotation_), theta = kPi * uv.y;
  const float s = std::sin(theta);
  return {s * std::cos(phi), std::cos(theta), s * std::sin(phi)};
}

Vec3 EnvironmentMap::radiance(Vec3 dir) const {
  const Vec2 uv = to_uv(dir);
  const int x = std::min(int(uv.x * float(width_)), width_ - 1), y = std::min(int(uv.y * float(height_)), height_ - 1);
  return texels_[size_t(y) * size_t(width_) + size_t(x)];
}

bool EnvironmentMap::sample(float u1, float u2, Vec3& dir, float& pdf) const {
  float uv_pdf = 0.0f;
  const Vec2 uv = distribution_.sample(u1, u2, uv_pdf);
  const float sin_theta = std::sin(kPi * uv.y);
  if (!(uv_pdf > 0.0f) || !(sin_theta > 0.0f)) return false;
  dir = from_uv(uv);
  pdf = uv_pdf / (2.0f * kPi * kPi * sin_theta);
  return true;
}

float EnvironmentMap::pdf(Vec3 dir) const {
  const Vec2 uv = to_uv(dir);
  const float sin_theta = std::sin(kPi * uv.y);
  if (!(sin_theta > 0.0f)) return 0.0f;
  return distribution_.pdf(uv) / (2.0f * kPi * kPi * sin_theta);
}

}  // namespace tracer
