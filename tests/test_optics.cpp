// Specular optics against analytic answers, and the whitted integrator on scenes whose radiance
// is known in closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "accel/accelerator.hpp"
#include "render/render_image.hpp"
#include "shade/optics.hpp"
#include "test_util.hpp"

namespace tracer {
namespace {

Vec3 unit_at(float degrees) {  // in the xz-plane, travelling down onto the surface y = 0
  const float a = degrees * std::numbers::pi_v<float> / 180.0f;
  return Vec3{std::sin(a), -std::cos(a), 0.0f};
}

TEST(Optics, ReflectionMirrorsAboutTheNormal) {
  const Vec3 r = reflect(unit_at(30.0f), Vec3{0, 1, 0});
  EXPECT_NEAR(r.x, std::sin(30.0f * std::numbers::pi_v<float> / 180.0f), 1e-6f);
  EXPECT_NEAR(r.y, std::cos(30.0f * std::numbers::pi_v<float> / 180.0f), 1e-6f);
  EXPECT_NEAR(r.z, 0.0f, 1e-7f);
}

TEST(Optics, RefractionFollowsSnellsLaw) {
  for (const float n : {1.33f, 1.5f, 2.5f}) {
    for (const float degrees : {0.0f, 10.0f, 30.0f, 60.0f, 89.0f}) {
      Vec3 t;
      ASSERT_TRUE(refract(unit_at(degrees), Vec3{0, 1, 0}, 1.0f / n, t)) << n << " " << degrees;
      const float sin_i = std::sin(degrees * std::numbers::pi_v<float> / 180.0f);
      EXPECT_NEAR(t.x, sin_i / n, 1e-6f);  // n1 sin(i) = n2 sin(t), in the plane of incidence
      EXPECT_LT(t.y, 0.0f);                // through the surface
      EXPECT_NEAR(length(t), 1.0f, 1e-6f);
    }
  }
}

TEST(Optics, TotalInternalReflectionBeyondTheCriticalAngle) {
  // Leaving glass (1.5) into air: the critical angle is asin(1/1.5) = 41.81 degrees.
  const float critical = std::asin(1.0f / 1.5f) * 180.0f / std::numbers::pi_v<float>;
  Vec3 t;
  EXPECT_TRUE(refract(unit_at(critical - 0.05f), Vec3{0, 1, 0}, 1.5f, t));
  EXPECT_FALSE(refract(unit_at(critical + 0.05f), Vec3{0, 1, 0}, 1.5f, t));
  const float c_below = std::cos((critical - 0.05f) * std::numbers::pi_v<float> / 180.0f);
  const float c_above = std::cos((critical + 0.05f) * std::numbers::pi_v<float> / 180.0f);
  EXPECT_LT(fresnel_dielectric(c_below, 1.5f, 1.0f), 1.0f);
  EXPECT_EQ(fresnel_dielectric(c_above, 1.5f, 1.0f), 1.0f);
}

TEST(Optics, FresnelAtNormalAndGrazingIncidenceAndReciprocity) {
  for (const float n : {1.33f, 1.5f, 2.5f}) {
    const float f0 = (n - 1.0f) * (n - 1.0f) / ((n + 1.0f) * (n + 1.0f));
    EXPECT_NEAR(fresnel_dielectric(1.0f, 1.0f, n), f0, 1e-6f);
    EXPECT_NEAR(fresnel_dielectric(1.0f, n, 1.0f), f0, 1e-6f);
    EXPECT_NEAR(fresnel_dielectric(0.0f, 1.0f, n), 1.0f, 1e-6f);
    // The same reflectance from either side of the interface along the same path.
    for (const float degrees : {15.0f, 40.0f, 70.0f}) {
      const float cos_i = std::cos(degrees * std::numbers::pi_v<float> / 180.0f);
      const float sin_t = std::sin(degrees * std::numbers::pi_v<float> / 180.0f) / n;
      const float cos_t = std::sqrt(1.0f - sin_t * sin_t);
      EXPECT_NEAR(fresnel_dielectric(cos_i, 1.0f, n), fresnel_dielectric(cos_t, n, 1.0f), 1e-5f) << degrees;
    }
  }
}

// A quad (two triangles) of one material, in the plane z = `z`, facing +z, half-size `h`.
void add_quad(Scene& s, float z, float h, uint32_t material) {
  s.add_mesh("quad", {{-h, -h, z}, {h, -h, z}, {h, h, z}, {-h, h, z}}, {0, 1, 2, 0, 2, 3}, material);
}

// The radiance at the centre pixel of a whitted render of `scene` seen from (0, 0, 5) down -z.
Vec3 centre_radiance(const Scene& scene) {
  RenderSettings s;
  s.width = s.height = 9;
  s.integrator = Integrator::Whitted;
  s.ambient = 0.0f;
  Framebuffer fb(s.width, s.height);
  const CameraSpec cam{{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 10.0f};
  PassContext ctx{&scene, Camera(cam, s.width, s.height), s, &fb};
  RenderMonitor control;
  EXPECT_TRUE(render_image(build_accelerator(scene, AccelOptions{}), ctx, SchedOptions{}, control));
  return fb.radiance(4, 4);
}

TEST(Whitted, GlassSlabTransmitsWhatFresnelLeaves) {
  // An emitter of radiance 1 behind a glass slab (n = 1.5, Tf = 1) seen head on: each face
  // transmits 1 - F0 with F0 = 0.04, and light bouncing twice inside adds a factor 1 + F0^2.
  Scene s;
  Material glass;
  glass.illum = 7;
  glass.ni = 1.5f;
  Material emitter;
  emitter.kd = Vec3{0.0f};
  emitter.ke = Vec3{1.0f};
  s.materials = {glass, emitter};
  add_quad(s, 0.5f, 2.0f, 0);
  add_quad(s, -0.5f, 2.0f, 0);
  add_quad(s, -3.0f, 4.0f, 1);
  s.finalize();
  const float f0 = 0.04f;
  const float expected = (1.0f - f0) * (1.0f - f0) * (1.0f + f0 * f0);
  const Vec3 l = centre_radiance(s);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(l[c], expected, 2e-5f);
}

TEST(Whitted, MirrorShowsWhatItFacesWeightedByKs) {
  // A mirror (Ks = 0.8, 0.5, 0.2) facing the camera, with an emitter of radiance 1 around the
  // camera facing the mirror: the centre pixel sees the emitter through the mirror.
  Scene s;
  Material mirror;
  mirror.illum = 5;
  mirror.kd = Vec3{0.0f};
  mirror.ks = Vec3{0.8f, 0.5f, 0.2f};
  Material emitter;
  emitter.kd = Vec3{0.0f};
  emitter.ke = Vec3{1.0f};
  s.materials = {mirror, emitter};
  add_quad(s, 0.0f, 2.0f, 0);
  // The emitter behind the camera (z = 8), facing -z toward the mirror.
  s.add_mesh("lamp", {{-4, -4, 8}, {-4, 4, 8}, {4, 4, 8}, {4, -4, 8}}, {0, 1, 2, 0, 2, 3}, 1);
  s.finalize();
  const Vec3 l = centre_radiance(s);
  EXPECT_NEAR(l.x, 0.8f, 1e-6f);
  EXPECT_NEAR(l.y, 0.5f, 1e-6f);
  EXPECT_NEAR(l.z, 0.2f, 1e-6f);
}

TEST(Whitted, VertexNormalsShadeDiffuseSurfaces) {
  // A diffuse quad lit by a point light on its axis (at the camera): with vertex normals tilted
  // 60 degrees from the face, the lit radiance is cos 60 = 1/2 of that with normals along it.
  const auto radiance = [](Vec3 vn) {
    Scene s;
    Material white;
    white.kd = Vec3{1.0f};
    s.materials = {white};
    add_quad(s, 0.0f, 2.0f, 0);
    s.corner_normals.assign(6, vn);
    s.finalize();
    Light light;
    light.position = Vec3{0, 0, 5};
    light.power = Vec3{25.0f};
    s.lights = {light};
    return centre_radiance(s);
  };
  const float c = std::cos(60.0f * std::numbers::pi_v<float> / 180.0f),
              sn = std::sin(60.0f * std::numbers::pi_v<float> / 180.0f);
  const Vec3 straight = radiance(Vec3{0, 0, 1});
  const Vec3 tilted = radiance(Vec3{0, sn, c});
  EXPECT_NEAR(straight.x, std::numbers::inv_pi_v<float>, 1e-4f);  // kd/pi * I cos / d^2, I = d^2
  EXPECT_NEAR(tilted.x / straight.x, c, 1e-4f);
  // Vertex normals pointing away from the camera side are turned to it, not shading as black.
  EXPECT_NEAR(radiance(Vec3{0, 0, -1}).x, straight.x, 1e-6f);
}

}  // namespace
}  // namespace tracer
