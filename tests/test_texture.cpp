// map_Kd textures: texels land where their texture coordinates say, the lookup forgives letter
// case, and a missing texture is one warning and the material's Kd.
#include <gtest/gtest.h>
#include <stb_image_write.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "accel/accelerator.hpp"
#include "render/render_image.hpp"
#include "scene/obj_loader.hpp"
#include "scene/texture.hpp"
#include "test_util.hpp"

namespace tracer {
namespace {

// A 4x4 texture whose every texel differs: red grows to the right, green downward.
std::vector<uint8_t> pattern() {
  std::vector<uint8_t> rgb;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      rgb.push_back(uint8_t(40 + 60 * x));
      rgb.push_back(uint8_t(20 + 70 * y));
      rgb.push_back(uint8_t(200));
    }
  return rgb;
}

float srgb_to_linear(uint8_t code) {
  const float c = float(code) / 255.0f;
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// A textured quad filling [-1, 1]^2 at z = 0, v up, in `dir`; the MTL names the texture `texname`.
void write_scene(const std::string& dir, const std::string& texname) {
  std::ofstream(dir + "/quad.obj") << "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
                                      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl tex\nf 1/1 2/2 3/3 4/4\n";
  std::ofstream(dir + "/quad.mtl") << "newmtl tex\nKd 0.1 0.2 0.3\nmap_Kd " << texname << "\n";
}

TEST(Texture, TexelsAppearWhereTheirCoordinatesSay) {
  const std::string dir = test::temp_dir();
  const std::vector<uint8_t> rgb = pattern();
  ASSERT_TRUE(stbi_write_png((dir + "/checker.png").c_str(), 4, 4, 3, rgb.data(), 4 * 3));
  write_scene(dir, "CHECKER.PNG");  // the file is lower case: found ignoring case
  std::vector<std::string> warnings;
  const Scene scene = load_obj(dir + "/quad.obj", [&](const std::string& w) { warnings.push_back(w); });
  EXPECT_TRUE(warnings.empty()) << warnings.front();
  ASSERT_EQ(scene.textures.size(), 1u);
  // A 4x4 image of the quad, each pixel centre on a texel centre; whitted with no light and
  // ambient 1 shows the diffuse colour itself.
  RenderSettings s;
  s.width = s.height = 4;
  s.integrator = Integrator::Whitted;
  s.ambient = 1.0f;
  const float fov = 2.0f * std::atan(1.0f / 4.0f) * 180.0f / float(M_PI);
  const CameraSpec cam{{0, 0, 4}, {0, 0, 0}, {0, 1, 0}, fov};
  Framebuffer fb(s.width, s.height);
  RenderContext ctx{&scene, Camera(cam, s.width, s.height), s, &fb};
  RenderControl control;
  ASSERT_TRUE(render_image(build_accelerator(scene, AccelOptions{}), ctx, SchedOptions{}, control));
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) {
      const uint8_t* t = &rgb[size_t(y * 4 + x) * 3];  // image row y is the top row y: v = 1 at the top
      const Vec3 c = fb.radiance(x, y);
      EXPECT_NEAR(c.x, srgb_to_linear(t[0]), 1e-4f) << x << "," << y;
      EXPECT_NEAR(c.y, srgb_to_linear(t[1]), 1e-4f) << x << "," << y;
      EXPECT_NEAR(c.z, srgb_to_linear(t[2]), 1e-4f) << x << "," << y;
    }
  }
}

TEST(Texture, BilinearBlendsNeighboursAndWraps) {
  const Texture t(2, 1, {0, 0, 0, 255, 255, 255});
  EXPECT_NEAR(t.bilinear(0.25f, 0.5f).x, 0.0f, 1e-6f);   // the centre of texel 0
  EXPECT_NEAR(t.bilinear(0.75f, 0.5f).x, 1.0f, 1e-6f);   // the centre of texel 1
  EXPECT_NEAR(t.bilinear(0.5f, 0.5f).x, 0.5f, 1e-6f);    // halfway
  EXPECT_NEAR(t.bilinear(1.25f, 0.5f).x, 0.0f, 1e-6f);   // wraps
  EXPECT_NEAR(t.bilinear(-0.25f, 0.5f).x, 1.0f, 1e-6f);  // wraps below 0
}

TEST(Texture, MissingTextureWarnsOnceAndUsesKd) {
  const std::string dir = test::temp_dir();
  write_scene(dir, "nowhere.png");
  std::ofstream(dir + "/quad.mtl", std::ios::app) << "newmtl tex2\nmap_Kd nowhere.png\nnewmtl tex3\nmap_Kd gone.jpg\n";
  std::vector<std::string> warnings;
  const Scene scene = load_obj(dir + "/quad.obj", [&](const std::string& w) { warnings.push_back(w); });
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("3 map_Kd texture(s) not used"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("nowhere.png"), std::string::npos) << warnings[0];
  EXPECT_TRUE(scene.textures.empty());
  EXPECT_EQ(scene.materials[0].diffuse_texture, kInvalidIndex);
  EXPECT_EQ(scene.materials[0].kd, (Vec3{0.1f, 0.2f, 0.3f}));
}

TEST(Texture, UnreadableTextureWarnsWithTheReason) {
  const std::string dir = test::temp_dir();
  std::ofstream(dir + "/bad.png") << "not a png";
  write_scene(dir, "bad.png");
  std::vector<std::string> warnings;
  const Scene scene = load_obj(dir + "/quad.obj", [&](const std::string& w) { warnings.push_back(w); });
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("cannot read texture"), std::string::npos) << warnings[0];
}

TEST(Texture, AnyCaseLookupMatchesEveryComponent) {
  const std::string dir = test::temp_dir();
  std::filesystem::create_directories(dir + "/Maps");
  std::ofstream(dir + "/Maps/Stone.JPG") << "x";
  EXPECT_EQ(find_file_any_case(dir, "maps/stone.jpg"), std::filesystem::path(dir + "/Maps/Stone.JPG"));
  EXPECT_EQ(find_file_any_case(dir, "MAPS\\STONE.jpg"), std::filesystem::path(dir + "/Maps/Stone.JPG"));
  EXPECT_EQ(find_file_any_case(dir, "Maps/Stone.JPG"), std::filesystem::path(dir + "/Maps/Stone.JPG"));
  EXPECT_FALSE(find_file_any_case(dir, "maps/other.jpg"));
}

TEST(Texture, TheSharedScenesFindAllTheirDiffuseTextures) {
  if (!test::have_shared_scenes()) GTEST_SKIP() << "needs ../shared/scenes";
  for (const char* path : {"sponza/sponza.obj", "sibenik/sibenik.obj"}) {
    std::vector<std::string> warnings;
    const Scene scene = load_obj(test::scene_path(path), [&](const std::string& w) { warnings.push_back(w); });
    for (const std::string& w : warnings) EXPECT_EQ(w.find("map_Kd"), std::string::npos) << w;
    EXPECT_GT(scene.textures.size(), 0u) << path;
    EXPECT_FALSE(scene.corner_uvs.empty()) << path;
  }
}

}  // namespace
}  // namespace tracer
