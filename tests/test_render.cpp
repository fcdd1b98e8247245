// Images: an analytic Lambert answer, golden images of the study's scenes, determinism.
#include <gtest/gtest.h>

#include <fstream>

#include <bit>
#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>

#include "accel/accelerator.hpp"
#include "accel/wide_bvh/wide_bvh.hpp"
#include "io/image_io.hpp"
#include "render/ao.hpp"
#include "render/render_image.hpp"
#include "render/render_tile.hpp"
#include "scene/builtin.hpp"
#include "test_util.hpp"

namespace tracer {
namespace {

Framebuffer render(const Scene& scene, const CameraSpec& cam, const RenderSettings& s, const AccelOptions& ao = {},
                   const SchedOptions& so = {}) {
  const Accelerator acc = build_accelerator(scene, ao);
  Framebuffer fb(s.width, s.height);
  PassContext ctx{&scene, Camera(cam, s.width, s.height), s, &fb};
  RenderMonitor control;
  EXPECT_TRUE(render_image(acc, ctx, so, control));
  return fb;
}

TEST(Render, LitQuadMatchesLambert) {
  // A 10x10 quad in z = 0 facing +z (filling the view), Kd 0.5, one point light of intensity 3 at (0.5, -0.25, 2),
  // AO off and no ambient: each pixel's radiance is Kd/pi * I * cos(theta) / d^2.
  Scene scene =
      test::scene_of({Triangle{{-5, -5, 0}, {5, -5, 0}, {5, 5, 0}}, Triangle{{-5, -5, 0}, {5, 5, 0}, {-5, 5, 0}}});
  scene.materials[0].kd = Vec3{0.5f};
  const Vec3 light{0.5f, -0.25f, 2.0f};
  scene.lights.push_back(Light{.position = light, .normal = {}, .power = Vec3{3.0f}});
  const CameraSpec cam{{0, 0, 3}, {0, 0, 0}, {0, 1, 0}, 60.0f};
  RenderSettings s;
  s.width = 32;
  s.height = 24;
  s.ao_samples = 0;
  s.ambient = 0.0f;
  const Framebuffer fb = render(scene, cam, s);
  const Camera camera(cam, s.width, s.height);
  int checked = 0;
  for (int y = 0; y < s.height; y += 5) {
    for (int x = 0; x < s.width; x += 7) {
      const Ray r = camera.primary_ray(x, y);
      const float t = -r.org.z / r.dir.z;
      const Vec3 p = r.org + r.dir * t;
      const Vec3 to = light - p;
      const float d2 = dot(to, to);
      const float expected = 0.5f / std::numbers::pi_v<float> * 3.0f * (to.z / std::sqrt(d2)) / d2;
      EXPECT_NEAR(fb.radiance(x, y).x, expected, 2e-3f * expected) << x << "," << y << " got " << fb.radiance(x, y).x;
      EXPECT_FLOAT_EQ(fb.radiance(x, y).x, fb.radiance(x, y).z);
      ++checked;
    }
  }
  EXPECT_GT(checked, 20);
}

TEST(Render, ShadowedPointIsAmbientOnly) {
  // A blocker between the light and the quad's centre leaves exactly the ambient term there.
  Scene scene =
      test::scene_of({Triangle{{-2, -2, 0}, {2, -2, 0}, {2, 2, 0}}, Triangle{{-2, -2, 0}, {2, 2, 0}, {-2, 2, 0}},
                      Triangle{{-0.2f, -0.2f, 1}, {0.2f, -0.2f, 1}, {0, 0.3f, 1}}});
  scene.lights.push_back(Light{.position = {0, 0, 2}, .normal = {}, .power = Vec3{3.0f}});
  const CameraSpec cam{{0.0f, -1.0f, 3.0f}, {0, 0, 0}, {0, 1, 0}, 60.0f};
  RenderSettings s;
  s.width = s.height = 33;
  s.ao_samples = 0;
  s.ambient = 0.25f;
  const Camera camera(cam, s.width, s.height);
  const Framebuffer fb = render(scene, cam, s);
  // Find the pixel whose primary ray hits the quad nearest (0,0,0) and is not the blocker itself.
  const Vec3 c = fb.radiance(16, 16);
  const Ray r = camera.primary_ray(16, 16);
  ASSERT_NEAR(-r.org.z / r.dir.z * r.dir.x + r.org.x, 0.0f, 0.1f);
  EXPECT_NEAR(c.x, 0.7f * 0.25f, 1e-6f);  // default Kd 0.7 times ambient
}

TEST(Render, SameRenderTwiceIsByteIdentical) {
  const Scene scene = make_cornell_box(200);
  RenderSettings s;
  s.width = s.height = 48;
  const Image8 a = tonemap(render(scene, *scene.camera, s), s.exposure);
  const Image8 b = tonemap(render(scene, *scene.camera, s), s.exposure);
  EXPECT_EQ(a.rgb, b.rgb);
  s.seed = 7;  // and the seed matters
  const Image8 c = tonemap(render(scene, *scene.camera, s), s.exposure);
  EXPECT_NE(a.rgb, c.rgb);
}

// --count renders through the counting kernels: the same image, and counts that are a function
// of the rays alone (the same for every scheduler and thread count).
TEST(Render, CountedTraversalChangesNoPixelAndCountsTheSameEverywhere) {
  const Scene scene = make_cornell_box(200);
  for (const Integrator integrator : {Integrator::Ao, Integrator::Path}) {
    for (const int together : {2, 1, 0}) {  // packets and AO streams, packets and AO bundles, single rays
      RenderSettings s;
      s.width = s.height = 40;
      s.integrator = integrator;
      s.packets = together > 0 && integrator == Integrator::Ao;
      s.streams = together == 2;
      s.spp = integrator == Integrator::Path ? 4 : 1;
      SCOPED_TRACE(std::string(name_of<Integrator>(kIntegratorNames, integrator)) +
                   (s.packets ? (s.streams ? " streams" : " packets") : ""));
      const Accelerator acc = build_accelerator(scene, AccelOptions{});
      QueryCounts first;
      std::map<Strategy, TraversalCounts> first_any;  // per scheduler: its tiles
      std::vector<float> plain;
      for (const auto& [kind, threads] :
           {std::pair{Strategy::Seq, 1}, {Strategy::Tbb, 2}, {Strategy::Queue, 3}, {Strategy::Tbb, 1}}) {
        for (const bool counted : {false, true}) {
          RenderSettings r = s;
          r.count_traversal = counted;
          Framebuffer fb(r.width, r.height);
          PassContext ctx{&scene, Camera(*scene.camera, r.width, r.height), r, &fb};
          RenderMonitor control;
          SchedOptions so;
          so.strategy = kind;
          so.threads = threads;
          ASSERT_TRUE(render_round(acc, ctx, sample_passes(r), so, control));
          std::vector<float> sums;
          for (size_t i = 0; i < fb.pixel_count(); ++i) {
            for (int k = 0; k < 3; ++k) sums.push_back(fb.sums()[i][k]);
          }
          if (plain.empty()) plain = sums;
          EXPECT_EQ(sums, plain);  // counting changes no pixel, nor does the scheduler
          const QueryCounts c = control.traversal.load();
          if (!counted) {
            EXPECT_EQ(c.closest.rays + c.any.rays, 0u);  // off means off
            continue;
          }
          const RayCounts rays = control.counts.load();
          EXPECT_EQ(c.closest.rays, rays.primary + rays.secondary);
          EXPECT_EQ(c.any.rays, rays.shadow + rays.ao);
          EXPECT_GE(c.closest.nodes, c.closest.rays);  // every query visits the root
          EXPECT_GT(c.any.packs, 0u);
          if (first.closest.rays == 0) first = c;
          EXPECT_EQ(c.closest, first.closest);
          // Streams: a stream is a chunk of a tile and its occluder cache lives as long as the
          // stream, so what the any-hit queries visit is a function of the rays and the tiles (of
          // the scheduler), not of the thread count.
          if (!s.streams) {
            EXPECT_EQ(c.any, first.any);
          }
          EXPECT_EQ(c.any.rays, first.any.rays);
          if (!first_any.count(kind)) first_any[kind] = c.any;
          EXPECT_EQ(c.any, first_any[kind]);
        }
      }
    }
  }
}

// The 8-wide BVH, counting the AO rays each path of a stream chunk takes.
struct ChunkSpy {
  const WideBvh* bvh;
  mutable uint64_t streamed = 0, bundled = 0;
  bool intersect(const Ray& r, Hit& h) const { return bvh->intersect(r, h); }
  bool occluded(const Ray& r) const { return bvh->occluded(r); }
  void intersect_packet(const RayPacket& p, Hit* h) const { bvh->intersect_packet(p, h); }
  uint32_t occluded_bundle_from(const RayBundle& b, uint32_t origin) const {
    bundled += uint64_t(std::popcount(b.active));
    return bvh->occluded_bundle_from(b, origin);
  }
  void occluded_stream(const RayStream& s, StreamMask& m) const {
    streamed += s.size;
    bvh->occluded_stream(s, m);
  }
};

// A stream chunk's AO rays go as a stream where its probe finds them nearly all blocked (inside a
// closed box) and as bundles where a quarter or more escape (a floor under the open sky); either
// way each pixel's colour is the one the 4x4 blocks give (as radiance() does, tested elsewhere).
TEST(Render, StreamChunksTraceOpenViewsByBundlesAndClosedOnesAsStreams) {
  const auto quad = [](std::vector<Triangle>& t, Vec3 o, Vec3 u, Vec3 v) {
    t.push_back({o, o + u, o + u + v});
    t.push_back({o, o + u + v, o + v});
  };
  std::vector<Triangle> floor, box;
  quad(floor, {-100, 0, -100}, {200, 0, 0}, {0, 0, 200});
  for (int a = 0; a < 3; ++a) {  // the six faces of the cube [-1, 1]^3
    Vec3 o{-1, -1, -1}, u{0, 0, 0}, v{0, 0, 0};
    u[(a + 1) % 3] = 2.0f;
    v[(a + 2) % 3] = 2.0f;
    quad(box, o, u, v);
    o[a] = 1.0f;
    quad(box, o, u, v);
  }
  struct Case {
    const char* name;
    Scene scene;
    CameraSpec camera;
    bool streamed;
  };
  Case cases[] = {{"floor", test::scene_of(floor), CameraSpec{{0, 5, 0}, {0, 0, 0}, {0, 0, -1}, 60.0f}, false},
                  {"box", test::scene_of(box), CameraSpec{{0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 60.0f}, true}};
  for (Case& c : cases) {
    SCOPED_TRACE(c.name);
    RenderSettings s;
    s.width = s.height = kChunkEdge;
    s.ao_samples = 16;
    const WideBvh bvh(c.scene, BvhBuildOptions{});
    const ChunkSpy spy{&bvh};
    Framebuffer fb(s.width, s.height);
    const PassContext ctx{&c.scene, Camera(c.camera, s.width, s.height), s, &fb};
    const PixelChunk chunk{0, 0, kChunkEdge, kChunkEdge};
    Vec3 streamed[kChunkPixels];
    RayCounts counts;
    AoIntegrator{}.chunk_radiance(spy, ctx, chunk, streamed, counts);
    EXPECT_EQ(counts.ao, uint64_t(kChunkPixels) * 16u);
    EXPECT_EQ(spy.streamed + spy.bundled, counts.ao);
    EXPECT_EQ(spy.streamed > 0, c.streamed);
    EXPECT_EQ(spy.bundled, c.streamed ? 16u * 16u : counts.ao);  // the probe: a pixel per 4x4 block
    for (int by = 0; by < kChunkEdge; by += kPacketEdge) {
      for (int bx = 0; bx < kChunkEdge; bx += kPacketEdge) {
        const PixelBlock block = primary_block(ctx, bx, by, kChunkEdge, kChunkEdge);
        Vec3 blocks[kPacketSize];
        AoIntegrator{}.block_radiance(bvh, ctx, block, blocks, counts);
        for (int k = 0; k < kPacketSize; ++k) EXPECT_EQ(streamed[chunk.index(block.x(k), block.y(k))], blocks[k]);
      }
    }
  }
}

// Renders `scene` (empty: the built-in box) at 96x96 with `flags` and requires the bytes of
// tests/golden/`golden`.png, or with `min_psnr` a PSNR of at least that many dB; the PSNR is
// printed on failure.
void expect_golden(const std::string& scene, const std::string& flags, const std::string& golden,
                   double min_psnr = 0.0) {
  SCOPED_TRACE(golden);
  const std::string dir = test::temp_dir();
  const std::string out = dir + "/" + golden + ".png";
  const auto r = test::run_tracer("render " + scene + " " + flags + " -q --width 96 --height 96 -o " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Image8 expected = read_image(std::string(TRACER_GOLDEN_DIR) + "/" + golden + ".png");
  const Image8 got = read_image(out);
  if (min_psnr > 0.0) {
    EXPECT_GE(test::psnr(expected, got), min_psnr);
  } else {
    EXPECT_EQ(expected.rgb, got.rgb) << "PSNR " << test::psnr(expected, got) << " dB";
  }
  std::filesystem::remove_all(dir);
}

std::string cornell(const std::string& name) { return test::scene_path("cornell-box/CornellBox-" + name + ".obj"); }

// Golden images: 96x96, the study's workload with its default settings (16 AO rays), made with
//   tracer render ../shared/scenes/cornell-box/CornellBox-X.obj --integrator ao --width 96
//     --height 96 --accel brute --sched seq -o tests/golden/X.png
// (and with no scene for builtin.png), then looked at. The test renders through the default
// path and requires the same bytes: every accelerator, SIMD target, scheduler and thread count
// computes the same floats (tested elsewhere), so the study's workload is byte-identical to its
// golden images. The tolerance is zero; only a different libm (another platform's exp/pow/sin)
// could move a pixel, and then PSNR says how far.
TEST(Render, GoldenImages) {
  expect_golden("", "--integrator ao", "builtin");
  if (!test::have_shared_scenes()) return;
  for (const char* name : {"Original", "Mirror", "Sphere", "Water"})
    expect_golden(cornell(name), "--integrator ao", name);
}

// Whitted reference images: 96x96, made with
//   tracer render ../shared/scenes/cornell-box/CornellBox-X.obj --integrator whitted --width 96
//     --height 96 -o tests/golden/whitted-X.png
// and looked at (the mirror block and spheres reflect the walls; the glass, Tf 0.1, is dark).
// Rendered here through the scalar BVH one ray at a time on one thread, against images made
// with the default 8-wide BVH on all threads: the same bytes.
TEST(Render, WhittedGoldenImages) {
  if (!test::have_shared_scenes()) GTEST_SKIP() << "no ../shared/scenes";
  for (const char* name : {"Mirror", "Sphere", "Water"}) {
    expect_golden(cornell(name), "--integrator whitted --accel bvh --sched seq", std::string("whitted-") + name);
  }
}

// Reference images of the renderer: whitted and path (16 spp, seed 0) of the Cornell boxes and
// the textured Sponza (its view), 96x96, made with
//   tracer render ../shared/scenes/cornell-box/CornellBox-X.obj --integrator path --spp 16
//     --width 96 --height 96 -o tests/golden/path-X.png   (and --view sponza; --integrator whitted)
// on all threads through the default 8-wide BVH, and looked at. Rendered here through the
// scalar BVH on one thread. The images are in fact the same bytes (the random numbers are a
// function of pixel, sample and bounce, and every accelerator returns the same hits); the stated
// tolerance, 40 dB PSNR, is for another platform's libm. A change to the integrator fails it:
// one more bounce, or a wrong MIS weight, moves these images by far more.
TEST(Render, PathAndWhittedReferenceImages) {
  if (!test::have_shared_scenes()) GTEST_SKIP() << "no ../shared/scenes";
  const std::string scalar = " --accel bvh --sched seq";
  for (const char* name : {"Original", "Mirror", "Sphere", "Water"}) {
    expect_golden(cornell(name), "--integrator path --spp 16" + scalar, std::string("path-") + name, 40.0);
  }
  const std::string sponza = "--view sponza --views " + test::scene_path("views.tsv");
  expect_golden("", sponza + " --integrator path --spp 16" + scalar, "path-Sponza", 40.0);
  expect_golden(cornell("Original"), "--integrator whitted" + scalar, "whitted-Original", 40.0);
  expect_golden("", sponza + " --integrator whitted" + scalar, "whitted-Sponza", 40.0);
}

TEST(Render, AovLayersHoldTheFirstHitsAlbedoAndNormal) {
  // --aov albedo,normal: beside the radiance, the mean over each pixel's samples of the first
  // hit's albedo and shading normal. Inside the Cornell box a pixel wholly on the left wall holds
  // its Kd and the normal facing +x; one on the back wall the floor's Kd and +z. The radiance is the render's without
  // the layers, to the byte.
  if (!test::have_shared_scenes()) GTEST_SKIP() << "no ../shared/scenes";
  const std::string dir = test::temp_dir();
  const std::string common = cornell("Original") + " --integrator path --spp 4 --width 32 --height 32 -q --exr float";
  ASSERT_EQ(test::run_tracer("render " + common + " --aov albedo,normal -o " + dir + "/a.exr").exit_code, 0);
  ASSERT_EQ(test::run_tracer("render " + common + " -o " + dir + "/b.exr").exit_code, 0);
  const Framebuffer albedo = read_exr(dir + "/a.exr", {"albedo", nullptr, {"R", "G", "B"}});
  const Framebuffer normal = read_exr(dir + "/a.exr", {"normal", nullptr, {"X", "Y", "Z"}});
  const Framebuffer with = read_exr(dir + "/a.exr"), without = read_exr(dir + "/b.exr");
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) ASSERT_EQ(with.radiance(x, y), without.radiance(x, y)) << x << "," << y;
  // Pixel (5, 16): the left wall; (16, 12): the back wall, between the boxes and the lamp.
  const Vec3 left = albedo.radiance(5, 16), back = albedo.radiance(16, 12);
  EXPECT_NEAR(left.x, 0.63f, 1e-6f);
  EXPECT_NEAR(left.y, 0.065f, 1e-6f);
  EXPECT_NEAR(back.x, 0.725f, 1e-6f);
  EXPECT_NEAR(normal.radiance(5, 16).x, 1.0f, 1e-3f);  // the walls of this file lean a little
  EXPECT_NEAR(normal.radiance(16, 12).z, 1.0f, 1e-3f);
  // Asked for where they cannot be written: one-line usage errors.
  const auto png = test::run_tracer("render " + common + " --aov albedo -o " + dir + "/c.png");
  EXPECT_EQ(png.exit_code, 2);
  EXPECT_NE(png.output.find("--aov: the layers need an .exr output (-o)"), std::string::npos) << png.output;
  const auto bad = test::run_tracer("render " + common + " --aov depth -o " + dir + "/c.exr");
  EXPECT_NE(bad.output.find("--aov: unknown layer 'depth' (expected albedo, normal, samples, noisy, variance)"),
            std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(Render, BumpMapOfConstantGradientShadesAsTheTiltedPlane) {
  // A 2 x 2 square in z = 0 with texture coordinates (x/2, y/2), its bump map a ramp: column i of
  // 256 holds the byte i, so height = u * 256/255 and the surface displaced by -bm 0.5 is the
  // plane z = 0.5 * 256/255 * x/2, whose normal is (-g, 0, 1) / |..| with g = 64/255. Seen from
  // above, the shading normal (--aov normal) is that normal wherever the central differences
  // stay inside the ramp (away from u = 0 and 1, where it wraps). Without the map: +z.
  const std::string dir = test::temp_dir();
  Image8 ramp;
  ramp.width = 256;
  ramp.height = 4;
  ramp.rgb.resize(size_t(256) * 4 * 3);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 256; ++x)
      for (int c = 0; c < 3; ++c) ramp.rgb[(size_t(y) * 256 + size_t(x)) * 3 + size_t(c)] = uint8_t(x);
  write_image(dir + "/ramp.png", ramp);
  std::ofstream(dir + "/plane.mtl") << "newmtl bumpy\nKd 0.5 0.5 0.5\nmap_bump -bm 0.5 ramp.png\n"
                                    << "newmtl flat\nKd 0.5 0.5 0.5\n";
  for (const char* mat : {"bumpy", "flat"}) {
    std::ofstream(dir + "/plane.obj") << "mtllib plane.mtl\nv 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\n"
                                      << "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl " << mat << "\nf 1/1 2/2 3/3 4/4\n";
    const auto r = test::run_tracer("render " + dir +
                                    "/plane.obj --eye 1,1,5 --look 1,1,0 --fov 20 --width 32 "
                                    "--height 32 --spp 1 --env 1,1,1 --aov normal --exr float -q -o " +
                                    dir + "/n.exr");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const Framebuffer n = read_exr(dir + "/n.exr", {"normal", nullptr, {"X", "Y", "Z"}});
    const float g = std::string(mat) == "bumpy" ? 64.0f / 255.0f : 0.0f;
    const float len = std::sqrt(1.0f + g * g);
    for (int y = 8; y < 24; ++y)
      for (int x = 8; x < 24; ++x) {
        const Vec3 v = n.radiance(x, y);
        EXPECT_NEAR(v.x, -g / len, 2e-3f) << mat << " " << x << "," << y;
        EXPECT_NEAR(v.y, 0.0f, 2e-3f) << mat << " " << x << "," << y;
        EXPECT_NEAR(v.z, 1.0f / len, 2e-3f) << mat << " " << x << "," << y;
      }
  }
  // No black fringes: bumps far steeper than the view (-bm 40, seen at 80 degrees from the
  // normal) under a white sky leave no pixel of the plane black, for path and whitted.
  std::ofstream(dir + "/plane.mtl") << "newmtl bumpy\nKd 0.5 0.5 0.5\nmap_bump -bm 40 ramp.png\n";
  std::ofstream(dir + "/plane.obj") << "mtllib plane.mtl\nv -50 -50 0\nv 50 -50 0\nv 50 50 0\nv -50 50 0\n"
                                    << "vt 0 0\nvt 9 0\nvt 9 9\nvt 0 9\nusemtl bumpy\nf 1/1 2/2 3/3 4/4\n";
  for (const char* integrator : {"path --env 1,1,1", "whitted --light 0,0,30"}) {
    const auto r = test::run_tracer("render " + dir +
                                    "/plane.obj --eye 0,-20,3.5 --look 0,0,0 --fov 30 --width 24 "
                                    "--height 24 --spp 4 --exr float -q -o " +
                                    dir + "/g.exr --integrator " + integrator);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const Framebuffer img = read_exr(dir + "/g.exr");
    for (int y = 14; y < 24; ++y)  // the lower part of the image: the plane
      for (int x = 0; x < 24; ++x) EXPECT_GT(luminance(img.radiance(x, y)), 0.0f) << integrator << " " << x << "," << y;
  }
  std::filesystem::remove_all(dir);
}

TEST(Exr, LinearRadianceRoundTripsAsFloatAndAsHalf) {
  // Values a render holds: zero, tiny, ordinary, above 1, large, in a 5x3 image (rows and
  // columns distinguishable). Float round-trips exactly; half within its 11-bit precision.
  Framebuffer fb(5, 3);
  const float values[] = {0.0f,    1e-4f, 0.18f, 0.5f,   1.0f,  3.75f, 17.0f, 1000.0f,
                          0.0312f, 2.5f,  7.0f,  0.001f, 64.0f, 0.9f,  42.0f};
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) {
      const float v = values[y * 5 + x];
      fb.set(x, y, Vec3{v, 2.0f * v, 0.5f * v});
    }
  const std::string dir = test::temp_dir();
  for (const ExrPixel pixel : {ExrPixel::Float, ExrPixel::Half}) {
    SCOPED_TRACE(std::string(name_of<ExrPixel>(kExrPixelNames, pixel)));
    write_render(dir + "/x.exr", fb, 1.5f, pixel);
    const Framebuffer back = read_exr(dir + "/x.exr");
    ASSERT_EQ(back.width(), 5);
    ASSERT_EQ(back.height(), 3);
    const float tolerance = pixel == ExrPixel::Float ? 0.0f : 1.0f / 2048.0f;  // half: 11 significant bits
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 5; ++x) {
        const Vec3 a = fb.radiance(x, y), b = back.radiance(x, y);
        for (int c = 0; c < 3; ++c)
          EXPECT_LE(std::fabs(a[c] - b[c]), tolerance * std::fabs(a[c]) + 1e-7f) << x << "," << y;
      }
  }
  std::filesystem::remove_all(dir);
}

TEST(Exr, TheCliWritesTheRadianceThePngToneMaps) {
  // A float EXR of a render, tone-mapped here, equals the PNG of the same render byte for byte.
  const std::string dir = test::temp_dir();
  auto r = test::run_tracer("render -q --width 40 --height 30 --ao 4 --exr float -o " + dir + "/r.exr");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = test::run_tracer("render -q --width 40 --height 30 --ao 4 -o " + dir + "/r.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(tonemap(read_exr(dir + "/r.exr"), 1.5f).rgb, read_image(dir + "/r.png").rgb);
  r = test::run_tracer("render -q --width 8 --height 8 --exr double -o " + dir + "/bad.exr");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--exr: unknown pixel type 'double' (half, float)"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/bad.exr"));
  std::filesystem::remove_all(dir);
}

using test::read_bytes;

TEST(AntiAliasing, EveryIntegratorTakesSamplesPerPixelDeterministically) {
  const std::string dir = test::temp_dir();
  for (const char* integrator : {"ao", "whitted"}) {
    SCOPED_TRACE(integrator);
    const std::string base = std::string("render -q --width 24 --height 20 --integrator ") + integrator;
    const auto a = test::run_tracer(base + " --spp 4 --threads 1 --sched seq -o " + dir + "/a.ppm");
    const auto b = test::run_tracer(base + " --spp 4 --threads 2 --sched tbb --tile 7 -o " + dir + "/b.ppm");
    const auto c = test::run_tracer(base + " --spp 4 --threads 2 --sched async -o " + dir + "/c.ppm");
    const auto one = test::run_tracer(base + " --spp 1 -o " + dir + "/one.ppm");
    const auto centre = test::run_tracer(base + " -o " + dir + "/centre.ppm");
    for (const auto* r : {&a, &b, &c, &one, &centre}) ASSERT_EQ(r->exit_code, 0) << r->output;
    EXPECT_EQ(read_bytes(dir + "/a.ppm"), read_bytes(dir + "/b.ppm"));
    EXPECT_EQ(read_bytes(dir + "/a.ppm"), read_bytes(dir + "/c.ppm"));
    EXPECT_EQ(read_bytes(dir + "/one.ppm"), read_bytes(dir + "/centre.ppm"));  // one sample: the pixel centre
    EXPECT_NE(read_bytes(dir + "/a.ppm"), read_bytes(dir + "/one.ppm"));       // four: edges are smoothed
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace tracer
