// The path integrator against answers known in closed form (furnaces), against itself (light
// sampling with MIS and BSDF sampling alone converge to the same image) and in its convergence
// rate (RMSE falls as 1/sqrt(spp)).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "accel/accelerator.hpp"
#include "importers/obj_loader.hpp"
#include "render/render_image.hpp"
#include "scene/builtin.hpp"
#include "test_util.hpp"

namespace tracer {
namespace {

Framebuffer render_path(const Scene& scene, const CameraSpec& cam, RenderSettings s) {
  s.integrator = Integrator::Path;
  Framebuffer fb(s.width, s.height);
  PassContext ctx{&scene, Camera(cam, s.width, s.height), s, &fb};
  RenderMonitor control;
  SchedOptions so;
  so.strategy = Strategy::Tbb;
  EXPECT_TRUE(render_round(build_accelerator(scene, AccelOptions{}), ctx, sample_passes(s), so, control));
  return fb;
}

// A sphere of one material; `inward` flips the winding so its front faces the centre.
Scene sphere_scene(const Material& mat, bool inward) {
  Scene s;
  s.materials = {mat};
  IndexedMesh m = make_uv_sphere(Vec3{0.0f}, 1.0f, 96, 48);
  if (inward) {
    for (size_t i = 0; i + 2 < m.indices.size(); i += 3) std::swap(m.indices[i + 1], m.indices[i + 2]);
  }
  s.add_mesh("sphere", m.vertices, m.indices, 0);
  s.finalize();
  return s;
}

TEST(Path, FurnaceDiffuseSphereInUniformLightShowsItsAlbedo) {
  // A convex diffuse sphere of albedo a under an environment of radiance 1: every path reflects
  // once and escapes, so every pixel on the sphere is a (and the background 1).
  for (const float albedo : {1.0f, 0.5f}) {
    Material m;
    m.kd = Vec3{albedo};
    const Scene scene = sphere_scene(m, false);
    RenderSettings s;
    s.width = s.height = 16;
    s.spp = 4;
    s.environment = Vec3{1.0f};
    const Framebuffer fb = render_path(scene, CameraSpec{{0, 0, 4}, {0, 0, 0}, {0, 1, 0}, 40.0f}, s);
    for (int y = 0; y < s.height; ++y) {
      for (int x = 0; x < s.width; ++x) {
        const float v = fb.radiance(x, y).x;
        // Pixels on the silhouette mix sphere and background; the centre block is all sphere.
        if (x >= 5 && x < 11 && y >= 5 && y < 11) {
          EXPECT_NEAR(v, albedo, 0.01f * albedo) << x << "," << y;
        }
        EXPECT_GE(v, albedo * 0.99f);
        EXPECT_LE(v, 1.0f + 1e-5f);
      }
    }
  }
}

TEST(Path, FurnaceGlossySphereReflectsNoMoreThanItReceives) {
  Material m;
  m.kd = Vec3{0.0f};
  m.ks = Vec3{1.0f};
  m.ns = 30.0f;
  const Scene scene = sphere_scene(m, false);
  RenderSettings s;
  s.width = s.height = 8;
  s.spp = 64;
  s.environment = Vec3{1.0f};
  const Framebuffer fb = render_path(scene, CameraSpec{{0, 0, 4}, {0, 0, 0}, {0, 1, 0}, 20.0f}, s);
  const float centre = fb.radiance(4, 4).x;
  EXPECT_LE(centre, 1.01f);
  EXPECT_GT(centre, 0.9f);  // a narrow lobe seen head on loses little to masking
}

TEST(Path, ClosedEmittingSphereSeenFromInsideIsEOverOneMinusA) {
  // Inside a closed sphere of emission E and albedo a, radiance is E + aE + a^2 E + ... = E/(1-a),
  // with next-event estimation and MIS, and with BSDF sampling alone.
  const float e = 1.0f, a = 0.5f;
  Material m;
  m.kd = Vec3{a};
  m.ke = Vec3{e};
  const Scene scene = sphere_scene(m, true);
  for (const LightSampling ls : {LightSampling::Mis, LightSampling::Bsdf}) {
    RenderSettings s;
    s.width = s.height = 16;
    s.spp = 64;
    s.max_depth = 64;
    s.light_sampling = ls;
    const Framebuffer fb = render_path(scene, CameraSpec{{0.1f, 0.2f, 0.3f}, {0, 0, -1}, {0, 1, 0}, 60.0f}, s);
    double sum = 0.0;
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x) sum += fb.radiance(x, y).x;
    EXPECT_NEAR(sum / (s.width * s.height), e / (1.0f - a), 0.01 * e / (1.0f - a))
        << name_of<LightSampling>(kLightSamplingNames, ls);
  }
}

TEST(Path, FurnaceDiffuseSphereUnderAUniformEnvironmentMapShowsItsAlbedo) {
  // The furnace again, lit by a constant environment map (importance-sampled as a map, by
  // luminance, and combined with BSDF samples by MIS) rather than the uniform sky: the same
  // answer, a, with the light sampling's noise only.
  Material m;
  m.kd = Vec3{0.5f};
  Scene scene = sphere_scene(m, false);
  scene.environment_map = EnvironmentMap(64, 32, std::vector<Vec3>(64 * 32, Vec3{2.0f}), 40.0f);
  RenderSettings s;
  s.width = s.height = 16;
  s.spp = 256;
  s.environment = Vec3{0.5f};  // scales the map: radiance 1
  const Framebuffer fb = render_path(scene, CameraSpec{{0, 0, 4}, {0, 0, 0}, {0, 1, 0}, 40.0f}, s);
  double sum = 0.0;
  for (int y = 5; y < 11; ++y)
    for (int x = 5; x < 11; ++x) sum += fb.radiance(x, y).x;
  EXPECT_NEAR(sum / 36.0, 0.5, 0.005);
  EXPECT_EQ(fb.radiance(0, 0).x, 1.0f);  // the background: the map, seen directly
}

double image_mean(const Framebuffer& fb);

// Two 24 x 24 renders of one scene by different estimators agree in mean luminance, over the
// image (within 2 %, 4 % with half the samples, under a sanitizer) and per quadrant (5 %, 10 %).
void expect_same_mean(const Framebuffer& a, const Framebuffer& b, bool many_samples) {
  const double ma = image_mean(a), mb = image_mean(b);
  EXPECT_NEAR(ma, mb, (many_samples ? 0.02 : 0.04) * ma);
  for (int q = 0; q < 4; ++q) {
    double sa = 0.0, sb = 0.0;
    for (int y = (q / 2) * 12; y < (q / 2) * 12 + 12; ++y)
      for (int x = (q % 2) * 12; x < (q % 2) * 12 + 12; ++x) {
        sa += luminance(a.radiance(x, y));
        sb += luminance(b.radiance(x, y));
      }
    EXPECT_NEAR(sa, sb, (many_samples ? 0.05 : 0.10) * sa) << "quadrant " << q;
  }
}

TEST(Path, SkyAndEnvironmentMapLightSamplingMatchBsdfSampling) {
  // Next-event estimation of the environment, a uniform sky and a map with a bright patch, is
  // unbiased: with MIS and with BSDF sampling alone the Cornell box lit only through its open
  // front converges to the same image (mean and per quadrant).
  if (!test::have_shared_scenes()) GTEST_SKIP() << "needs ../shared/scenes";
  Scene scene = load_obj(test::scene_path("cornell-box/CornellBox-Original.obj"), [](const std::string&) {});
  scene.lights.clear();
  scene.emitters = Emitters{};
  std::vector<Vec3> texels(32 * 16, Vec3{0.3f});
  for (int y = 6; y < 9; ++y)
    for (int x = 14; x < 18; ++x) texels[size_t(y) * 32 + size_t(x)] = Vec3{30.0f, 20.0f, 10.0f};
  const CameraSpec cam{{0, 1, 3}, {0, 1, 0}, {0, 1, 0}, 60.0f};
  for (const bool with_map : {false, true}) {
    if (with_map) scene.environment_map = EnvironmentMap(32, 16, texels, 100.0f);
    RenderSettings s;
    s.width = s.height = 24;
    s.spp = test::ray_budget(100'000) >= 100'000 ? 512 : 256;
    s.environment = Vec3{1.0f};
    s.light_sampling = LightSampling::Mis;
    const Framebuffer mis = render_path(scene, cam, s);
    s.light_sampling = LightSampling::Bsdf;
    const Framebuffer bsdf = render_path(scene, cam, s);
    SCOPED_TRACE(with_map ? "map" : "uniform sky");
    expect_same_mean(mis, bsdf, s.spp >= 512);
  }
}

TEST(Path, WhittedSeesTheEnvironmentWhereNothingIsHit) {
  Material m;
  m.kd = Vec3{0.5f};
  Scene scene = sphere_scene(m, false);
  std::vector<Vec3> texels(8 * 4);
  for (size_t i = 0; i < texels.size(); ++i) texels[i] = Vec3{float(i), 1.0f, 2.0f};
  scene.environment_map = EnvironmentMap(8, 4, texels);
  RenderSettings s;
  s.integrator = Integrator::Whitted;
  s.width = s.height = 8;
  s.environment = Vec3{0.5f};
  Framebuffer fb(s.width, s.height);
  const Camera camera(CameraSpec{{0, 0, 4}, {0, 0, 0}, {0, 1, 0}, 60.0f}, s.width, s.height);
  PassContext ctx{&scene, camera, s, &fb};
  RenderMonitor control;
  ASSERT_TRUE(render_round(build_accelerator(scene, AccelOptions{}), ctx, sample_passes(s), SchedOptions{}, control));
  const Ray corner = camera.primary_ray(0, 0);
  const Vec3 expected = scene.environment_map.radiance(corner.dir) * 0.5f;
  EXPECT_EQ(fb.radiance(0, 0).x, expected.x);
  EXPECT_EQ(fb.radiance(0, 0).z, 1.0f);
}

double image_mean(const Framebuffer& fb) {
  double sum = 0.0;
  for (int y = 0; y < fb.height(); ++y)
    for (int x = 0; x < fb.width(); ++x) sum += double(luminance(fb.radiance(x, y)));
  return sum / (double(fb.width()) * fb.height());
}

TEST(Path, LightSamplingAndBsdfSamplingConvergeToTheSameImage) {
  // The Cornell box with its lamp three times as wide (so BSDF sampling alone finds it often
  // enough for a quadrant's mean to be known within ~1.5 % at 512 spp; the original lamp leaves
  // the floor's quadrants 5-12 % apart from seed to seed): MIS and BSDF-only sampling agree.
  if (!test::have_shared_scenes()) GTEST_SKIP() << "needs ../shared/scenes";
  Scene scene = load_obj(test::scene_path("cornell-box/CornellBox-Original.obj"), [](const std::string&) {});
  for (size_t t = 0; t < scene.triangles.size(); ++t) {
    if (max_component(scene.materials[scene.tri_material[t]].ke) <= 0.0f) continue;
    for (Vec3* v : {&scene.triangles[t].v0, &scene.triangles[t].v1, &scene.triangles[t].v2}) {
      v->x = 3.0f * v->x;
      v->z = 3.0f * v->z;
    }
  }
  scene.finalize();
  const CameraSpec cam{{0, 1, 3}, {0, 1, 0}, {0, 1, 0}, 60.0f};
  RenderSettings s;
  s.width = s.height = 24;
  s.spp = test::ray_budget(100'000) >= 100'000 ? 512 : 256;
  s.light_sampling = LightSampling::Mis;
  const Framebuffer mis = render_path(scene, cam, s);
  s.light_sampling = LightSampling::Bsdf;
  const Framebuffer bsdf = render_path(scene, cam, s);
  expect_same_mean(mis, bsdf, s.spp >= 512);
}

TEST(Path, RmseFallsAsOneOverSqrtSpp) {
  // The built-in box at 4, 16 and 64 spp against a 1024-spp reference: each fourfold increase
  // halves the RMSE (within 20 %; the reference's own noise is 1/16 of the 64-spp variance). The
  // error is measured on the displayed (tone-mapped) values, as a viewer sees noise: in linear
  // radiance the few pixels on the lamp's edge (Ke 17 beside 0.5) dominate and make the RMSE of
  // one small image a noisy statistic.
  if (test::ray_budget(100'000) < 100'000) GTEST_SKIP() << "too slow under a sanitizer";
  const Scene scene = make_cornell_box();
  RenderSettings s;
  s.width = s.height = 32;
  s.spp = 1024;
  s.seed = 1;
  const Image8 reference = tonemap(render_path(scene, *scene.camera, s), s.exposure);
  double previous = 0.0;
  for (const int spp : {4, 16, 64}) {
    s.spp = spp;
    s.seed = 2;
    const Image8 img = tonemap(render_path(scene, *scene.camera, s), s.exposure);
    double se = 0.0;
    for (size_t i = 0; i < img.rgb.size(); ++i) {
      const double d = (double(img.rgb[i]) - double(reference.rgb[i])) / 255.0;
      se += d * d;
    }
    const double rmse = std::sqrt(se / double(img.rgb.size()));
    if (previous > 0.0) {
      EXPECT_NEAR(previous / rmse, 2.0, 0.4) << spp << " spp: RMSE " << rmse << " after " << previous;
    }
    previous = rmse;
  }
}

}  // namespace
}  // namespace tracer

namespace tracer {
namespace {

// A floor under a large square lamp 0.3 above it: where the lamp fills most of a point's sky,
// area sampling's 1/d^2 noise is largest.
Scene big_lamp_scene() {
  Scene s;
  Material floor, lamp;
  floor.kd = Vec3{0.7f};
  lamp.kd = Vec3{0.0f};
  lamp.ke = Vec3{4.0f};
  s.materials = {floor, lamp};
  s.add_mesh("floor", {{-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2}}, {0, 3, 2, 0, 2, 1}, 0);
  s.add_mesh("lamp", {{-0.8f, 0.3f, -0.8f}, {0.8f, 0.3f, -0.8f}, {0.8f, 0.3f, 0.8f}, {-0.8f, 0.3f, 0.8f}},
             {0, 1, 2, 0, 2, 3}, 1);
  s.finalize();
  return s;
}

TEST(Path, EmittersBySolidAngleGiveAreaSamplingsImageWithLessNoise) {
  const Scene by_angle = big_lamp_scene();
  Scene by_area = by_angle;
  by_area.emitters = Emitters(by_area, /*solid_angle=*/false);
  const CameraSpec cam{{0.0f, 1.2f, 3.5f}, {0.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, 50.0f};
  // Each way, two renders of other seeds: their mean, the variance of that mean (from each
  // pixel's samples, taken as independent), and their squared difference (the error as it is).
  double mean[2], var[2], difference[2];
  for (int m = 0; m < 2; ++m) {
    const Scene& scene = m == 0 ? by_angle : by_area;
    const Accelerator accel = build_accelerator(scene, AccelOptions{});
    RenderSettings s;
    s.integrator = Integrator::Path;
    s.width = s.height = 32;
    s.spp = 64;
    std::vector<Framebuffer> images;
    mean[m] = var[m] = difference[m] = 0.0;
    for (const uint32_t seed : {1u, 2u}) {
      s.seed = seed;
      Framebuffer fb(s.width, s.height);
      FeatureFilm film(s.width, s.height);
      PassContext ctx{&scene, Camera(cam, s.width, s.height), s, &fb};
      ctx.features = &film;
      RenderMonitor control;
      ASSERT_TRUE(render_round(accel, ctx, sample_passes(s), SchedOptions{}, control));
      for (int y = 0; y < s.height; ++y) {
        for (int x = 0; x < s.width; ++x) {
          mean[m] += double(fb.radiance(x, y).x);
          var[m] += double(film.variance_of_mean(x, y).x);
        }
      }
      images.push_back(std::move(fb));
    }
    for (int y = 0; y < s.height; ++y) {
      for (int x = 0; x < s.width; ++x) {
        const double d = double(images[0].radiance(x, y).x) - double(images[1].radiance(x, y).x);
        difference[m] += d * d;
      }
    }
    const double n = double(2 * s.width * s.height);
    mean[m] /= n;
    var[m] /= n * n;
  }
  // The same image within four standard errors, and the error between two renders a third
  // (when written; in linear radiance, where the lamp's edge pixels, as noisy either way, count most).
  EXPECT_NEAR(mean[0], mean[1], 4.0 * std::sqrt(var[0] + var[1])) << mean[0] << " " << mean[1];
  EXPECT_LT(difference[0], 0.5 * difference[1]) << difference[0] << " " << difference[1];
}

}  // namespace
}  // namespace tracer
