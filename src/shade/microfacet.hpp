// The GGX (Trowbridge-Reitz) microfacet distribution with Smith's masking, separable (g1 * g1,
// MTL's glossy lobe) or height-correlated (g2, glTF's BRDF), in the local frame where the
// macro-surface normal is +z (Walter et al. 2007, "Microfacet Models for Refraction through Rough
// Surfaces"; Heitz 2014, "Understanding the Masking-Shadowing Function").
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include "math/vec.hpp"

namespace tracer {

struct Ggx {
  float alpha;

  // The MTL specular exponent Ns as a GGX roughness: Walter et al.'s Phong-to-Beckmann mapping
  // alpha = sqrt(2 / (Ns + 2)), which GGX shares closely for the lobe's width; kept within
  // [0.01, 1] so Ns 0 is a rough lobe and a huge Ns stays finite.
  static Ggx from_phong_exponent(float ns) {
    return Ggx{std::clamp(std::sqrt(2.0f / (std::max(ns, 0.0f) + 2.0f)), 0.01f, 1.0f)};
  }

  // Density of microfacet normals h (projected area per solid angle).
  float d(Vec3 h) const {
    if (h.z <= 0.0f) return 0.0f;
    const float a2 = alpha * alpha, c2 = h.z * h.z;
    const float k = c2 * (a2 - 1.0f) + 1.0f;
    return a2 / (std::numbers::pi_v<float> * k * k);
  }
  // Smith masking of direction v.
  float g1(Vec3 v) const {
    if (v.z <= 0.0f) return 0.0f;
    const float c2 = v.z * v.z;
    const float tan2 = std::max(0.0f, 1.0f - c2) / c2;
    return 2.0f / (1.0f + std::sqrt(1.0f + alpha * alpha * tan2));
  }
  // Smith's Lambda of direction v (g1 = 1 / (1 + lambda)).
  float lambda(Vec3 v) const {
    const float c2 = v.z * v.z;
    const float tan2 = std::max(0.0f, 1.0f - c2) / c2;
    return 0.5f * (std::sqrt(1.0f + alpha * alpha * tan2) - 1.0f);
  }
  // Height-correlated masking-shadowing of the pair (wo, wi), both above the surface: what the
  // glTF specification's appendix B prescribes.
  float g2(Vec3 wo, Vec3 wi) const {
    if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
    return 1.0f / (1.0f + lambda(wo) + lambda(wi));
  }
  // A normal drawn with density d(h) * h.z.
  Vec3 sample_normal(float u1, float u2) const {
    const float a2 = alpha * alpha;
    const float c2 = (1.0f - u1) / (1.0f + (a2 - 1.0f) * u1);
    const float c = std::sqrt(std::max(0.0f, c2)), s = std::sqrt(std::max(0.0f, 1.0f - c2));
    const float phi = 2.0f * std::numbers::pi_v<float> * u2;
    return {s * std::cos(phi), s * std::sin(phi), c};
  }
};

}  // namespace tracer
