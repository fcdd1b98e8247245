// Directions toward a triangle drawn uniformly in the solid angle it subtends: Arvo 1995,
// "Stratified Sampling of Spherical Triangles" (the algorithm pbrt-v4 and Cycles also use for
// large emitters). Where a triangle covers much of a point's sky, a point drawn uniformly by area
// crowds the directions toward its near part and spreads 1/d^2-weighted noise over the rest; a
// direction drawn by solid angle has the same density everywhere the triangle is seen. Computed
// in double: the angles of a small spherical triangle are differences of nearly equal numbers.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "math/vec.hpp"

namespace tracer {

// The solid angle the triangle (v0, v1, v2) subtends at `p` (Van Oosterom and Strackee 1983).
inline double triangle_solid_angle(Vec3 p, Vec3 v0, Vec3 v1, Vec3 v2) {
  const auto unit = [&](Vec3 v) {
    const double x = double(v.x) - double(p.x), y = double(v.y) - double(p.y), z = double(v.z) - double(p.z);
    const double l = std::sqrt(x * x + y * y + z * z);
    return std::array<double, 3>{x / l, y / l, z / l};
  };
  const auto a = unit(v0), b = unit(v1), c = unit(v2);
  const auto dot3 = [](const std::array<double, 3>& u, const std::array<double, 3>& v) {
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
  };
  const double triple =
      a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  const double omega = 2.0 * std::atan2(std::fabs(triple), 1.0 + dot3(a, b) + dot3(b, c) + dot3(c, a));
  return std::isfinite(omega) ? omega : 0.0;
}

// A unit direction from `p` toward the triangle, uniform in its solid angle, by two uniform
// numbers: u1 picks the sub-triangle of area u1 * A (sliding its third vertex along the edge
// opposite the first), u2 the point along the arc from the second vertex to that third one.
// False when the triangle is degenerate as seen from p.
inline bool sample_spherical_triangle(Vec3 p, Vec3 v0, Vec3 v1, Vec3 v2, float u1, float u2, Vec3& w) {
  struct D3 {
    double x, y, z;
    D3 operator+(D3 o) const { return {x + o.x, y + o.y, z + o.z}; }
    D3 operator-(D3 o) const { return {x - o.x, y - o.y, z - o.z}; }
    D3 operator*(double s) const { return {x * s, y * s, z * s}; }
  };
  const auto dot3 = [](D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; };
  const auto cross3 = [](D3 a, D3 b) {
    return D3{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  };
  const auto unit = [&](D3 v) { return v * (1.0 / std::sqrt(dot3(v, v))); };
  const auto from = [&](Vec3 v) { return unit(D3{double(v.x) - p.x, double(v.y) - p.y, double(v.z) - p.z}); };
  // The part of v orthogonal to the unit vector n, made unit.
  const auto orthogonal = [&](D3 v, D3 n) { return unit(v - n * dot3(v, n)); };
  const D3 a = from(v0), b = from(v1), c = from(v2);
  // The angle at each vertex: between the great circles through its two edges.
  const auto angle = [&](D3 at, D3 x, D3 y) {
    return std::acos(std::clamp(dot3(unit(cross3(at, x)), unit(cross3(at, y))), -1.0, 1.0));
  };
  const double alpha = angle(a, b, c), beta = angle(b, c, a), gamma = angle(c, a, b);
  const double area = alpha + beta + gamma - std::numbers::pi;
  if (!(area > 0.0) || !std::isfinite(area)) return false;
  // Arvo's steps 2-5: the sub-triangle's third vertex c_hat on the arc from a to c.
  const double area_hat = double(u1) * area;
  const double s = std::sin(area_hat - alpha), t = std::cos(area_hat - alpha);
  const double cos_alpha = std::cos(alpha), sin_alpha = std::sin(alpha);
  const double u = t - cos_alpha, v = s + sin_alpha * dot3(a, b);
  const double q = std::clamp(((v * t - u * s) * cos_alpha - v) / ((v * s + u * t) * sin_alpha), -1.0, 1.0);
  const D3 c_hat = a * q + orthogonal(c, a) * std::sqrt(std::max(0.0, 1.0 - q * q));
  // Steps 6-7: a point on the arc from b to c_hat, uniform in the sub-triangle's area.
  const double z = 1.0 - double(u2) * (1.0 - dot3(c_hat, b));
  const D3 d = b * z + orthogonal(c_hat, b) * std::sqrt(std::max(0.0, 1.0 - z * z));
  if (!std::isfinite(d.x) || !std::isfinite(d.y) || !std::isfinite(d.z)) return false;
  w = normalize(Vec3{float(d.x), float(d.y), float(d.z)});
  return true;
}

}  // namespace tracer
