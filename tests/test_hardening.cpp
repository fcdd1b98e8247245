// Hostile inputs and outputs (docs/RELIABILITY.md): outputs that are device nodes, FIFOs,
// symbolic links or inputs; coordinates at the edge of the accepted range; inputs that never end;
// texture decompression bombs; black images.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include <zlib.h>
#include <nlohmann/json.hpp>

#include "base/errors.hpp"
#include "importers/obj_loader.hpp"
#include "parallel/executor.hpp"
#include "scene/texture.hpp"
#include "test_util.hpp"

namespace tracer {
namespace {

namespace fs = std::filesystem;

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

class Hardening : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::temp_dir();
    std::ofstream(dir_ + "/tri.obj") << "mtllib tri.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                                     << "usemtl a\nf 1/1 2/2 3/3\n";
    std::ofstream(dir_ + "/tri.mtl") << "newmtl a\nKd 0.5\nmap_Kd s-0001.png\n";
    const unsigned char texel[3] = {200, 100, 50};
    // A 1x1 PNG written by hand is long; an uncompressed PPM is a texture stb reads too.
    std::ofstream(dir_ + "/s-0001.png", std::ios::binary) << "P6\n1 1\n255\n"
                                                          << std::string(reinterpret_cast<const char*>(texel), 3);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string in(const std::string& name) const { return dir_ + "/" + name; }
  std::string dir_;
};

TEST_F(Hardening, ASymlinkOutputReplacesItsTargetAndStaysALink) {
  fs::create_symlink("target.png", in("link.png"));
  const auto r = test::run_tracer("render " + in("tri.obj") + " -q --width 8 --height 8 -o " + in("link.png"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::is_symlink(in("link.png")));
  EXPECT_TRUE(fs::is_regular_file(in("target.png")));
}

TEST_F(Hardening, AFifoOutputIsWrittenIntoNotReplaced) {
  ASSERT_EQ(::mkfifo(in("stats.json").c_str(), 0644), 0);
  std::string received;
  std::thread reader([&] { received = slurp(in("stats.json")); });
  const auto r = test::run_tracer("render " + in("tri.obj") + " -q --width 8 --height 8 -o " + in("o.png") +
                                  " --stats-json " + in("stats.json"));
  reader.join();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  struct stat st {};
  ASSERT_EQ(::stat(in("stats.json").c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  EXPECT_NE(received.find("\"rays\""), std::string::npos) << received;
}

TEST_F(Hardening, ADeviceNodeOutputIsWrittenIntoNotReplaced) {
  if (::geteuid() != 0) GTEST_SKIP() << "mknod of a character device needs root";
  // A copy of /dev/null and one of /dev/full in the test's own directory.
  ASSERT_EQ(::mknod(in("null").c_str(), S_IFCHR | 0666, makedev(1, 3)), 0);
  ASSERT_EQ(::mknod(in("full").c_str(), S_IFCHR | 0666, makedev(1, 7)), 0);
  const std::string render = "render " + in("tri.obj") + " -q --width 8 --height 8 -o " + in("o.png");
  auto r = test::run_tracer(render + " --stats-json " + in("null"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  r = test::run_tracer(render + " --stats-json " + in("full"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("No space left on device"), std::string::npos) << r.output;
  for (const char* name : {"null", "full"}) {
    struct stat st {};
    ASSERT_EQ(::stat(in(name).c_str(), &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode)) << name;
  }
}

TEST_F(Hardening, NoOutputMayBeAnInputByAnyName) {
  const std::string mtl = slurp(in("tri.mtl")), texture = slurp(in("s-0001.png"));
  fs::create_symlink("tri.mtl", in("alias.json"));
  const std::string render = "render " + in("tri.obj") + " -q --width 8 --height 8";
  const std::pair<std::string, std::string> cases[] = {
      {render + " --stats-json " + in("tri.mtl"), "--stats-json: '" + in("tri.mtl") + "' is an input of this run"},
      {render + " --stats-json " + in("alias.json"), "is an input of this run"},
      {render + " -o " + in("s-0001.png"), "-o: '" + in("s-0001.png") + "' is an input of this run"},
      // The second frame's name is the texture.
      {render + " --frames 2 -o " + in("s.png"), "-o: '" + in("s-0001.png") + "' is an input of this run"},
      {"bench --size 8x8 --runs 1 --best 1 --variants bvh --scenes " + in("tri.obj") + " --plot " + in("tri.obj"),
       "--plot: '" + in("tri.obj") + "' is an input of this run"},
      {"bench --size 8x8 --runs 1 --best 1 --variants bvh --scenes " + in("tri.obj") + " --json " + in("tri.mtl"),
       "--json: '" + in("tri.mtl") + "' is an input of this run"},
  };
  for (const auto& [args, message] : cases) {
    SCOPED_TRACE(args);
    const auto r = test::run_tracer(args);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << r.output;
  }
  EXPECT_EQ(slurp(in("tri.mtl")), mtl);
  EXPECT_EQ(slurp(in("s-0001.png")), texture);
  EXPECT_FALSE(fs::exists(in("s-0000.png")));  // nothing written, not even the first frame
}

// Every accelerator renders a triangle spanning the whole accepted range, the same image, and
// the next float past the range is refused.
TEST_F(Hardening, CoordinatesAtTheEdgeOfTheRangeRenderOnEveryAccelerator) {
  std::ofstream(in("edge.obj")) << "v -1e12 -1e12 0\nv 1e12 -1e12 0\nv 0 1e12 0\nf 1 2 3\n";
  std::ofstream(in("past.obj")) << "v -1.0001e12 -1e12 0\nv 1e12 -1e12 0\nv 0 1e12 0\nf 1 2 3\n";
  std::string reference;
  for (const char* accel : {"brute", "simd-brute", "bvh", "bvh8", "embree"}) {
    SCOPED_TRACE(accel);
    const std::string out = in(std::string(accel) + ".ppm");
    const auto r = test::run_tracer("render " + in("edge.obj") + " -q --integrator ao --ao 0 --width 16 --height 16" +
                                    " --accel " + accel + " -o " + out);
    if (std::string(accel) == "embree" && r.exit_code == 2) continue;  // a build without Embree
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const std::string image = slurp(out);
    EXPECT_NE(image.find_first_not_of('\0', image.size() - 16 * 16 * 3), std::string::npos) << "all black";
    if (reference.empty()) reference = image;
    EXPECT_EQ(image, reference);
  }
  const auto r = test::run_tracer("render " + in("past.obj") + " -q -o " + in("p.png"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("past.obj:1: number out of range '-1.0001e12' (coordinates must lie within +-1e12)"),
            std::string::npos)
      << r.output;
}

TEST_F(Hardening, ANarrowFovThatBacksTheCameraOutOfRangeIsRefused) {
  std::ofstream(in("wide.obj")) << "v -1e10 -1e10 0\nv 1e10 -1e10 0\nv 0 1e10 0\nf 1 2 3\n";
  auto r = test::run_tracer("render " + in("wide.obj") + " -q --fov 0.01 -o " + in("w.png"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--fov: 0.010000 degrees frames this scene from too far away"), std::string::npos)
      << r.output;
  for (const char* accel : {"bvh8", "embree"}) {
    r = test::run_tracer("render -q --fov 1e-30 --accel " + std::string(accel) + " -o " + in("w.png"));
    EXPECT_EQ(r.exit_code, 2) << r.output;
  }
}

TEST_F(Hardening, InputsThatNeverEndStopAtTheirLimit) {
  fs::create_symlink("/dev/zero", in("zero.mtl"));
  std::ofstream(in("zero.obj")) << "mtllib zero.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  auto r = test::run_tracer("render " + in("zero.obj") + " -q -o " + in("z.png"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("zero.mtl: larger than 64 MiB, the limit for this input"), std::string::npos) << r.output;
  {
    std::ofstream big(in("big.obj"));
    for (int i = 0; i < 70000; ++i) big << "v 0.000000 0.000000 0.000000\n";
    big << "f 1 2 3\n";
  }
  r = test::run_tracer("render " + in("big.obj") + " -q --max-input-mib 1 -o " + in("z.png"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("big.obj: larger than 1 MiB"), std::string::npos) << r.output;
  r = test::run_tracer("render " + in("big.obj") + " -q --max-input-mib 0 -o " + in("z.png"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_FALSE(fs::exists(in("z.png")));
}

// The header of a PNG that claims 16384 x 16384 texels, and no image data: the size is refused
// from the header, before anything is decoded.
std::string png_header(uint32_t width, uint32_t height) {
  std::string png = "\x89PNG\r\n\x1a\n";
  const auto be32 = [&](uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) png += char((v >> s) & 0xff);
  };
  be32(13);
  const size_t crc_from = png.size();
  png += "IHDR";
  be32(width);
  be32(height);
  png += std::string("\x08\x02\x00\x00\x00", 5);
  uint32_t crc = 0xffffffffu;  // CRC-32 of type and data, as PNG requires
  for (size_t i = crc_from; i < png.size(); ++i) {
    crc ^= uint8_t(png[i]);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  be32(~crc);
  return png;
}

TEST_F(Hardening, TextureBombsAreRefusedFromTheirHeader) {
  std::ofstream(in("bomb.png"), std::ios::binary) << png_header(16384, 16384);
  try {
    load_texture(in("bomb.png"));
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("16384x16384 texels, more than the 67108864 a texture may have"),
              std::string::npos)
        << e.what();
  }
  std::ofstream(in("bomb.mtl")) << "newmtl a\nmap_Kd bomb.png\n";
  std::ofstream(in("bomb.obj")) << "mtllib bomb.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nusemtl a\nf 1 2 3\n";
  std::vector<std::string> warnings;
  const Scene s = load_obj(in("bomb.obj"), [&](const std::string& w) { warnings.push_back(w); });
  EXPECT_TRUE(s.textures.empty());
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("more than the 67108864 a texture may have"), std::string::npos) << warnings[0];
  // And the total: two real textures with a cap below their sum.
  LoadLimits limits;
  limits.textures.max_total_bytes = 20;  // a 1x1 texture keeps 4 bytes and takes at most 18 to decode
  std::ofstream(in("two.mtl")) << "newmtl a\nmap_Kd s-0001.png\nnewmtl b\nmap_Kd t.ppm\n";
  std::ofstream(in("t.ppm"), std::ios::binary) << "P6\n1 1\n255\n" << std::string(3, '\x7f');
  std::ofstream(in("two.obj")) << "mtllib two.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nusemtl a\nf 1 2 3\n"
                               << "usemtl b\nf 1 2 3\n";
  warnings.clear();
  const Scene two = load_obj(
      in("two.obj"), [&](const std::string& w) { warnings.push_back(w); }, nullptr, limits);
  EXPECT_EQ(two.textures.size(), 1u);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("the scene's textures would take more than"), std::string::npos) << warnings[0];
}

// A 16-bit RGB PNG of w x h black texels (zlib-compressed rows: a 4096^2 one is ~100 KB).
std::string png16(int w, int h) {
  const auto chunk = [](const std::string& type, const std::string& data) {
    std::string c;
    for (int s = 24; s >= 0; s -= 8) c += char((data.size() >> s) & 255);
    c += type + data;
    const uLong crc = crc32(crc32(0, nullptr, 0), reinterpret_cast<const Bytef*>(c.data() + 4), uInt(c.size() - 4));
    for (int s = 24; s >= 0; s -= 8) c += char((crc >> s) & 255);
    return c;
  };
  std::string ihdr;
  for (int v : {w, h})
    for (int s = 24; s >= 0; s -= 8) ihdr += char((v >> s) & 255);
  ihdr += std::string("\x10\x02\x00\x00\x00", 5);  // 16 bits, RGB
  z_stream z{};
  deflateInit(&z, 9);
  const std::string row(size_t(w) * 6 + 1, '\0');
  std::string idat;
  std::vector<unsigned char> out(1 << 16);
  for (int y = 0; y < h; ++y) {
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(row.data()));
    z.avail_in = uInt(row.size());
    do {
      z.next_out = out.data();
      z.avail_out = uInt(out.size());
      deflate(&z, y + 1 == h ? Z_FINISH : Z_NO_FLUSH);
      idat.append(reinterpret_cast<char*>(out.data()), out.size() - z.avail_out);
    } while (z.avail_out == 0);
  }
  deflateEnd(&z);
  return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) + chunk("IDAT", idat) + chunk("IEND", "");
}

// Twelve 16-bit 4096^2 textures (stb_image decodes each through ~400 MB of buffers) under a
// 512 MiB budget: the process's peak stays within the budget and a stated 160 MiB for the rest.
TEST_F(Hardening, TheTextureBudgetBoundsPeakMemory) {
  if (test::kUnderSanitizer) GTEST_SKIP() << "peak memory under a sanitizer is the sanitizer's";
  const std::string png = png16(4096, 4096);
  std::ofstream obj(in("many.obj")), mtl(in("many.mtl"));
  obj << "mtllib many.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n";
  for (int i = 0; i < 12; ++i) {
    std::ofstream(in("t" + std::to_string(i) + ".png"), std::ios::binary) << png;
    mtl << "newmtl m" << i << "\nmap_Kd t" << i << ".png\n";
    obj << "usemtl m" << i << "\nf 1/1 2/2 3/3\n";
  }
  obj.close();
  mtl.close();
  const test::CommandResult r = test::run_tracer("render " + in("many.obj") +
                                                 " --max-texture-mib 512 --threads 2 --integrator ao --width 8 "
                                                 "--height 8 -o " +
                                                 in("m.png") + " --stats-json " + in("s.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("10 map_Kd texture(s) not used"), std::string::npos) << r.output;
  const nlohmann::json stats = nlohmann::json::parse(slurp(in("s.json")));
  EXPECT_LT(stats["peak_rss_mib"].get<double>(), 512.0 + 160.0) << stats.dump();
}

TEST_F(Hardening, ATextureOfOnlyItsHeaderSaysWhy) {
  std::ofstream(in("ihdr.png"), std::ios::binary) << png_header(8, 8);
  try {
    load_texture(in("ihdr.png"));
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("ihdr.png: cannot read texture: corrupt or truncated"), std::string::npos)
        << e.what();
  }
}

TEST_F(Hardening, TexturesThatAreNoRegularFileSayWhy) {
  ASSERT_EQ(::mkfifo(in("fifo.png").c_str(), 0644), 0);
  fs::create_symlink("loop-b.png", in("loop-a.png"));
  fs::create_symlink("loop-a.png", in("loop-b.png"));
  const auto expect_error = [](const std::string& path, const std::string& text) {
    try {
      load_texture(path);
      ADD_FAILURE() << path << ": no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
  };
  expect_error(in("fifo.png"), "not a regular file (a FIFO)");
  expect_error(in("loop-a.png"), "symbolic links");
  // Found (not "not found") by the finder, which lists each directory once.
  FileFinder finder;
  EXPECT_EQ(finder.find(dir_, "FIFO.PNG"), fs::path(in("fifo.png")));
  EXPECT_EQ(finder.find(dir_, "loop-a.png"), fs::path(in("loop-a.png")));
  EXPECT_FALSE(finder.find(dir_, "none.png"));
}

TEST_F(Hardening, ABlackImageIsNeverSilent) {
  // The only emitter faces away from the camera, far outside the view.
  std::ofstream(in("dark.obj")) << "mtllib dark.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nv 100 100 100\n"
                                << "v 101 100 100\nv 100 101 100\nf 1 2 3\nusemtl lamp\nf 4 6 5\n";
  std::ofstream(in("dark.mtl")) << "newmtl lamp\nKe 10 10 10\n";
  for (const char* integrator : {"path --spp 2", "ao --ambient 0", "whitted --ambient 0"}) {
    SCOPED_TRACE(integrator);
    const auto r = test::run_tracer("render " + in("dark.obj") + " -q --width 8 --height 8 --integrator " + integrator +
                                    " --eye 0,0,3 --look 0,0,0 -o " + in("d.png"));
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("the image is black: "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("--env 1,1,1"), std::string::npos) << r.output;
  }
  const auto lit = test::run_tracer("render " + in("tri.obj") + " -q --width 8 --height 8 -o " + in("d.png"));
  EXPECT_EQ(lit.output.find("the image is black"), std::string::npos) << lit.output;
}

// --spp anti-aliases ao and whitted too, the same image whatever the threads, scheduler and tiles.
TEST_F(Hardening, ABrokenViewsFileBesideTheSceneIsAWarning) {
  std::ofstream(in("views.tsv")) << "scene\tobj\teye\tlook\tup\tfov\tlight\n"
                                 << "tri\ttri.obj\t0,0,3\t0,0\n";
  const auto r = test::run_tracer("render " + in("tri.obj") + " --width 8 --height 8 -o " + in("v.png"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("tracer: warning: " + in("views.tsv") + ":2: expected 7 or 8 tab-separated fields"),
            std::string::npos)
      << r.output;
}

TEST_F(Hardening, FrameNamesSortInFrameOrderPastTenThousand) {
  const auto r = test::run_tracer("render " + in("tri.obj") + " -q --width 2 --height 2 --frames 10001 -o " +
                                  in("f.ppm") + " --integrator ao --ao 0");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(in("f-00000.ppm")));
  EXPECT_TRUE(fs::exists(in("f-09999.ppm")));
  EXPECT_TRUE(fs::exists(in("f-10000.ppm")));
  EXPECT_LT(std::string("f-09999.ppm"), std::string("f-10000.ppm"));
}

// Textures read and decoded on several threads give the scene one thread gives, and the total
// budget leaves out the same textures.
}  // namespace
}  // namespace tracer
