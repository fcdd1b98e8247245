// map_Kd textures: texels land where their texture coordinates say, the lookup forgives letter
// case, and a missing texture is one warning and the material's Kd.
#include <gtest/gtest.h>
#include <stb_image_write.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "accel/accelerator.hpp"
#include "importers/obj_loader.hpp"
#include "io/exr_io.hpp"
#include "parallel/executor.hpp"
#include "render/render_image.hpp"
#include "scene/emission.hpp"
#include "scene/texture.hpp"
#include "shade/material_bsdf.hpp"
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
  // A 12x12 image of the quad, pixels 1, 4, 7 and 10 of each row and column centred on the texel
  // centres (a texel spans three pixels: the ray cone asks for no coarser level than the texels);
  // whitted with no light and ambient 1 shows the diffuse colour itself.
  RenderSettings s;
  s.width = s.height = 12;
  s.integrator = Integrator::Whitted;
  s.ambient = 1.0f;
  const float fov = 2.0f * std::atan(1.0f / 4.0f) * 180.0f / float(M_PI);
  const CameraSpec cam{{0, 0, 4}, {0, 0, 0}, {0, 1, 0}, fov};
  Framebuffer fb(s.width, s.height);
  PassContext ctx{&scene, Camera(cam, s.width, s.height), s, &fb};
  RenderMonitor control;
  ASSERT_TRUE(render_image(build_accelerator(scene, AccelOptions{}), ctx, SchedOptions{}, control));
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) {
      const uint8_t* t = &rgb[size_t(y * 4 + x) * 3];  // image row y is the top row y: v = 1 at the top
      const Vec3 c = fb.radiance(3 * x + 1, 3 * y + 1);
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
  EXPECT_FALSE(scene.materials[0].diffuse_texture.present());
  EXPECT_EQ(scene.materials[0].kd, (Vec3{0.1f, 0.2f, 0.3f}));
}

// map_Ks, map_Ns, map_Ke and norm, each a one-texel PNG: the specular colour is Ks times the
// texel, the shininess Ns times the texel as data, the emission Ke times the texel (Ke 1 where
// the MTL gives none), and norm the normal map; a missing one is its own grouped warning.
TEST(Texture, MtlMapsScaleTheirValues) {
  const std::string dir = test::temp_dir();
  const auto png = [&](const std::string& file, std::vector<uint8_t> rgb) {
    ASSERT_TRUE(stbi_write_png((dir + "/" + file).c_str(), 1, 1, 3, rgb.data(), 3));
  };
  png("ks.png", {255, 128, 0});
  png("ns.png", {51, 102, 153});  // as data: the mean 0.4
  png("ke.png", {0, 255, 128});
  png("n.png", {128, 128, 255});
  std::ofstream(dir + "/quad.obj") << "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
                                      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3 4/4\n"
                                      "usemtl lamp\nf 1/1 3/3 4/4\nusemtl lost\nf 1/1 2/2 3/3\n";
  std::ofstream(dir + "/quad.mtl") << "newmtl m\nKd 0.5 0.5 0.5\nKs 0.5 0.5 0.5\nNs 100\nillum 2\nmap_Ks ks.png\n"
                                      "map_Ns ns.png\nnorm -bm 0.5 n.png\nnewmtl lamp\nmap_Ke ke.png\n"
                                      "newmtl lost\nmap_Ks gone.png\n";
  std::vector<std::string> warnings;
  const Scene scene = load_obj(dir + "/quad.obj", [&](const std::string& w) { warnings.push_back(w); });
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("1 map_Ks texture(s) not used (first 'gone.png': not found); those materials use Ks"),
            std::string::npos)
      << warnings[0];
  const Material& m = scene.materials[0];
  ASSERT_TRUE(m.specular_texture.present() && m.shininess_texture.present() && m.normal_texture.present());
  EXPECT_EQ(m.normal_scale, 0.5f);
  Hit hit;
  hit.tri = 0;
  hit.u = hit.v = 0.3f;
  const MaterialPoint p = material_point(scene, hit, m);
  EXPECT_NEAR(p.specular.x, 0.5f, 1e-6f);
  EXPECT_NEAR(p.specular.y, 0.5f * srgb_to_linear(uint8_t(128)), 1e-6f);
  EXPECT_EQ(p.specular.z, 0.0f);
  EXPECT_NEAR(p.shininess, 40.0f, 1e-3f);
  const Material& lamp = scene.materials[1];
  EXPECT_EQ(lamp.ke, Vec3{1.0f});
  const Vec3 e = emitted_radiance(scene, 2, 0.3f, 0.3f);
  EXPECT_EQ(e.x, 0.0f);
  EXPECT_NEAR(e.y, 1.0f, 1e-6f);
  EXPECT_NEAR(e.z, srgb_to_linear(uint8_t(128)), 1e-6f);
  EXPECT_EQ(scene.emitters.size(), 1u);  // the lamp's triangle
  // Without the maps the same material is its plain values, bit for bit (OBJ images unchanged).
  Material plain = m;
  plain.specular_texture = plain.shininess_texture = TextureSlot{};
  const MaterialPoint q = material_point(scene, hit, plain);
  EXPECT_EQ(q.specular, m.ks);
  EXPECT_EQ(q.shininess, m.ns);
  std::filesystem::remove_all(dir);
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

TEST(Texture, MipLevelsAverageInLinearLight) {
  // A 4 x 4 checker of black and white: each 2 x 2 block of level 1 and the 1 x 1 level 2 hold
  // linear 0.5 (sRGB code 188), not the code 128 an average of the codes would give.
  std::vector<uint8_t> rgb;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 3; ++c) rgb.push_back((x + y) % 2 ? 255 : 0);
  const Texture t(4, 4, rgb);
  EXPECT_EQ(t.levels(), 3);
  for (const float lod : {1.0f, 1.5f, 2.0f, 7.0f}) {
    for (const float u : {0.1f, 0.6f}) {
      const Vec3 c = t.filtered(u, 0.3f, lod);
      EXPECT_NEAR(c.x, srgb_to_linear(188), 1e-6f) << lod;
      EXPECT_EQ(c.x, c.z);
    }
  }
  // Level 0 is the texels: bilinear, and between levels a blend.
  EXPECT_EQ(t.filtered(0.125f, 0.125f, 0.0f).x, t.bilinear(0.125f, 0.125f).x);
  EXPECT_EQ(t.filtered(0.125f, 0.125f, -3.0f).x, t.bilinear(0.125f, 0.125f).x);
  const float half = t.filtered(0.125f, 0.125f, 0.5f).x;
  EXPECT_NEAR(half, 0.5f * (t.bilinear(0.125f, 0.125f).x + srgb_to_linear(188)), 1e-6f);
  // Odd sizes halve down to 1 x 1 too.
  EXPECT_EQ(Texture(5, 3, std::vector<uint8_t>(5 * 3 * 3, 9)).levels(), 3);
}

TEST(Texture, RayConesFilterDistantTexturesAndKeepNearOnesSharp) {
  // A 10 x 10 plane under a 1024 x 1024 checker of single texels, seen from above by whitted with
  // ambient light only (each pixel: its texture colour). From far away a pixel spans ~37 texels:
  // with the cone's mip level every pixel is the checker's mean (linear 0.5); a point sample would
  // be 0 or 1. From close by a texel spans many pixels: the texels' own black and white show.
  const std::string dir = test::temp_dir();
  std::vector<uint8_t> rgb(size_t(1024) * 1024 * 3);
  for (size_t y = 0; y < 1024; ++y)
    for (size_t x = 0; x < 1024; ++x)
      for (size_t c = 0; c < 3; ++c) rgb[(y * 1024 + x) * 3 + c] = (x + y) % 2 ? 255 : 0;
  ASSERT_TRUE(stbi_write_png((dir + "/checker.png").c_str(), 1024, 1024, 3, rgb.data(), 1024 * 3));
  std::ofstream(dir + "/plane.obj") << "mtllib plane.mtl\nv -5 -5 0\nv 5 -5 0\nv 5 5 0\nv -5 5 0\n"
                                       "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl c\nf 1/1 2/2 3/3 4/4\n";
  std::ofstream(dir + "/plane.mtl") << "newmtl c\nKd 0.5 0.5 0.5\nmap_Kd checker.png\n";
  const std::string flags = " --integrator whitted --ambient 1 --width 64 --height 64 --fov 20 --exr float -q -o ";
  ASSERT_EQ(
      test::run_tracer("render " + dir + "/plane.obj --eye 0.01,0.02,20 --look 0.01,0.02,0" + flags + dir + "/far.exr")
          .exit_code,
      0);
  const Framebuffer far = read_exr(dir + "/far.exr");
  for (int y = 8; y < 56; ++y)
    for (int x = 8; x < 56; ++x) ASSERT_NEAR(far.radiance(x, y).x, 0.5f, 0.02f) << x << "," << y;
  ASSERT_EQ(test::run_tracer("render " + dir + "/plane.obj --eye 0.0012,0.0013,0.05 --look 0.0012,0.0013,0" + flags +
                             dir + "/near.exr")
                .exit_code,
            0);
  const Framebuffer near = read_exr(dir + "/near.exr");
  float lo = 1.0f, hi = 0.0f;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      lo = std::min(lo, near.radiance(x, y).x);
      hi = std::max(hi, near.radiance(x, y).x);
    }
  EXPECT_LT(lo, 0.1f);
  EXPECT_GT(hi, 0.9f);
  std::filesystem::remove_all(dir);
}

TEST(Texture, TheSharedScenesFindAllTheirDiffuseTextures) {
  if (!test::have_shared_scenes()) GTEST_SKIP() << "needs ../shared/scenes";
  for (const char* path : {"sponza/sponza.obj", "sibenik/sibenik.obj"}) {
    std::vector<std::string> warnings;
    const Scene scene = load_obj(test::scene_path(path), [&](const std::string& w) { warnings.push_back(w); });
    for (const std::string& w : warnings) {
      EXPECT_EQ(w.find("map_Kd"), std::string::npos) << w;
      EXPECT_EQ(w.find("map_bump"), std::string::npos) << w;
    }
    EXPECT_GT(scene.textures.size(), 0u) << path;
    EXPECT_FALSE(scene.corner_uvs.empty()) << path;
  }
}

TEST(ParallelTextures, TheSameSceneAsOneThread) {
  if (!test::have_shared_scenes()) GTEST_SKIP() << "needs ../shared/scenes";
  const std::string path = test::scene_path("sponza/sponza.obj");
  const Executor executor(Strategy::Tbb, 2);
  for (const uint64_t budget : {uint64_t(2048) << 20, uint64_t(2) << 20}) {
    LoadLimits one, many;
    one.textures.max_total_bytes = many.textures.max_total_bytes = budget;
    many.for_each = [&](size_t count, const std::function<void(size_t)>& body) { executor.for_each(count, body); };
    std::vector<std::string> w1, w2;
    const Scene a = load_obj(
        path, [&](const std::string& w) { w1.push_back(w); }, nullptr, one);
    const Scene b = load_obj(
        path, [&](const std::string& w) { w2.push_back(w); }, nullptr, many);
    EXPECT_EQ(w1, w2);
    ASSERT_EQ(a.textures.size(), b.textures.size());
    for (size_t t = 0; t < a.textures.size(); ++t) EXPECT_EQ(a.textures[t].srgb(), b.textures[t].srgb()) << t;
    ASSERT_EQ(a.materials.size(), b.materials.size());
    for (size_t m = 0; m < a.materials.size(); ++m) {
      EXPECT_EQ(a.materials[m].diffuse_texture, b.materials[m].diffuse_texture) << m;
    }
    if (budget < (uint64_t(100) << 20)) {
      EXPECT_FALSE(w1.empty());  // some textures left out, and said
    }
  }
}

}  // namespace
}  // namespace tracer
