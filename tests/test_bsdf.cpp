// Each BSDF lobe on its own: energy (white furnace), sampling against evaluation (the pdf of the
// sampled directions, a chi-square test in the style of pbrt-v4's), and the delta lobes against
// Fresnel and Snell.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "shade/bsdf.hpp"
#include "shade/material_bsdf.hpp"
#include "test_util.hpp"

namespace tracer {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

Vec3 direction(float theta_deg, float phi_deg = 0.0f) {
  const float t = theta_deg * kPi / 180.0f, p = phi_deg * kPi / 180.0f;
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

struct Lobe {
  std::string name;
  Bsdf bsdf;
};

// Non-delta BSDFs under a tilted shading frame, so the frame code is part of what is tested.
std::vector<Lobe> smooth_lobes() {
  const Frame frame(normalize(Vec3{0.2f, 0.3f, 1.0f}));
  std::vector<Lobe> v;
  v.push_back({"lambert", Bsdf::smooth(frame, Vec3{1.0f}, Vec3{0.0f}, Ggx{1.0f})});
  for (const float ns : {1.0f, 10.0f, 50.0f, 256.0f}) {
    v.push_back({"ggx Ns " + std::to_string(int(ns)),
                 Bsdf::smooth(frame, Vec3{0.0f}, Vec3{1.0f}, Ggx::from_phong_exponent(ns))});
  }
  v.push_back({"lambert + ggx", Bsdf::smooth(frame, Vec3{0.5f}, Vec3{0.5f}, Ggx::from_phong_exponent(20.0f))});
  // glTF's metallic-roughness BRDF: a metal, a dielectric (Lambert under a specular layer) and a
  // half-metal mix; alpha is roughness squared.
  for (const float rough : {0.3f, 0.7f}) {
    v.push_back({"metal rough " + std::to_string(rough),
                 Bsdf::metallic_roughness(frame, Vec3{1.0f}, 1.0f, Ggx{rough * rough})});
  }
  v.push_back({"dielectric rough 0.5", Bsdf::metallic_roughness(frame, Vec3{0.8f}, 0.0f, Ggx{0.25f})});
  v.push_back({"half metal rough 0.4", Bsdf::metallic_roughness(frame, Vec3{0.9f}, 0.5f, Ggx{0.16f})});
  return v;
}

Vec3 world_wo(float theta_deg) {
  const Frame frame(normalize(Vec3{0.2f, 0.3f, 1.0f}));
  return frame.to_world(direction(theta_deg, 30.0f));
}

TEST(Bsdf, WhiteFurnaceNoLobeReturnsMoreThanItReceives) {
  // The mean sample weight is the lobe's albedo for light arriving along wo; it must not exceed 1
  // (within 1 %), and a white Lambert lobe reflects exactly 1.
  std::mt19937 gen(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (const Lobe& lobe : smooth_lobes()) {
    for (const float theta : {0.0f, 30.0f, 60.0f, 85.0f}) {
      const Vec3 wo = world_wo(theta);
      const int n = 200000;
      double sum = 0.0;
      for (int i = 0; i < n; ++i) {
        BsdfSample s;
        if (lobe.bsdf.sample(wo, u(gen), u(gen), u(gen), s)) sum += s.weight.x;
      }
      const double albedo = sum / n;
      EXPECT_LE(albedo, 1.01) << lobe.name << " at " << theta;
      if (lobe.name == "lambert") {
        EXPECT_NEAR(albedo, 1.0, 1e-3) << theta;
      }
      // A narrow GGX lobe loses little to masking away from grazing angles (a rough one more:
      // single scattering has no multiple-bounce term).
      if (lobe.name == "ggx Ns 256" && theta <= 60.0f) {
        EXPECT_GT(albedo, 0.93) << theta;
      }
    }
  }
}

TEST(Bsdf, SamplingAgreesWithEvaluation) {
  // Two estimates of the albedo: the mean weight of sampled directions, and eval() integrated
  // by uniform hemisphere sampling; and the pdf integrates to the fraction of draws that give a
  // direction (1 for Lambert; GGX loses the reflections that fall below the horizon).
  std::mt19937 gen(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const Frame frame(normalize(Vec3{0.2f, 0.3f, 1.0f}));
  for (const Lobe& lobe : smooth_lobes()) {
    for (const float theta : {10.0f, 45.0f, 75.0f}) {
      const Vec3 wo = world_wo(theta);
      const int n = 400000;
      double sampled = 0.0, taken = 0.0, f_sum = 0.0, f_sq = 0.0, pdf_sum = 0.0, pdf_sq = 0.0;
      for (int i = 0; i < n; ++i) {
        BsdfSample s;
        if (lobe.bsdf.sample(wo, u(gen), u(gen), u(gen), s)) {
          sampled += s.weight.x;
          taken += 1.0;
          EXPECT_NEAR(s.pdf, lobe.bsdf.pdf(wo, s.wi), 1e-3f * s.pdf);
        }
        // Uniform on the hemisphere: pdf 1 / (2 pi).
        const float z = u(gen), phi = 2.0f * kPi * u(gen), r = std::sqrt(std::max(0.0f, 1.0f - z * z));
        const Vec3 wi = frame.to_world({r * std::cos(phi), r * std::sin(phi), z});
        const double f = double(lobe.bsdf.eval(wo, wi).x) * 2.0 * std::numbers::pi;
        const double p = double(lobe.bsdf.pdf(wo, wi)) * 2.0 * std::numbers::pi;
        f_sum += f;
        f_sq += f * f;
        pdf_sum += p;
        pdf_sq += p * p;
      }
      // Uniform sampling of a narrow lobe is noisy: allow four standard errors of that estimate
      // plus 0.5 %, which is far below what a wrong factor in eval, pdf or sample would give.
      const auto bound = [n](double sum, double sq) {
        const double mean = sum / n, var = std::max(0.0, sq / n - mean * mean);
        return 4.0 * std::sqrt(var / n) + 0.005 * mean;
      };
      EXPECT_NEAR(sampled / n, f_sum / n, bound(f_sum, f_sq)) << lobe.name << " at " << theta;
      EXPECT_NEAR(pdf_sum / n, taken / n, bound(pdf_sum, pdf_sq)) << lobe.name << " at " << theta;
    }
  }
}

// Chi-square test of `sampled`'s sample() against `judged`'s pdf() (the same BSDF, except when a
// test checks that the test can fail) over a (theta, phi) grid of the shading hemisphere:
// expected counts from the pdf integrated per cell, cells below 5 expected pooled; returns the
// statistic's upper tail probability (Wilson-Hilferty), small when the samples do not follow.
double chi_square_upper_tail(const Bsdf& sampled, const Bsdf& judged, Vec3 wo, const Frame& frame, uint32_t seed) {
  constexpr int kTheta = 16, kPhi = 32, kSamples = 400000, kSub = 6;
  std::vector<double> observed(kTheta * kPhi, 0.0), expected(kTheta * kPhi, 0.0);
  std::mt19937 gen(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < kSamples; ++i) {
    BsdfSample s;
    if (!sampled.sample(wo, u(gen), u(gen), u(gen), s)) continue;
    const Vec3 l = frame.to_local(s.wi);
    const double theta = std::acos(std::clamp(double(l.z), -1.0, 1.0));
    double phi = std::atan2(double(l.y), double(l.x));
    if (phi < 0) phi += 2.0 * std::numbers::pi;
    const int ti = std::min(kTheta - 1, int(theta / (std::numbers::pi / 2) * kTheta));
    const int pi = std::min(kPhi - 1, int(phi / (2.0 * std::numbers::pi) * kPhi));
    observed[size_t(ti * kPhi + pi)] += 1.0;
  }
  const double dt = std::numbers::pi / 2 / kTheta, dp = 2.0 * std::numbers::pi / kPhi;
  for (int ti = 0; ti < kTheta; ++ti) {
    for (int pi = 0; pi < kPhi; ++pi) {
      double sum = 0.0;
      for (int a = 0; a < kSub; ++a) {
        for (int b = 0; b < kSub; ++b) {
          const double theta = (ti + (a + 0.5) / kSub) * dt, phi = (pi + (b + 0.5) / kSub) * dp;
          const Vec3 l{float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)),
                       float(std::cos(theta))};
          sum += double(judged.pdf(wo, frame.to_world(l))) * std::sin(theta);
        }
      }
      expected[size_t(ti * kPhi + pi)] = sum * dt * dp / (kSub * kSub) * kSamples;
    }
  }
  return test::chi_square_tail(observed, expected);
}

TEST(Bsdf, ChiSquareSamplesFollowThePdf) {
  const Frame frame(normalize(Vec3{0.2f, 0.3f, 1.0f}));
  uint32_t seed = 1;
  for (const Lobe& lobe : smooth_lobes()) {
    for (const float theta : {15.0f, 60.0f}) {
      EXPECT_GT(chi_square_upper_tail(lobe.bsdf, lobe.bsdf, world_wo(theta), frame, seed++), 1e-5)
          << lobe.name << " at " << theta;
    }
  }
}

TEST(Bsdf, ChiSquareCatchesAWrongPdf) {
  // The test must be able to fail: samples of a GGX lobe judged by the pdf of a slightly wider
  // one (Ns 40 against 30), and cosine samples judged by a GGX pdf, are rejected.
  const Frame frame(normalize(Vec3{0.2f, 0.3f, 1.0f}));
  const Bsdf narrow = Bsdf::smooth(frame, Vec3{0.0f}, Vec3{1.0f}, Ggx::from_phong_exponent(40.0f));
  const Bsdf wider = Bsdf::smooth(frame, Vec3{0.0f}, Vec3{1.0f}, Ggx::from_phong_exponent(30.0f));
  const Bsdf lambert = Bsdf::smooth(frame, Vec3{1.0f}, Vec3{0.0f}, Ggx{1.0f});
  const Bsdf rough = Bsdf::smooth(frame, Vec3{0.0f}, Vec3{1.0f}, Ggx::from_phong_exponent(0.0f));
  EXPECT_LT(chi_square_upper_tail(narrow, wider, world_wo(30.0f), frame, 3), 1e-5);
  EXPECT_LT(chi_square_upper_tail(lambert, rough, world_wo(30.0f), frame, 4), 1e-5);
}

TEST(Bsdf, DielectricReflectsTheFresnelFractionAndRefractsBySnell) {
  std::mt19937 gen(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const Frame frame(Vec3{0.0f, 0.0f, 1.0f});
  // Clear glass, and a dim coloured filter (as water's Tf 0.1), which makes reflection the likelier
  // choice: it is chosen in proportion to f against (1 - f) * luminance(Tf), each weighted so that
  // the estimate is f for the reflection and Tf (1 - f) / eta^2 for the refraction.
  for (const Vec3 tf : {Vec3{1.0f}, Vec3{0.1f, 0.2f, 0.05f}}) {
    for (const float eta : {1.5f, 1.0f / 1.5f}) {
      const Bsdf glass = Bsdf::dielectric(frame, eta, tf);
      for (const float theta : {0.0f, 30.0f, 40.0f, 60.0f}) {
        const Vec3 wo = direction(theta);
        const float f = fresnel_dielectric(wo.z, 1.0f, eta);
        const double p_reflect = f / (f + (1.0 - f) * luminance(tf));
        const int n = 100000;
        int reflected = 0;
        Vec3 reflected_sum{0.0f}, transmitted_sum{0.0f};
        for (int i = 0; i < n; ++i) {
          BsdfSample s;
          ASSERT_TRUE(glass.sample(wo, u(gen), u(gen), u(gen), s));
          ASSERT_TRUE(s.delta);
          if (!s.transmitted) {
            ++reflected;
            EXPECT_NEAR(s.wi.z, wo.z, 1e-6f);
            EXPECT_NEAR(s.wi.x, -wo.x, 1e-6f);
            EXPECT_NEAR(s.weight.x, f / p_reflect, 1e-5f);
            reflected_sum += s.weight;
          } else {
            // Snell: sin_t = sin_i / eta; the radiance scales by 1 / eta^2.
            EXPECT_NEAR(std::sqrt(s.wi.x * s.wi.x + s.wi.y * s.wi.y), std::sin(theta * kPi / 180.0f) / eta, 1e-5f);
            EXPECT_LT(s.wi.z, 0.0f);
            EXPECT_NEAR(s.weight.y, tf.y * (1.0f - f) / ((1.0f - p_reflect) * eta * eta), 1e-5f);
            transmitted_sum += s.weight;
          }
        }
        const double frac = double(reflected) / n;
        EXPECT_NEAR(frac, p_reflect, 4.0 * std::sqrt(p_reflect * (1.0 - p_reflect) / n) + 1e-6) << eta << " " << theta;
        // The estimates' means are f and Tf (1 - f) / eta^2, within 4 sigma of the binomial count.
        const double sigma = std::sqrt(p_reflect * (1.0 - p_reflect) / n);
        EXPECT_NEAR(reflected_sum.x / n, f, 4.0 * sigma * f / p_reflect + 1e-6) << eta << " " << theta;
        for (int c = 0; c < 3 && p_reflect < 1.0; ++c) {  // beyond the critical angle nothing passes
          const double expect = tf[c] * (1.0 - f) / (eta * eta);
          EXPECT_NEAR(transmitted_sum[c] / n, expect, 4.0 * sigma * expect / (1.0 - p_reflect) + 1e-6)
              << eta << " " << theta << " " << c;
        }
      }
    }
  }
  // Normal incidence from air onto n = 1.5: ((n - 1) / (n + 1))^2 = 0.04.
  EXPECT_NEAR(fresnel_dielectric(1.0f, 1.0f, 1.5f), 0.04f, 1e-6f);
  // Beyond the critical angle from inside glass, everything reflects.
  const Bsdf inside = Bsdf::dielectric(frame, 1.0f / 1.5f, Vec3{1.0f});
  BsdfSample s;
  ASSERT_TRUE(inside.sample(direction(45.0f), 0.999f, 0.5f, 0.5f, s));
  EXPECT_FALSE(s.transmitted);
}

TEST(Bsdf, MaterialsMapToTheirLobes) {
  Material m;
  m.illum = 5;
  m.ks = Vec3{0.9f};
  EXPECT_EQ(material_bsdf(m, MaterialPoint{.color = m.kd, .specular = m.ks}, Vec3{0, 0, 1}, true).kind(),
            Bsdf::Kind::Mirror);
  m.illum = 7;
  m.ni = 1.33f;
  EXPECT_EQ(material_bsdf(m, MaterialPoint{.color = m.kd}, Vec3{0, 0, 1}, true).kind(), Bsdf::Kind::Dielectric);
  m.illum = 2;
  m.ns = 100.0f;
  const Bsdf b =
      material_bsdf(m, MaterialPoint{.color = Vec3{0.5f}, .specular = m.ks, .shininess = m.ns}, Vec3{0, 0, 1}, true);
  EXPECT_EQ(b.kind(), Bsdf::Kind::Smooth);
  // Kd + Ks = 1.4 is scaled to 1: the white furnace holds for any MTL values.
  std::mt19937 gen(9);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  double sum = 0.0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    BsdfSample s;
    if (b.sample(direction(20.0f), u(gen), u(gen), u(gen), s)) sum += s.weight.x;
  }
  EXPECT_LE(sum / n, 1.01);
  EXPECT_GT(sum / n, 0.9);
  m.metallic_roughness = true;
  EXPECT_EQ(material_bsdf(m, MaterialPoint{.color = Vec3{0.5f}}, Vec3{0, 0, 1}, true).kind(),
            Bsdf::Kind::MetallicRoughness);
}

TEST(Ggx, WeakWhiteFurnaceIntegratesToOne) {
  // Heitz 2014, eq. 18: the visible normals' projected area integrates to the view's, i.e.
  // int G1(wo) max(0, wo.h) D(h) dh = cos(theta_o) for every wo and width. Estimated with normals
  // drawn from D(h) h.z, the integrand over that density is G1(wo) max(0, wo.h) / h.z.
  std::mt19937 gen(21);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (const float alpha : {0.05f, 0.3f, 0.7f, 1.0f}) {
    const Ggx ggx{alpha};
    for (const float theta : {0.0f, 40.0f, 70.0f, 85.0f}) {
      const Vec3 wo = direction(theta, 10.0f);
      const int n = 200000;
      double sum = 0.0, sq = 0.0;
      for (int i = 0; i < n; ++i) {
        const Vec3 h = ggx.sample_normal(u(gen), u(gen));
        const double x = double(ggx.g1(wo)) * std::max(0.0f, dot(wo, h)) / h.z / wo.z;
        sum += x;
        sq += x * x;
      }
      // Within four standard errors (normals near the horizon make the estimate's tail heavy at
      // grazing views) plus 0.2 %.
      const double mean = sum / n, sigma = std::sqrt(std::max(0.0, sq / n - mean * mean) / n);
      EXPECT_NEAR(mean, 1.0, 4.0 * sigma + 2e-3) << alpha << " " << theta;
    }
    // g2 is height-correlated: 1 / (1 + lambda_o + lambda_i), between the separable product
    // (which counts the shared heights twice) and either mask alone.
    const Vec3 a = direction(60.0f), b = direction(70.0f, 120.0f), n = direction(0.0f);
    EXPECT_GE(ggx.g2(a, b), ggx.g1(a) * ggx.g1(b) - 1e-6f);
    EXPECT_LE(ggx.g2(a, b), std::min(ggx.g1(a), ggx.g1(b)) + 1e-6f);
    EXPECT_NEAR(ggx.g2(n, n), 1.0f, 1e-6f);
    EXPECT_NEAR(ggx.g2(a, n), ggx.g1(a), 1e-6f);  // lambda(n) = 0: the pair reduces to one mask
  }
}

TEST(Bsdf, MetallicRoughnessMatchesTheSpecificationAtNormalIncidence) {
  // wo = wi = n: h = n, Schlick's weight is 0, D(n) = 1 / (pi alpha^2), G2 = 1. A metal reflects
  // base * D / 4; a dielectric f0 * D / 4 plus Lambert of base scaled by 1 - f0.
  const Frame frame(Vec3{0.0f, 0.0f, 1.0f});
  const Vec3 n{0.0f, 0.0f, 1.0f}, base{0.9f, 0.5f, 0.2f};
  const float alpha = 0.36f, d = 1.0f / (kPi * alpha * alpha);
  const Vec3 metal = Bsdf::metallic_roughness(frame, base, 1.0f, Ggx{alpha}).eval(n, n);
  const Vec3 dielectric = Bsdf::metallic_roughness(frame, base, 0.0f, Ggx{alpha}).eval(n, n);
  const Vec3 half = Bsdf::metallic_roughness(frame, base, 0.5f, Ggx{alpha}).eval(n, n);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(metal[c], base[c] * d / 4.0f, 1e-5f) << c;
    EXPECT_NEAR(dielectric[c], 0.04f * d / 4.0f + 0.96f * base[c] / kPi, 1e-5f) << c;
    EXPECT_NEAR(half[c], 0.5f * (metal[c] + dielectric[c]), 1e-5f) << c;
  }
  // At grazing half-vector angles Fresnel goes to f90 = 1 for both: the colour leaves a metal's
  // highlight (wo and wi grazing on opposite sides: h is near n, wo.h small).
  const Vec3 wo = direction(80.0f, 0.0f), wi = direction(80.0f, 179.0f);
  const Bsdf gold = Bsdf::metallic_roughness(frame, base, 1.0f, Ggx{0.5f});
  const Vec3 f = gold.eval(wo, wi);
  const float s5 = std::pow(1.0f - dot(wo, normalize(wo + wi)), 5.0f);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(f[c] / f.x, (base[c] + (1 - base[c]) * s5) / (base.x + (1 - base.x) * s5), 1e-4f);
}

TEST(Bsdf, MetallicRoughnessWithoutSpecularIsLambert) {
  // KHR_materials_specular's factor 0 removes the layer (f0 = f90 = 0): what remains is exactly
  // Lambert, which is how an OBJ's diffuse material survives a glTF round trip unchanged.
  const Frame frame(normalize(Vec3{0.2f, 0.3f, 1.0f}));
  const Vec3 base{0.7f, 0.4f, 0.1f};
  const Bsdf mr = Bsdf::metallic_roughness(frame, base, 0.0f, Ggx{0.5f}, Vec3{0.0f}, 0.0f);
  const Bsdf lambert = Bsdf::smooth(frame, base, Vec3{0.0f}, Ggx{1.0f});
  EXPECT_FALSE(mr.two_lobes());
  std::mt19937 gen(4);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 wo = world_wo(80.0f * u(gen));
    const float a = u(gen), b = u(gen), c = u(gen);
    BsdfSample s, t;
    ASSERT_EQ(mr.sample(wo, a, b, c, s), lambert.sample(wo, a, b, c, t));
    EXPECT_EQ(s.wi, t.wi);
    EXPECT_EQ(s.weight, t.weight);
    EXPECT_EQ(s.pdf, t.pdf);
    EXPECT_EQ(mr.eval(wo, s.wi), lambert.eval(wo, s.wi));
  }
}

}  // namespace
}  // namespace tracer
