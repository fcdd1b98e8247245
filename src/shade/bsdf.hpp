// The scattering of one surface point, built from its material: a diffuse (Lambert) lobe plus a
// glossy GGX lobe (MTL), glTF's metallic-roughness BRDF, a perfect mirror, or a smooth dielectric. Directions are
// world-space unit vectors pointing away from the surface; the shading frame's +z is the shading normal on the side
// `wo` arrives from. eval() returns f * cos(theta_i), sample() the weight f * cos / pdf.
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
  enum class Kind { Smooth, MetallicRoughness, Mirror, Dielectric };

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
  // The glTF 2.0 BRDF (the specification's appendix B): a metal of reflectance base_color and a
  // dielectric (Lambert of base_color under a specular layer) mixed by `metallic`; both specular
  // lobes GGX of width `ggx` with height-correlated Smith masking, their Fresnel Schlick's: the
  // metal's from base_color to 1, the dielectric's from f0 to f90 (0.04 and 1 for ior 1.5;
  // KHR_materials_ior and _specular move them), the diffuse weighted by 1 - max(F).
  static Bsdf metallic_roughness(const Frame& frame, Vec3 base_color, float metallic, Ggx ggx, Vec3 f0 = Vec3{0.04f},
                                 float f90 = 1.0f) {
    Bsdf b(Kind::MetallicRoughness, frame);
    b.kd_ = min(max(base_color, Vec3{0.0f}), Vec3{1.0f});
    b.metallic_ = std::clamp(metallic, 0.0f, 1.0f);
    b.ggx_ = Ggx{std::max(ggx.alpha, kMinAlpha)};
    b.ks_ = min(max(f0, Vec3{0.0f}), Vec3{1.0f});
    b.f90_ = std::clamp(f90, 0.0f, 1.0f);
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
  bool delta() const { return kind_ == Kind::Mirror || kind_ == Kind::Dielectric; }
  // A BSDF with both a diffuse and a glossy lobe: sample() then reads u_lobe.
  bool two_lobes() const {
    if (kind_ == Kind::MetallicRoughness) {  // a diffuse lobe, and a specular one (metal or layer)
      return metallic_ < 1.0f && luminance(kd_) > 0.0f &&
             (metallic_ > 0.0f || f90_ > 0.0f || max_component(ks_) > 0.0f);
    }
    return kind_ == Kind::Smooth && p_glossy_ > 0.0f && p_glossy_ < 1.0f;
  }

  Vec3 eval(Vec3 wo_world, Vec3 wi_world) const {
    if (delta()) return Vec3{0.0f};
    const Vec3 wo = frame_.to_local(wo_world), wi = frame_.to_local(wi_world);
    if (wo.z <= 0.0f || wi.z <= 0.0f) return Vec3{0.0f};
    if (kind_ == Kind::MetallicRoughness) {
      const Vec3 h = normalize(wo + wi);
      const float s5 = schlick_weight(dot(wo, h));
      const Vec3 f_dielectric = ks_ + (Vec3{f90_} - ks_) * s5;
      const Vec3 f_metal = kd_ + (Vec3{1.0f} - kd_) * s5;
      const float specular = ggx_.d(h) * ggx_.g2(wo, wi) / (4.0f * wo.z * wi.z);
      const Vec3 fresnel = f_metal * metallic_ + f_dielectric * (1.0f - metallic_);
      const float diffuse = (1.0f - metallic_) * (1.0f - max_component(f_dielectric)) * std::numbers::inv_pi_v<float>;
      return (fresnel * specular + kd_ * diffuse) * wi.z;
    }
    Vec3 f = kd_ * std::numbers::inv_pi_v<float>;
    if (p_glossy_ > 0.0f) {
      const Vec3 h = normalize(wo + wi);
      f += ks_ * (ggx_.d(h) * ggx_.g1(wo) * ggx_.g1(wi) / (4.0f * wo.z * wi.z));
    }
    return f * wi.z;
  }

  float pdf(Vec3 wo_world, Vec3 wi_world) const {
    if (delta()) return 0.0f;
    const Vec3 wo = frame_.to_local(wo_world), wi = frame_.to_local(wi_world);
    if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
    const float p_glossy = glossy_probability(wo.z);
    float p = (1.0f - p_glossy) * wi.z * std::numbers::inv_pi_v<float>;
    if (p_glossy > 0.0f) {
      const Vec3 h = normalize(wo + wi);
      p += p_glossy * ggx_.d(h) * h.z / (4.0f * dot(wo, h));
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
      case Kind::MetallicRoughness:
        break;
    }
    Vec3 wi;
    if (u_lobe < glossy_probability(wo.z)) {
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
  // Below this width GGX's density overflows single precision near its peak: roughness 0 is
  // drawn as roughness 0.03, narrower than a texel shows.
  static constexpr float kMinAlpha = 1e-3f;
  static float schlick_weight(float cos_theta) {
    const float m = std::clamp(1.0f - cos_theta, 0.0f, 1.0f), m2 = m * m;
    return m2 * m2 * m;
  }
  // The chance that sample() takes the glossy lobe for wo at cosine cos_o. Metallic-roughness:
  // in proportion to the two lobes' reflectance estimated at wo (Fresnel at cos_o), so grazing
  // views, whose light the specular layer carries, sample it more; never below 1 in 10 while there is a specular lobe.
  float glossy_probability(float cos_o) const {
    if (kind_ != Kind::MetallicRoughness) return p_glossy_;
    if (metallic_ >= 1.0f) return 1.0f;
    const float s5 = schlick_weight(cos_o);
    const Vec3 f_dielectric = ks_ + (Vec3{f90_} - ks_) * s5;
    const float specular =
        luminance(kd_ + (Vec3{1.0f} - kd_) * s5) * metallic_ + luminance(f_dielectric) * (1.0f - metallic_);
    const float diffuse = (1.0f - metallic_) * (1.0f - max_component(f_dielectric)) * luminance(kd_);
    if (!(specular > 0.0f)) return 0.0f;
    if (!(diffuse > 0.0f)) return 1.0f;
    return std::clamp(specular / (specular + diffuse), 0.1f, 1.0f);
  }
  Bsdf(Kind kind, const Frame& frame) : kind_(kind), frame_(frame) {}
  Kind kind_;
  Frame frame_;
  Vec3 kd_{0.0f}, ks_{0.0f};  // kd_ is Tf for a dielectric, the base colour for metallic-roughness; ks_ its f0
  Ggx ggx_{1.0f};
  float p_glossy_ = 0.0f;
  float eta_ = 1.0f;
  float metallic_ = 0.0f, f90_ = 1.0f;
};

}  // namespace tracer
