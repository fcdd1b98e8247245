// The scattering of one surface point, built from its material: a diffuse (Lambert) lobe plus a
// glossy GGX lobe, a perfect mirror, or a smooth dielectric. Directions are world-space unit
// vectors pointing away from the surface; the shading frame's +z is the shading normal on the
// side `wo` arrives from. eval() returns f * cos(theta_i), sample() the weight f * cos / pdf.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include "math/sampling.hpp"
#include "shade/microfacet.hpp"
#include "shade/optics.hpp"

namespace tracer {

struct BsdfSample {
  Vec3 wi;
  Vec3 weight;       // f * |cos theta_i| / pdf
  float pdf = 0.0f;  // solid-angle density; for a delta lobe, the probability of having chosen it
  bool delta = false;
  bool transmitted = false;  // wi leaves through the surface, to the far side
};

class Bsdf {
 public:
  enum class Kind { Smooth, Mirror, Dielectric };

  // Lambert of albedo kd plus a GGX lobe of reflectance ks: scaled down together if kd + ks
  // exceeds 1 in some channel, so no material reflects more than it receives.
  static Bsdf smooth(const Frame& frame, Vec3 kd, Vec3 ks, Ggx ggx) {
    Bsdf b(Kind::Smooth, frame);
    kd = max(kd, Vec3{0.0f});
    ks = max(ks, Vec3{0.0f});
    const float sum = max_component(kd + ks);
    const float scale = sum > 1.0f ? 1.0f / sum : 1.0f;
    b.kd_ = kd * scale;
    b.ks_ = ks * scale;
    b.ggx_ = ggx;
    const float d = luminance(b.kd_), s = luminance(b.ks_);
    b.p_glossy_ = s > 0.0f ? s / (d + s) : 0.0f;
    return b;
  }
  static Bsdf mirror(const Frame& frame, Vec3 ks) {
    Bsdf b(Kind::Mirror, frame);
    b.ks_ = ks;
    return b;
  }
  // eta: the index ratio across the surface, far side over wo's side; tf filters what passes.
  static Bsdf dielectric(const Frame& frame, float eta, Vec3 tf) {
    Bsdf b(Kind::Dielectric, frame);
    b.eta_ = eta;
    b.kd_ = tf;
    return b;
  }

  Kind kind() const { return kind_; }
  bool delta() const { return kind_ != Kind::Smooth; }
  // A smooth BSDF with both a diffuse and a glossy lobe: sample() then reads u_lobe.
  bool two_lobes() const { return kind_ == Kind::Smooth && p_glossy_ > 0.0f && p_glossy_ < 1.0f; }

  Vec3 eval(Vec3 wo_world, Vec3 wi_world) const {
    if (kind_ != Kind::Smooth) return Vec3{0.0f};
    const Vec3 wo = frame_.to_local(wo_world), wi = frame_.to_local(wi_world);
    if (wo.z <= 0.0f || wi.z <= 0.0f) return Vec3{0.0f};
    Vec3 f = kd_ * std::numbers::inv_pi_v<float>;
    if (p_glossy_ > 0.0f) {
      const Vec3 h = normalize(wo + wi);
      f += ks_ * (ggx_.d(h) * ggx_.g1(wo) * ggx_.g1(wi) / (4.0f * wo.z * wi.z));
    }
    return f * wi.z;
  }

  float pdf(Vec3 wo_world, Vec3 wi_world) const {
    if (kind_ != Kind::Smooth) return 0.0f;
    const Vec3 wo = frame_.to_local(wo_world), wi = frame_.to_local(wi_world);
    if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
    float p = (1.0f - p_glossy_) * wi.z * std::numbers::inv_pi_v<float>;
    if (p_glossy_ > 0.0f) {
      const Vec3 h = normalize(wo + wi);
      p += p_glossy_ * ggx_.d(h) * h.z / (4.0f * dot(wo, h));
    }
    return p;
  }

  // Draws wi from three uniform numbers (u_lobe picks the lobe); false when no direction results
  // (a glossy reflection below the horizon).
  bool sample(Vec3 wo_world, float u_lobe, float u1, float u2, BsdfSample& out) const {
    const Vec3 wo = frame_.to_local(wo_world);
    if (wo.z <= 0.0f) return false;
    switch (kind_) {
      case Kind::Mirror:
        out = {.wi = frame_.to_world({-wo.x, -wo.y, wo.z}), .weight = ks_, .pdf = 1.0f, .delta = true};
        return true;
      case Kind::Dielectric: {
        // Reflection or refraction, chosen in proportion to what each carries: the Fresnel
        // reflectance f, and 1 - f through the filter Tf. A dim filter (water's Tf 0.1) makes
        // the reflections, a lamp's highlight among them, the larger part of what is seen.
        const float f = fresnel_dielectric(wo.z, 1.0f, eta_);
        const float t = (1.0f - f) * luminance(kd_);
        const float p_reflect = f + t > 0.0f ? f / (f + t) : 1.0f;
        if (u_lobe < p_reflect) {
          out = {.wi = frame_.to_world({-wo.x, -wo.y, wo.z}),
                 .weight = Vec3{f / p_reflect},
                 .pdf = p_reflect,
                 .delta = true};
          return true;
        }
        Vec3 wt;
        if (!refract(-wo, Vec3{0.0f, 0.0f, 1.0f}, 1.0f / eta_, wt)) return false;  // f was 1: not reached
        // Radiance scales by 1/eta^2 crossing into the denser side (it is L/n^2 that is conserved).
        out = {.wi = frame_.to_world(wt),
               .weight = kd_ * ((1.0f - f) / ((1.0f - p_reflect) * eta_ * eta_)),
               .pdf = 1.0f - p_reflect,
               .delta = true,
               .transmitted = true};
        return true;
      }
      case Kind::Smooth:
        break;
    }
    Vec3 wi;
    if (u_lobe < p_glossy_) {
      const Vec3 h = ggx_.sample_normal(u1, u2);
      wi = h * (2.0f * dot(wo, h)) - wo;
      if (wi.z <= 0.0f) return false;
    } else {
      wi = cosine_hemisphere(u1, u2);
      if (wi.z <= 0.0f) return false;
    }
    const Vec3 wi_world = frame_.to_world(wi);
    const float p = pdf(wo_world, wi_world);
    if (!(p > 0.0f)) return false;
    out = {.wi = wi_world, .weight = eval(wo_world, wi_world) / p, .pdf = p};
    return true;
  }

 private:
  Bsdf(Kind kind, const Frame& frame) : kind_(kind), frame_(frame) {}
  Kind kind_;
  Frame frame_;
  Vec3 kd_{0.0f}, ks_{0.0f};  // kd_ is Tf for a dielectric
  Ggx ggx_{1.0f};
  float p_glossy_ = 0.0f;
  float eta_ = 1.0f;
};

}  // namespace tracer
