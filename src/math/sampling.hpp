// Sampling building blocks shared by the BSDFs and the light sampler: a shading frame, the
// standard warps from [0,1)^2 and the MIS heuristic.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include "math/vec.hpp"

namespace tracer {

inline float luminance(Vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

// An orthonormal basis around a unit normal (Duff et al. 2017, "Building an Orthonormal Basis,
// Revisited": branchless, continuous except at n.z = -1 where it flips sign cleanly).
struct Frame {
  Vec3 s, t, n;
  Frame() = default;
  explicit Frame(Vec3 normal) : n(normal) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float b = n.x * n.y * a;
    s = Vec3{1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x};
    t = Vec3{b, sign + n.y * n.y * a, -n.y};
  }
  Vec3 to_local(Vec3 v) const { return {dot(v, s), dot(v, t), dot(v, n)}; }
  Vec3 to_world(Vec3 v) const { return s * v.x + t * v.y + n * v.z; }
};

// Cosine-weighted direction about +z (Malley's method: a uniform disk point lifted to the
// hemisphere); pdf cos(theta)/pi.
inline Vec3 cosine_hemisphere(float u1, float u2) {
  const float r = std::sqrt(u1);
  const float phi = 2.0f * std::numbers::pi_v<float> * u2;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - u1))};
}

// A uniform point on the unit disk by Shirley and Chiu's concentric map: the square's strata stay
// compact on the disk, so stratified numbers give a stratified lens.
inline Vec2 concentric_disk(float u1, float u2) {
  const float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f;
  if (a == 0.0f && b == 0.0f) return {0.0f, 0.0f};
  constexpr float kQuarterPi = std::numbers::pi_v<float> / 4.0f;
  float r, phi;
  if (std::fabs(a) > std::fabs(b)) {
    r = a;
    phi = kQuarterPi * (b / a);
  } else {
    r = b;
    phi = 2.0f * kQuarterPi - kQuarterPi * (a / b);
  }
  return {r * std::cos(phi), r * std::sin(phi)};
}

// Uniform barycentrics (b1, b2) on a triangle: the square-root warp.
inline void uniform_triangle(float u1, float u2, float& b1, float& b2) {
  const float su = std::sqrt(u1);
  b1 = 1.0f - su;
  b2 = u2 * su;
}

// Veach's power heuristic (beta = 2) for one sample from each of two strategies.
inline float power_heuristic(float pdf_a, float pdf_b) {
  const float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  return a + b > 0.0f ? a / (a + b) : 0.0f;
}

}  // namespace tracer
