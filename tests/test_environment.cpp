// Reading environment maps (io/environment_io.hpp, io/rgbe_decode.hpp) and what the map makes of
// odd texels and angles: truncated files are errors, memory follows the file's pixels, values
// equal stb_image's on complete files, every angle turns the map, black maps are said.
#include <gtest/gtest.h>
#include <stb_image.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "base/errors.hpp"
#include "io/environment_io.hpp"
#include "io/exr_io.hpp"
#include "io/rgbe_decode.hpp"
#include "test_util.hpp"

namespace tracer {
namespace {

namespace fs = std::filesystem;

// A Radiance HDR file of w x h texels whose texel (x, y) is rgbe(x, y): run-length scanlines
// (one run per channel where the channel is constant along the row, literals elsewhere), or flat.
template <class Texel>
std::string hdr_file(int w, int h, bool rle, Texel&& rgbe) {
  std::string s = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " + std::to_string(h) + " +X " + std::to_string(w) + "\n";
  for (int y = 0; y < h; ++y) {
    if (!rle) {
      for (int x = 0; x < w; ++x) {
        const std::array<uint8_t, 4> c = rgbe(x, y);
        s.append(reinterpret_cast<const char*>(c.data()), 4);
      }
      continue;
    }
    s += {char(2), char(2), char(w >> 8), char(w & 255)};
    for (int c = 0; c < 4; ++c) {
      for (int x = 0; x < w;) {
        const int n = std::min(w - x, 100);
        s += char(n);  // literals
        for (int k = 0; k < n; ++k) s += char(rgbe(x + k, y)[size_t(c)]);
        x += n;
      }
    }
  }
  return s;
}

std::array<uint8_t, 4> pattern(int x, int y) {
  return {uint8_t(x * 7 + y), uint8_t(255 - x), uint8_t(y * 3), uint8_t(120 + (x + y) % 20)};
}

TEST(RgbeDecode, CompleteFilesDecodeAsStbImageDecodesThem) {
  for (const bool rle : {true, false}) {
    const std::string bytes = hdr_file(137, 9, rle, pattern);
    const RgbeImage mine = decode_rgbe(
        bytes, "t.hdr", [](const std::string&, long long, long long) {}, nullptr);
    int w = 0, h = 0, n = 0;
    const std::unique_ptr<float, void (*)(void*)> ref(
        stbi_loadf_from_memory(reinterpret_cast<const stbi_uc*>(bytes.data()), int(bytes.size()), &w, &h, &n, 3),
        stbi_image_free);
    ASSERT_TRUE(ref);
    ASSERT_EQ(mine.width, w);
    ASSERT_EQ(mine.height, h);
    ASSERT_EQ(mine.texels.size(), size_t(w) * size_t(h));
    for (size_t i = 0; i < mine.texels.size(); ++i) {
      for (int c = 0; c < 3; ++c) ASSERT_EQ(mine.texels[i][c], ref.get()[3 * i + size_t(c)]) << i << " " << rle;
    }
  }
}

TEST(RgbeDecode, TruncatedAndCorruptFilesAreErrors) {
  const std::string bytes = hdr_file(64, 8, true, pattern);
  const auto no_check = [](const std::string&, long long, long long) {};
  for (const size_t keep : {bytes.size() - 1, bytes.size() / 2, size_t(50)}) {
    try {
      decode_rgbe(bytes.substr(0, keep), "t.hdr", no_check, nullptr);
      ADD_FAILURE() << "no error for " << keep << " bytes";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("t.hdr: truncated"), std::string::npos) << e.what();
    }
  }
  std::string corrupt = bytes;
  corrupt[corrupt.find("+X 64\n") + 6 + 4] = char(200);  // a run of 72 in a row of 64
  EXPECT_THROW(decode_rgbe(corrupt, "t.hdr", no_check, nullptr), InputError);
  EXPECT_THROW(decode_rgbe("#?RADIANCE\n\n-Y 2 +X 2 junk\n", "t.hdr", no_check, nullptr), InputError);
  EXPECT_THROW(decode_rgbe("#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 2 +X 2\n", "t.hdr", no_check, nullptr),
               InputError);
}

class EnvironmentFiles : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::temp_dir(); }
  void TearDown() override { fs::remove_all(dir_); }
  std::string in(const std::string& name) const { return dir_ + "/" + name; }
  std::string dir_;
};

// A header claiming the largest map allowed, 10 texels behind it: refused as truncated while the
// process stays within 1 GB of address space (the claimed map alone would take 1.5 GB).
TEST_F(EnvironmentFiles, AHeaderClaimingAHugeMapCostsWhatTheFileHolds) {
  if (test::kUnderSanitizer) GTEST_SKIP() << "a sanitizer's shadow memory needs more address space than the bound";
  std::string bytes = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8192 +X 16384\n";
  bytes += std::string(40, char(1));
  std::ofstream(in("claim.hdr"), std::ios::binary) << bytes;
  const test::CommandResult r = test::run_shell("ulimit -v 1000000; " + std::string(TRACER_EXE) +
                                                " render -q --integrator path --spp 1 --width 8 --height 8 --env-map " +
                                                in("claim.hdr") + " -o " + in("o.png"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("claim.hdr: "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("truncated"), std::string::npos) << r.output;
}

TEST_F(EnvironmentFiles, AnExrWithoutItsPixelsIsTruncated) {
  Framebuffer fb(2048, 1024);
  for (int y = 0; y < fb.height(); ++y)
    for (int x = 0; x < fb.width(); ++x) fb.set(x, y, Vec3{float(x % 7), 1.0f, float(y % 5)});
  const std::string bytes = encode_exr(fb, ExrPixel::Float);
  std::ofstream(in("whole.exr"), std::ios::binary) << bytes;
  const EnvironmentMap whole = load_environment_map(in("whole.exr"), 0.0);
  EXPECT_EQ(whole.width(), 2048);
  for (const size_t keep : {size_t(400), bytes.size() / 2}) {
    std::ofstream(in("cut.exr"), std::ios::binary) << bytes.substr(0, keep);
    try {
      load_environment_map(in("cut.exr"), 0.0);
      ADD_FAILURE() << "no error for " << keep << " bytes";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("cut.exr: "), std::string::npos) << e.what();
    }
  }
}

// Any finite angle turns the map by its remainder of a full turn (--env-rotation 1e300 crashed).
TEST(EnvironmentMapAngles, EveryFiniteAngleTurnsTheMapByItsRemainder) {
  std::vector<Vec3> texels(16 * 8);
  for (size_t i = 0; i < texels.size(); ++i) texels[i] = Vec3{float(i % 16) + 1.0f};
  const EnvironmentMap base(16, 8, texels, 40.0), turned(16, 8, texels, 360.0 * 1e6 + 40.0);
  const EnvironmentMap huge(16, 8, texels, 1e300), negative(16, 8, texels, -3.5e38);
  for (float a = 0.0f; a < 6.28f; a += 0.1f) {
    const Vec3 d{std::cos(a), 0.3f, std::sin(a)};
    EXPECT_EQ(base.radiance(normalize(d)), turned.radiance(normalize(d)));
    EXPECT_TRUE(is_finite(huge.radiance(normalize(d))));
    EXPECT_TRUE(is_finite(negative.radiance(normalize(d))));
    EXPECT_GT(huge.pdf(normalize(d)), 0.0f);
  }
}

TEST_F(EnvironmentFiles, BlackNegativeAndHugeTexelsAreSaid) {
  std::ofstream(in("tri.obj")) << "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n";
  Framebuffer negative(8, 4), huge(8, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) negative.set(x, y, Vec3{-1.0f}), huge.set(x, y, Vec3{3e38f});
  std::ofstream(in("negative.exr"), std::ios::binary) << encode_exr(negative, ExrPixel::Float);
  std::ofstream(in("huge.exr"), std::ios::binary) << encode_exr(huge, ExrPixel::Float);
  const std::string render = "render " + in("tri.obj") + " --integrator path --spp 1 --width 8 --height 8 -o ";
  test::CommandResult r = test::run_tracer(render + in("n.png") + " --env-map " + in("negative.exr"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("negative.exr: 96 texel values negative or not finite, read as 0"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("negative.exr: the environment map is black: it lights nothing"), std::string::npos)
      << r.output;
  // Seen directly, the limit (1e6) overflows a half: the EXR holds the half's largest value and says so.
  r = test::run_tracer(render + in("h.exr") + " --env-map " + in("huge.exr") + " --eye 0,0,-3 --look 0,0,-4");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("huge.exr: 96 texel values above the radiance limit 1e6, read as 1e6"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("h.exr: 192 pixel values beyond the half EXR's range"), std::string::npos) << r.output;
  const Framebuffer out = read_exr(in("h.exr"));
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x) EXPECT_TRUE(is_finite(out.radiance(x, y)));
}

}  // namespace
}  // namespace tracer
