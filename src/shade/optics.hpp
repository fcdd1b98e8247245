// Perfect specular optics: mirror reflection, Snell refraction and the exact Fresnel reflectance
// of a dielectric interface (unpolarised light). Directions point away from the surface for the
// outgoing ray and along travel for the incoming one; normals are unit length.
#pragma once

#include <algorithm>
#include <cmath>

#include "math/vec.hpp"

namespace tracer {

// The mirror direction of `d` (travelling toward the surface) about `n`.
inline Vec3 reflect(Vec3 d, Vec3 n) { return d - n * (2.0f * dot(d, n)); }

// Refracts `d` (unit, travelling toward the surface) through a surface whose normal `n` faces the
// side `d` comes from, with eta = n_incident / n_transmitted. False on total internal reflection.
inline bool refract(Vec3 d, Vec3 n, float eta, Vec3& out) {
  const float cos_i = -dot(d, n);
  const float sin2_t = eta * eta * std::max(0.0f, 1.0f - cos_i * cos_i);
  if (sin2_t >= 1.0f) return false;
  const float cos_t = std::sqrt(1.0f - sin2_t);
  out = normalize(d * eta + n * (eta * cos_i - cos_t));
  return true;
}

// Fresnel reflectance of unpolarised light arriving at cos_i (>= 0) from a medium of index eta_i
// onto one of index eta_t: the mean of the s and p reflectances; 1 beyond the critical angle.
inline float fresnel_dielectric(float cos_i, float eta_i, float eta_t) {
  cos_i = std::clamp(cos_i, 0.0f, 1.0f);
  const float sin_t = eta_i / eta_t * std::sqrt(std::max(0.0f, 1.0f - cos_i * cos_i));
  if (sin_t >= 1.0f) return 1.0f;
  const float cos_t = std::sqrt(std::max(0.0f, 1.0f - sin_t * sin_t));
  const float rs = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
  const float rp = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
  return 0.5f * (rs * rs + rp * rp);
}

}  // namespace tracer
