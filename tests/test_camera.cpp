// The thin-lens camera: without a lens it is the pinhole; with one, the plane in focus stays
// sharp, a point off it blurs into the circle the thin-lens formula gives, the lens is sampled
// uniformly, and renders through it are the same for every scheduler.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>

#include "math/sampling.hpp"
#include "scene/camera.hpp"
#include "test_util.hpp"

namespace tracer {
namespace {

constexpr int kSide = 64;

CameraSpec lens_spec(float radius, float focus) {
  CameraSpec s{{0.0f, 1.0f, 3.0f}, {0.0f, 1.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, 50.0f};
  s.lens_radius = radius;
  s.focus_distance = focus;
  return s;
}

// Where `r` crosses the plane at distance `depth` along the view direction (-z from z = 3).
Vec3 at_depth(const Ray& r, float depth) {
  const float t = depth / -r.dir.z;
  return r.org + r.dir * t;
}

TEST(Camera, WithoutALensEveryLensPointGivesThePinholeRay) {
  const Camera cam(lens_spec(0.0f, 0.0f), kSide, kSide);
  EXPECT_FALSE(cam.thin_lens());
  for (const float u : {0.0f, 0.3f, 0.999f}) {
    const Ray a = cam.ray_through(10.5f, 20.25f), b = cam.ray_through(10.5f, 20.25f, u, 1.0f - u);
    EXPECT_EQ(a.org, b.org);
    EXPECT_EQ(a.dir, b.dir);
  }
}

TEST(Camera, ThePlaneInFocusStaysSharp) {
  const float focus = 2.5f;
  const Camera cam(lens_spec(0.2f, focus), kSide, kSide);
  ASSERT_TRUE(cam.thin_lens());
  for (const auto& [px, py] : {std::pair{32.0f, 32.0f}, {3.5f, 60.25f}, {63.0f, 0.5f}}) {
    const Vec3 sharp = at_depth(cam.ray_through(px, py), focus);
    for (int i = 0; i < 8; ++i) {
      for (int j = 0; j < 8; ++j) {
        const Ray r = cam.ray_through(px, py, (i + 0.5f) / 8.0f, (j + 0.5f) / 8.0f);
        EXPECT_NEAR(std::fabs(3.0f - r.org.z), 0.0f, 1e-6f);  // on the lens, in the eye's plane
        const Vec3 p = at_depth(r, focus);
        EXPECT_NEAR(length(p - sharp), 0.0f, 2e-6f * focus);
      }
    }
  }
}

// Rays through the image centre from the lens's rim cross the plane at depth z at a distance
// R |1 - z / f| from the axis: the blur circle of the thin-lens model, of radius R at the lens, 0
// in focus, growing linearly past it.
TEST(Camera, BlurCircleFollowsTheThinLensFormula) {
  const float radius = 0.15f, focus = 2.0f;
  const Camera cam(lens_spec(radius, focus), kSide, kSide);
  for (const float z : {0.5f, 1.0f, 3.0f, 6.0f}) {
    for (const auto& [u1, u2] : {std::pair{1.0f, 0.5f}, {0.0f, 0.5f}, {0.5f, 1.0f}, {0.5f, 0.0f}}) {
      const Ray r = cam.ray_through(32.0f, 32.0f, u1, u2);
      const Vec3 p = at_depth(r, z);
      const float off_axis = std::hypot(p.x, p.y - 1.0f);
      EXPECT_NEAR(off_axis, radius * std::fabs(1.0f - z / focus), 1e-5f) << "z " << z;
    }
  }
}

// The concentric map is uniform on the disk: 32 equal-area cells (8 sectors x 4 rings), 64k
// points, chi-square against 31 degrees of freedom (61.1 is the 0.1 % quantile); the stream is
// fixed, so the test is deterministic.
TEST(Camera, LensPointsAreUniformOnTheDisk) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  std::array<int, 32> cells{};
  constexpr int kPoints = 1 << 16;
  for (int i = 0; i < kPoints; ++i) {
    const Vec2 d = concentric_disk(u01(rng), u01(rng));
    const float r2 = d.x * d.x + d.y * d.y;
    ASSERT_LE(r2, 1.0f + 1e-6f);
    const int ring = std::min(3, int(r2 * 4.0f));
    const float angle = std::atan2(d.y, d.x) + float(M_PI);
    const int sector = std::min(7, int(angle / (2.0f * float(M_PI)) * 8.0f));
    ++cells[size_t(ring * 8 + sector)];
  }
  double chi2 = 0.0;
  const double expected = kPoints / 32.0;
  for (const int c : cells) chi2 += (c - expected) * (c - expected) / expected;
  EXPECT_LT(chi2, 61.1);
}

// Depth of field through the whole renderer: the same image for every scheduler and thread count
// (each sample's lens point is a function of the pixel and the sample), a different one from the
// pinhole's, and --aperture 0 is the pinhole.
TEST(Camera, LensRendersAreTheSameForEverySchedulerAndApertureZeroIsThePinhole) {
  const std::string dir = test::temp_dir();
  for (const char* integrator : {"path --spp 3", "ao"}) {
    SCOPED_TRACE(integrator);
    const std::string base = std::string("render -q --width 24 --height 20 --integrator ") + integrator;
    const std::string lens = " --aperture 0.1 --focus-distance 2";
    const auto a = test::run_tracer(base + lens + " --threads 1 --sched seq -o " + dir + "/a.ppm");
    const auto b = test::run_tracer(base + lens + " --threads 2 --sched tbb --tile 7 -o " + dir + "/b.ppm");
    const auto pin = test::run_tracer(base + " -o " + dir + "/pin.ppm");
    const auto zero = test::run_tracer(base + " --aperture 0 -o " + dir + "/zero.ppm");
    for (const auto* r : {&a, &b, &pin, &zero}) ASSERT_EQ(r->exit_code, 0) << r->output;
    EXPECT_EQ(test::read_bytes(dir + "/a.ppm"), test::read_bytes(dir + "/b.ppm"));
    EXPECT_NE(test::read_bytes(dir + "/a.ppm"), test::read_bytes(dir + "/pin.ppm"));
    EXPECT_EQ(test::read_bytes(dir + "/pin.ppm"), test::read_bytes(dir + "/zero.ppm"));
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace tracer
