// The command line: every bad input's one-line error and exit code (1 input, 2 usage), and no
// image left behind by a failed run.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "io/image_io.hpp"
#include "test_util.hpp"

namespace tracer {
namespace {

namespace fs = std::filesystem;

struct CliCase {
  const char* args;
  int exit_code;
  const char* message;
};

int count_lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::temp_dir();
    std::ofstream(dir_ + "/nan.obj") << "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n";
    std::ofstream(dir_ + "/range.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n";
    std::ofstream(dir_ + "/empty.obj") << "# nothing\n";
    std::ofstream(dir_ + "/ok.obj") << "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n";
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string dir_;
};

TEST_F(Cli, BadInputsGiveOneLineErrorsAndExitCodes) {
  const std::string out = " -q -o " + dir_ + "/out.png";
  const std::vector<CliCase> cases = {
      {"render /nonexistent.obj", 1, "/nonexistent.obj: cannot open: no such file"},
      {"render NAN", 1, "nan.obj:2: non-finite coordinate 'nan'"},
      {"render RANGE", 1, "range.obj:4: vertex index 7 out of range"},
      {"render EMPTY", 1, "empty.obj: scene has no triangles"},
      {"info NAN", 1, "nan.obj:2: non-finite coordinate"},
      {"render --eye 1,2", 2, "--eye: expected three finite numbers x,y,z, got '1,2'"},
      {"render --look 1,2,x", 2, "--look: expected three finite numbers"},
      {"render --light 1,,3", 2, "--light: expected three finite numbers"},
      {"render --width 0", 2, "--width: must be between 1 and 16384, got 0"},
      {"render --height 16385", 2, "--height: must be between 1 and 16384, got 16385"},
      {"render --width abc", 2, "--width"},
      {"render --threads 0", 2, "--threads: must be between 1 and 1024, got 0"},
      {"render --threads -3", 2, "--threads"},
      {"render --threads 100000", 2, "--threads: must be between 1 and 1024"},
      {"render --tile 0", 2, "--tile: must be between 1 and 4096, got 0"},
      {"render --ao -1", 2, "--ao: must be between 0 and 4096, got -1"},
      {"render --fov 0", 2, "--fov: must be above 0"},
      {"render --accel kdtree", 2, "--accel: unknown accelerator 'kdtree'"},
      {"render --sched openmp", 2, "--sched: unknown scheduler 'openmp'"},
      {"render --bvh-split middle", 2, "--bvh-split: unknown split 'middle'"},
      {"render --build magic", 2, "--build: unknown builder 'magic'"},
      {"render --no-such-flag", 2, "--no-such-flag"},
      {"frobnicate", 2, "unknown command 'frobnicate'"},
      {"render --width 20000", 2, "--width: must be between 1 and 16384, got 20000"},
      {"render --simd maybe", 2, "--simd: expected auto or off, got 'maybe'"},
      {"render --accel bvh8 --simd off", 2, "--simd off: bvh8 is the SIMD tree"},
      {"render --simd-target neon", 2, "--simd-target: unknown target 'neon'"},
      {"render --accel brute --packets", 2, "--packets: needs --accel bvh or bvh8"},
      {"render --accel embree --packets", 2, "--packets: needs --accel bvh or bvh8"},
      {"render --up 0,0,0", 2, "--up: must not be the zero vector"},
      {"render --traversal-cost 0", 2, "--traversal-cost: must be above 0"},
      {"render --traversal-cost nan", 2, "--traversal-cost"},
  };
  for (const CliCase& c : cases) {
    std::string args = c.args;
    for (const auto& [key, file] : {std::pair{"NAN", "nan.obj"}, {"RANGE", "range.obj"}, {"EMPTY", "empty.obj"}}) {
      if (const size_t p = args.find(key); p != std::string::npos) args.replace(p, std::string(key).size(), dir_ + "/" + file);
    }
    if (args.rfind("render", 0) == 0) args += out;
    SCOPED_TRACE(args);
    const test::CommandResult r = test::run_tracer(args);
    EXPECT_EQ(r.exit_code, c.exit_code) << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << r.output;
    EXPECT_EQ(count_lines(r.output), 1) << r.output;
    EXPECT_EQ(r.output.rfind("tracer: error: ", 0), 0u) << r.output;
    EXPECT_FALSE(fs::exists(dir_ + "/out.png"));
  }
  // No temporary files were left behind either.
  for (const auto& entry : fs::directory_iterator(dir_)) EXPECT_EQ(entry.path().extension(), ".obj") << entry.path();
}

TEST_F(Cli, OutputErrors) {
  const std::string scene = dir_ + "/ok.obj";
  auto r = test::run_tracer("render " + scene + " -q --width 8 --height 8 -o /nonexistent-dir/out.png");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("/nonexistent-dir/out.png: cannot write"), std::string::npos) << r.output;
  r = test::run_tracer("render " + scene + " -q --width 8 --height 8 -o " + dir_ + "/out.jpg");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("-o: unsupported image extension '.jpg'"), std::string::npos) << r.output;
  r = test::run_tracer("render " + scene + " -q --width 8 --height 8 -o " + dir_);
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

TEST_F(Cli, RendersPngPpmAndStats) {
  const std::string scene = dir_ + "/ok.obj";
  auto r = test::run_tracer("render " + scene + " -q --width 16 --height 12 --ao 2 --stats --stats-json " + dir_ + "/s.json -o " + dir_ + "/a.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("Mrays/s"), std::string::npos);
  const Image8 png = read_image(dir_ + "/a.png");
  EXPECT_EQ(png.width, 16);
  EXPECT_EQ(png.height, 12);
  std::ifstream json(dir_ + "/s.json");
  const std::string text((std::istreambuf_iterator<char>(json)), {});
  EXPECT_NE(text.find("\"primary\": 192"), std::string::npos) << text;
  EXPECT_NE(text.find("\"mrays_per_s\""), std::string::npos);
  r = test::run_tracer("render " + scene + " -q --width 16 --height 12 --ao 2 -o " + dir_ + "/a.ppm");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Image8 ppm = read_image(dir_ + "/a.ppm");
  EXPECT_EQ(ppm.rgb, png.rgb);  // same render, two containers
  // The 8-wide BVH with primary-ray packets: the same image, every primary ray counted once.
  r = test::run_tracer("render " + scene + " -q --width 16 --height 12 --ao 2 --accel bvh8 --packets --stats-json " + dir_ + "/p.json -o " + dir_ + "/p.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read_image(dir_ + "/p.png").rgb, png.rgb);
  std::ifstream pjson(dir_ + "/p.json");
  const std::string ptext((std::istreambuf_iterator<char>(pjson)), {});
  EXPECT_NE(ptext.find("\"packets\": true"), std::string::npos) << ptext;
  EXPECT_NE(ptext.find("\"primary\": 192"), std::string::npos) << ptext;
  // The binary BVH with AO bundles: the same image.
  r = test::run_tracer("render " + scene + " -q --width 16 --height 12 --ao 2 --packets -o " + dir_ + "/b.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read_image(dir_ + "/b.png").rgb, png.rgb);
  r = test::run_tracer("info " + scene);
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.output.find("triangles   1"), std::string::npos) << r.output;
  r = test::run_tracer("--help");
  EXPECT_EQ(r.exit_code, 0);
}

TEST_F(Cli, SigintStopsWithoutImageOrWithPartialImage) {
  // A brute-force render of a few thousand triangles at 2048x2048 runs for minutes; SIGINT after
  // a second must end it within a fraction of a second with exit code 130. --foreground: without
  // it `timeout` signals the child and then its whole process group, so the tracer gets SIGINT
  // twice, and a second Ctrl-C kills at once by design (SA_RESETHAND), which made this test flaky.
  const std::string scene = dir_ + "/many.obj";
  {
    std::ofstream f(scene);
    for (int i = 0; i < 2000; ++i) f << "v " << i % 50 << " " << i / 50 << " 0\n";
    for (int i = 1; i + 51 <= 2000; ++i) f << "f " << i << " " << i + 1 << " " << i + 50 << "\n";
  }
  const std::string exe = TRACER_EXE;
  for (const bool partial : {false, true}) {
    const std::string out = dir_ + (partial ? "/partial.png" : "/none.png");
    const std::string cmd = "timeout --foreground --preserve-status -s INT 1 " + exe + " render " + scene + " -q --accel brute --width 2048 --height 2048 -o " + out +
                            (partial ? " --save-partial" : "") + " 2>&1";
    const auto t0 = std::chrono::steady_clock::now();
    const int status = std::system(cmd.c_str());
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 130);
    EXPECT_LT(seconds, 30.0);  // a generous bound: without the handler this render takes minutes
    EXPECT_EQ(fs::exists(out), partial);
    if (partial) {
      const Image8 img = read_image(out);
      EXPECT_EQ(img.width, 2048);
    }
  }
  for (const auto& entry : fs::directory_iterator(dir_)) EXPECT_EQ(entry.path().string().find(".tmp-"), std::string::npos);
}

}  // namespace
}  // namespace tracer
