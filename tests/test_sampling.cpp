// The samplers: the stratification of the Sobol-Burley sequence, and the environment map's
// importance sampling against its own density (chi-square) and against the sphere (it integrates
// to one).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <random>
#include <vector>

#include "math/sampling.hpp"
#include "math/sobol.hpp"
#include "math/spherical_triangle.hpp"
#include "scene/emission.hpp"
#include "scene/emitters.hpp"
#include "scene/environment_map.hpp"
#include "scene/scene.hpp"
#include "test_util.hpp"

namespace tracer {
namespace {

TEST(Sobol, UnscrambledPointsAreTheSobolSequence) {
  // Dimension 0 is the van der Corput sequence; dimension 1 (x + 1) the classic second one.
  const double d0[8] = {0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875};
  const double d1[8] = {0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875};
  for (uint32_t i = 0; i < 8; ++i) {
    EXPECT_EQ(sobol_point(i, 0) * 0x1p-32, d0[i]) << i;
    EXPECT_EQ(sobol_point(i, 1) * 0x1p-32, d1[i]) << i;
  }
  // Each dimension alone: the first 2^m points fill the 2^m intervals of width 2^-m once each.
  for (int d = 0; d < 4; ++d) {
    for (uint32_t m = 0; m <= 10; ++m) {
      std::vector<int> seen(1u << m, 0);
      for (uint32_t i = 0; i < (1u << m); ++i) ++seen[m == 0 ? 0 : sobol_point(i, d) >> (32 - m)];
      for (int c : seen) ASSERT_EQ(c, 1) << "dim " << d << ", m " << m;
    }
  }
}

// The first 2^m samples of a pixel put exactly one point in every elementary interval of area
// 2^-m of dimensions 0 and 1 (a (0,m,2)-net), and one in every interval of width 2^-m of each
// dimension alone: for every pixel, dimension set and m up to 12.
TEST(Sobol, FirstPowerOfTwoSamplesOfAPixelAreStratified) {
  for (uint32_t pixel : {0u, 1u, 77u, 123456u}) {
    for (uint32_t set : {0u, 1u, 5u, 31u}) {
      const PixelSampler first(pixel, 0, 3);
      for (uint32_t m = 0; m <= 12; ++m) {
        const uint32_t n = 1u << m;
        std::vector<std::array<float, 4>> pts(n);
        for (uint32_t i = 0; i < n; ++i) pts[i] = PixelSampler(pixel, i, 3).get<4>(set);
        for (uint32_t a = 0; a <= m; ++a) {  // intervals of 2^-a by 2^-(m-a)
          std::vector<int> seen(n, 0);
          for (const auto& p : pts) {
            const uint32_t x = uint32_t(p[0] * float(1u << a)), y = uint32_t(p[1] * float(1u << (m - a)));
            ++seen[(y << a) | x];
          }
          for (int c : seen) ASSERT_EQ(c, 1) << "pixel " << pixel << " set " << set << " m " << m << " a " << a;
        }
        for (int d = 0; d < 4; ++d) {
          std::vector<int> seen(n, 0);
          for (const auto& p : pts) ++seen[uint32_t(p[d] * float(n))];
          for (int c : seen) ASSERT_EQ(c, 1) << "dimension " << d << " m " << m;
        }
      }
      // Fewer dimensions are the same numbers: get<N> is a prefix of get<4>.
      EXPECT_EQ(first.get<2>(set)[1], first.get<4>(set)[1]);
      EXPECT_EQ(first.get<1>(set)[0], first.get<4>(set)[0]);
    }
  }
}

TEST(Sobol, SetsAndPixelsAreScrambledApart) {
  // Different sets and pixels give different points for the same sample (independent scrambles),
  // and one (pixel, sample, set) always the same.
  const PixelSampler s(5, 9, 0);
  EXPECT_NE(s.get<2>(0), s.get<2>(1));
  EXPECT_NE(s.get<2>(0), PixelSampler(6, 9, 0).get<2>(0));
  EXPECT_NE(s.get<2>(0), PixelSampler(5, 9, 1).get<2>(0));
  EXPECT_EQ(s.get<3>(7), PixelSampler(5, 9, 0).get<3>(7));
  // Samples past 2^20 still differ from each other.
  EXPECT_NE(PixelSampler(5, (1u << 20) + 1, 0).get<2>(0), PixelSampler(5, (1u << 20) + 2, 0).get<2>(0));
}

// A 32 x 16 map: a gradient from the top, a bright patch, a black band and one coloured texel.
EnvironmentMap test_map(float rotation) {
  const int w = 32, h = 16;
  std::vector<Vec3> texels(size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Vec3 v{1.0f + float(h - y)};
      if (x >= 20 && x < 24 && y >= 3 && y < 6) v = Vec3{200.0f};
      if (y == 10) v = Vec3{0.0f};
      texels[size_t(y) * w + size_t(x)] = v;
    }
  texels[size_t(12) * w + 3] = Vec3{0.0f, 0.0f, 40.0f};  // blue only: luminance from B alone
  return EnvironmentMap(w, h, std::move(texels), rotation);
}

TEST(EnvironmentMap, DensityIntegratesToOneOverTheSphere) {
  for (const float rotation : {0.0f, 73.0f}) {
    const EnvironmentMap map = test_map(rotation);
    // Midpoint rule in (theta, phi) on a grid finer than the texels.
    const int nt = 512, np = 1024;
    double sum = 0.0;
    const double pi = std::numbers::pi;
    for (int i = 0; i < nt; ++i) {
      const double theta = pi * (i + 0.5) / nt;
      for (int j = 0; j < np; ++j) {
        const double phi = 2 * pi * (j + 0.5) / np;
        const Vec3 d{float(std::sin(theta) * std::cos(phi)), float(std::cos(theta)),
                     float(std::sin(theta) * std::sin(phi))};
        sum += map.pdf(d) * std::sin(theta) * (pi / nt) * (2 * pi / np);
      }
    }
    EXPECT_NEAR(sum, 1.0, 2e-3) << rotation;
  }
}

TEST(EnvironmentMap, SamplesFollowTheirDensityChiSquare) {
  // Directions drawn from the map, counted in a 24 x 12 grid of (phi, cos theta) cells (not the
  // texels'), against each cell's probability integrated from pdf(). The statistic of a correct
  // sampler is below the 0.1 % quantile of chi-square with the grid's degrees of freedom; a
  // sampler off by a cell's row or by sin(theta) is far above it.
  const EnvironmentMap map = test_map(30.0f);
  const int nphi = 24, nz = 12, n = 200000;
  std::vector<double> observed(nphi * nz, 0.0), expected(nphi * nz, 0.0);
  const auto cell = [&](Vec3 d) {
    const double phi = std::atan2(double(d.z), double(d.x)) + std::numbers::pi;
    const int i = std::min(int(phi / (2 * std::numbers::pi) * nphi), nphi - 1);
    const int j = std::min(int((double(d.y) + 1.0) / 2.0 * nz), nz - 1);
    return j * nphi + i;
  };
  int mismatched = 0;
  for (int k = 0; k < n; ++k) {
    const std::array<float, 2> u = PixelSampler(uint32_t(k) >> 10, uint32_t(k) & 1023u, 11).get<2>(0);
    Vec3 d;
    float pdf = 0.0f;
    ASSERT_TRUE(map.sample(u[0], u[1], d, pdf));
    ASSERT_NEAR(length(d), 1.0f, 1e-5f);
    // The density returned is pdf()'s, but for the rare direction that rounds into the next texel.
    if (std::fabs(pdf - map.pdf(d)) > 1e-2f * pdf) ++mismatched;
    observed[cell(d)] += 1.0;
  }
  EXPECT_LT(mismatched, n / 1000);
  // Expected counts: pdf integrated over each cell (uniform in phi and z = cos theta: dw = dphi dz).
  const int sub = 32;
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nphi; ++i)
      for (int a = 0; a < sub; ++a)
        for (int b = 0; b < sub; ++b) {
          const double phi = (i + (a + 0.5) / sub) / nphi * 2 * std::numbers::pi - std::numbers::pi;
          const double z = (j + (b + 0.5) / sub) / nz * 2.0 - 1.0, r = std::sqrt(1.0 - z * z);
          const Vec3 d{float(r * std::cos(phi)), float(z), float(r * std::sin(phi))};
          expected[j * nphi + i] += map.pdf(d) * (2 * std::numbers::pi / nphi / sub) * (2.0 / nz / sub) * n;
        }
  double chi2 = 0.0;
  int dof = -1;
  for (size_t c = 0; c < observed.size(); ++c) {
    if (expected[c] < 5.0) {
      EXPECT_LE(observed[c], 20.0) << "cell " << c;  // (almost) never drawn where the density is ~0
      continue;
    }
    chi2 += (observed[c] - expected[c]) * (observed[c] - expected[c]) / expected[c];
    ++dof;
  }
  // The 0.1 % quantile of chi-square(dof) by the Wilson-Hilferty approximation.
  const double z = 3.09, k = dof;
  const double quantile = k * std::pow(1.0 - 2.0 / (9 * k) + z * std::sqrt(2.0 / (9 * k)), 3.0);
  EXPECT_LT(chi2, quantile) << "dof " << dof;
}

TEST(EnvironmentMap, RadianceIsTheTexelTheDirectionFallsIn) {
  const EnvironmentMap map = test_map(0.0f);
  // Straight up: the top row, whose value is 1 + 16.
  EXPECT_EQ(map.radiance(Vec3{0.0f, 1.0f, 0.0f}).x, 17.0f);
  // Turned by 90 degrees, what was at +x is at +z (phi = atan2(z, x) grows toward +z).
  const EnvironmentMap turned = test_map(90.0f);
  for (const Vec3 d : {Vec3{0.6f, 0.3f, 0.2f}, Vec3{-0.1f, -0.7f, 0.5f}}) {
    const Vec3 rd{-d.z, d.y, d.x};  // d turned by -90 degrees about +y
    EXPECT_EQ(turned.radiance(normalize(d)).z, map.radiance(normalize(rd)).z);
  }
  // Negative and non-finite texels read as black.
  const EnvironmentMap bad(2, 1, {Vec3{-1.0f, NAN, INFINITY}, Vec3{1.0f}});
  EXPECT_EQ(bad.radiance(Vec3{-1.0f, 0.0f, 0.01f}).x + bad.radiance(Vec3{-1.0f, 0.0f, 0.01f}).y, 0.0f);
}

}  // namespace
}  // namespace tracer

namespace tracer {
namespace {

// One emissive triangle, large and close above the origin, its front face down toward it.
Scene one_emitter() {
  Scene s;
  Material lamp;
  lamp.kd = Vec3{0.0f};
  lamp.ke = Vec3{1.0f};
  s.materials = {lamp};
  s.add_mesh("lamp", {{-1.0f, 0.5f, -1.0f}, {1.2f, 0.5f, -1.0f}, {0.0f, 0.5f, 1.5f}}, {0, 1, 2}, 0);
  s.finalize();
  if (s.triangles[0].normal().y > 0.0f) {  // make the front face the origin
    Scene flipped;
    flipped.materials = s.materials;
    flipped.add_mesh("lamp", {{-1.0f, 0.5f, -1.0f}, {1.2f, 0.5f, -1.0f}, {0.0f, 0.5f, 1.5f}}, {0, 2, 1}, 0);
    flipped.finalize();
    return flipped;
  }
  return s;
}

// Where the ray from `o` along `d` meets triangle `t` (Moller-Trumbore), if it does.
std::optional<Vec3> hit_point(const Triangle& t, Vec3 o, Vec3 d) {
  const Vec3 e1 = t.v1 - t.v0, e2 = t.v2 - t.v0, p = cross(d, e2);
  const float det = dot(e1, p);
  if (std::fabs(det) < 1e-12f) return std::nullopt;
  const Vec3 s = o - t.v0;
  const float u = dot(s, p) / det;
  const Vec3 q = cross(s, e1);
  const float v = dot(d, q) / det, dist = dot(e2, q) / det;
  if (u < 0.0f || v < 0.0f || u + v > 1.0f || dist <= 0.0f) return std::nullopt;
  return o + d * dist;
}

// Chi-square test of `sampled`'s directions from the origin against `judged`'s pdf over a
// (theta, phi) grid of the upper hemisphere (theta from +y), as the BSDFs' test does; returns the
// upper tail probability. `integral`: the judged pdf integrated over the hemisphere.
double emitter_chi_square(const Scene& scene, const Emitters& sampled, const Emitters& judged, double& integral) {
  constexpr int kTheta = 24, kPhi = 48, kSamples = 400000, kSub = 8;
  const Frame frame(Vec3{0.0f, 1.0f, 0.0f});
  std::vector<double> observed(kTheta * kPhi, 0.0), expected(kTheta * kPhi, 0.0);
  std::mt19937 gen(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const auto cell = [&](Vec3 w) {
    const Vec3 l = frame.to_local(w);
    const double theta = std::acos(std::clamp(double(l.z), -1.0, 1.0));
    double phi = std::atan2(double(l.y), double(l.x));
    if (phi < 0) phi += 2.0 * std::numbers::pi;
    return size_t(std::min(kTheta - 1, int(theta / (std::numbers::pi / 2) * kTheta)) * kPhi +
                  std::min(kPhi - 1, int(phi / (2.0 * std::numbers::pi) * kPhi)));
  };
  for (int i = 0; i < kSamples; ++i) {
    EmitterSample s;
    if (sampled.sample(scene, Vec3{0.0f}, u(gen), u(gen), u(gen), s)) observed[cell(s.wi)] += 1.0;
  }
  const double dt = std::numbers::pi / 2 / kTheta, dp = 2.0 * std::numbers::pi / kPhi;
  integral = 0.0;
  for (int ti = 0; ti < kTheta; ++ti) {
    for (int pi = 0; pi < kPhi; ++pi) {
      double sum = 0.0;
      for (int a = 0; a < kSub; ++a) {
        for (int b = 0; b < kSub; ++b) {
          const double theta = (ti + (a + 0.5) / kSub) * dt, phi = (pi + (b + 0.5) / kSub) * dp;
          const Vec3 w = frame.to_world(Vec3{float(std::sin(theta) * std::cos(phi)),
                                             float(std::sin(theta) * std::sin(phi)), float(std::cos(theta))});
          if (const std::optional<Vec3> p = hit_point(scene.triangles[0], Vec3{0.0f}, w)) {
            sum += double(judged.pdf(scene, 0, kInvalidIndex, Vec3{0.0f}, *p)) * std::sin(theta);
          }
        }
      }
      expected[size_t(ti * kPhi + pi)] = sum * dt * dp / (kSub * kSub) * kSamples;
      integral += sum * dt * dp / (kSub * kSub);
    }
  }
  return test::chi_square_tail(observed, expected);
}

TEST(EmitterSampling, SolidAngleSamplesFollowTheirPdfWhichIntegratesToOne) {
  const Scene scene = one_emitter();
  const double omega =
      triangle_solid_angle(Vec3{0.0f}, scene.triangles[0].v0, scene.triangles[0].v1, scene.triangles[0].v2);
  ASSERT_GT(omega, Emitters::kMinSolidAngle);  // a triangle sampled by solid angle from here
  ASSERT_LT(omega, Emitters::kMaxSolidAngle);
  const Emitters by_angle(scene, true), by_area(scene, false);
  for (const Emitters* e : {&by_angle, &by_area}) {
    double integral = 0.0;
    EXPECT_GT(emitter_chi_square(scene, *e, *e, integral), 1e-4);
    EXPECT_NEAR(integral, 1.0, 0.01);
  }
  // The test can fail: area samples judged by the solid-angle density.
  double integral = 0.0;
  EXPECT_LT(emitter_chi_square(scene, by_area, by_angle, integral), 1e-5);
}

// The lamp of one_emitter() as a quad of two triangles beside each other, each of emission 2
// times a texture: the first's black, the second's a 4 x 4 gradient over its corners (bilinear).
Scene textured_lamp() {
  Scene s;
  Material lamp;
  lamp.kd = Vec3{0.0f};
  lamp.ke = Vec3{2.0f};
  lamp.emission_texture.texture = 0;
  s.materials = {lamp, lamp};
  s.materials[0].emission_texture.texture = 1;
  std::vector<uint8_t> rgb;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) rgb.insert(rgb.end(), {uint8_t(40 * x + 30 * y), uint8_t(200 - 40 * x), uint8_t(60)});
  s.textures.push_back(Texture(4, 4, rgb));
  s.textures.push_back(Texture(1, 1, {0, 0, 0}));
  // Both wound so the front faces down, toward the origin.
  s.add_mesh("black", {{-1.0f, 0.5f, -1.0f}, {0.0f, 0.5f, 1.0f}, {1.0f, 0.5f, -1.0f}}, {0, 2, 1}, 0);
  s.add_mesh("lit", {{0.0f, 0.5f, 1.0f}, {1.0f, 0.5f, -1.0f}, {2.0f, 0.5f, 1.0f}}, {0, 1, 2}, 1);
  s.corner_uvs = {{0.5f, 0.5f}, {0.5f, 0.5f}, {0.5f, 0.5f}, {0.0f, 0.0f}, {1.0f, 0.0f}, {1.0f, 1.0f}};
  s.finalize();
  return s;
}

TEST(EmitterSampling, TexturedEmissionIsSampledByItsPowerAndReadAtThePoint) {
  const Scene scene = textured_lamp();
  ASSERT_LT(scene.triangles[0].normal().y, 0.0f);
  // The black triangle is no emitter and adds nothing to its light's power.
  EXPECT_EQ(mean_emission(scene, 0), Vec3{0.0f});
  ASSERT_EQ(scene.emitters.size(), 1u);
  ASSERT_EQ(scene.lights.size(), 1u);
  const float area = 0.5f * length(scene.triangles[1].normal());
  const Vec3 mean = mean_emission(scene, 1);
  EXPECT_NEAR(scene.lights[0].power.x, mean.x * area, 1e-5f * mean.x * area);
  // The mean over the triangle against a fine numerical one (400 x 400 stratified points).
  Vec3 fine{0.0f};
  for (int i = 0; i < 400; ++i) {
    for (int j = 0; j < 400; ++j) {
      float b1, b2;
      uniform_triangle((i + 0.5f) / 400.0f, (j + 0.5f) / 400.0f, b1, b2);
      fine += emitted_radiance(scene, 1, b1, b2) * (1.0f / 160000.0f);
    }
  }
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean[c], fine[c], 0.02f * fine[c]) << c;
  // Irradiance at the origin (normal +y): the estimate of sampled points (radiance x cos / pdf)
  // against the integral of the emission over the quad, by both samplings.
  double reference = 0.0;
  for (uint32_t t = 0; t < 2; ++t) {
    const Triangle tri = scene.triangles[t];
    const float a = 0.5f * length(tri.normal());
    for (int i = 0; i < 400; ++i) {
      for (int j = 0; j < 400; ++j) {
        float b1, b2;
        uniform_triangle((i + 0.5f) / 400.0f, (j + 0.5f) / 400.0f, b1, b2);
        const Vec3 p = tri.v0 * (1.0f - b1 - b2) + tri.v1 * b1 + tri.v2 * b2;
        const float d2 = dot(p, p), cos_r = p.y / std::sqrt(d2), cos_l = cos_r;  // the lamp is level
        reference += double(emitted_radiance(scene, t, b1, b2).x) * cos_r * cos_l / d2 * a / 160000.0;
      }
    }
  }
  std::mt19937 gen(17);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (const bool solid_angle : {true, false}) {
    const Emitters e(scene, solid_angle);
    const int n = 400000;
    double sum = 0.0, sq = 0.0;
    for (int i = 0; i < n; ++i) {
      EmitterSample s;
      if (!e.sample(scene, Vec3{0.0f}, u(gen), u(gen), u(gen), s)) continue;
      ASSERT_GT(max_component(s.radiance), 0.0f);  // only the lit triangle is sampled
      const double x = double(s.radiance.x) * s.wi.y / s.pdf;
      sum += x;
      sq += x * x;
    }
    const double mean_x = sum / n, sigma = std::sqrt(std::max(0.0, sq / n - mean_x * mean_x) / n);
    EXPECT_NEAR(mean_x, reference, 4.0 * sigma + 1e-3 * reference) << solid_angle;
  }
}

}  // namespace
}  // namespace tracer
