// The command line: every bad input's one-line error and exit code (1 input, 2 usage), and no
// image left behind by a failed run.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <gtest/gtest.h>
#include <half.h>

#include <sys/stat.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <thread>

#include <nlohmann/json.hpp>

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

std::string slurp_text(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

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
    std::ofstream(dir_ + "/same.obj") << "v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n";
    std::ofstream(dir_ + "/tiny.obj") << "v 0 0 0\nv 1e-30 0 0\nv 0 1e-30 0\nf 1 2 3\n";
    std::ofstream(dir_ + "/bad.exr") << "v/1\x01 not an EXR";
    std::ofstream(dir_ + "/bad.hdr") << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4000000 +X 4000000\n";
    // Not called views.tsv: that name beside ok.obj would give plain renders of ok.obj its view.
    std::ofstream(dir_ + "/tri-views.tsv") << "scene\tobj\teye\tlook\tup\tfov\tlight\tnote\n"
                                           << "tri\tok.obj\t0,0,3\t0,0,0\t0,1,0\t45\t0,0,2\tthe triangle\n";
    std::ofstream(dir_ + "/badviews.tsv") << "scene\tobj\teye\tlook\tup\tfov\tlight\n"
                                          << "tri\tok.obj\t0,0,3\t0,0\t0,1,0\t45\t0,0,2\n";
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
      {"render --eye 1,2", 2, "--eye: expected three numbers x,y,z, got '1,2'"},
      {"render --look 1,2,x", 2, "--look: expected three numbers"},
      {"render --light 1,,3", 2, "--light: expected three numbers"},
      {"render --width 0", 2, "--width: must be between 1 and 16384, got 0"},
      {"render --height 16385", 2, "--height: must be between 1 and 16384, got 16385"},
      // Memory estimated before it is taken: the film from the flags alone, then scene and build.
      {"render --width 4096 --height 4096 --max-memory-mib 100", 2,
       "the image's film (with adaptive sampling's, --noise-threshold): about 608 MiB needed, more than the memory "
       "limit of 100 MiB (--max-memory-mib"},
      {"render --builtin-spheres 200000 --max-memory-mib 48 --width 8 --height 8", 1,
       "builtin:cornell: its 399648 triangles (24 MiB), their accelerator (about 36 MiB) and the image together: about "
       "60 MiB needed, more than the memory limit of 48 MiB"},
      {"render --max-memory-mib 0", 2, "--max-memory-mib"},
      {"render --width abc", 2, "--width"},
      {"render --threads 0", 2, "--threads: must be between 1 and 1024, got 0"},
      {"render --threads -3", 2, "--threads"},
      {"render --threads 100000", 2, "--threads: must be between 1 and 1024"},
      {"render --tile 0", 2, "--tile: must be between 1 and 4096, got 0"},
      {"render --ao -1", 2, "--ao: must be between 0 and 4096, got -1"},
      {"render --fov 0", 2, "--fov: must be at least 0.001"},
      {"render --fov 1e-30", 2, "--fov: must be at least 0.001"},
      {"render --accel kdtree", 2, "--accel: unknown accelerator 'kdtree'"},
      {"render --aperture -0.5", 2, "--aperture: must be at least 0"},
      {"render --focus-distance 0", 2, "--focus-distance: must be above 0"},
      {"render --aperture 0.1 --focus-distance 1e-30", 2,
       "--focus-distance 1e-30: below a millionth of the scene's size (its diagonal, "},
      {"render --build-quality HIGH", 2, "--build-quality: unknown quality 'HIGH' (medium, high)"},
      {"render --integrator PATH", 2, "--integrator: unknown integrator 'PATH'"},
      {"bench --build-quality best", 2, "--build-quality: unknown quality 'best'"},
      {"render --count --accel bvh", 2, "--count: only the 8-wide BVH counts its traversal"},
      {"render --sched openmp", 2, "--sched: unknown strategy 'openmp'"},
      {"render --bvh-split middle", 2, "--bvh-split: unknown split 'middle'"},
      {"render --build-sched magic", 2, "--build-sched: unknown strategy 'magic'"},
      {"render --build-sched atomic", 2, "--build-sched: atomic hands out tiles"},
      {"render --build-quality low", 2, "--build-quality: unknown quality 'low'"},
      {"render --accel bvh --build-quality high", 2, "--build-quality: only bvh8 and embree build at a quality level"},
      {"render --accel brute --build-quality medium", 2, "--build-quality: only bvh8 and embree"},
      {"render --no-such-flag", 2, "--no-such-flag"},
      {"frobnicate", 2, "unknown command 'frobnicate'"},
      {"render --width 20000", 2, "--width: must be between 1 and 16384, got 20000"},
      {"render --simd maybe", 2, "--simd: unknown SIMD use 'maybe' (auto, off)"},
      {"render --accel bvh8 --simd off", 2, "--simd off: bvh8 is the SIMD tree"},
      {"render --simd-target neon", 2, "--simd-target: unknown target 'neon'"},
      {"render --accel brute --packets", 2, "--packets: needs --accel bvh, bvh8 or embree"},
      {"render --integrator ao --accel bvh --streams", 2, "--streams: needs --accel bvh8 or embree"},
      {"render --integrator ao --no-packets --streams", 2, "--streams: traces rays together, which --no-packets"},
      {"render --integrator path --streams", 2, "--streams: only for --integrator ao"},
      {"render --accel simd-brute --simd off", 2, "--simd off: simd-brute is the SIMD brute force"},
      {"render --up 0,0,0", 2, "--up: must not be the zero vector"},
      {"render --traversal-cost 0", 2, "--traversal-cost: must be above 0"},
      {"render --traversal-cost nan", 2, "--traversal-cost"},
      {"render --eye 0,1,1e19 --look 0,1,0", 2, "--eye: coordinates must lie within +-1e12, got '0,1,1e+19'"},
      {"render --light 1e30,0,0", 2, "--light: coordinates must lie within +-1e12"},
      {"render --light 1e12,0,4e38", 2, "--light: '4e38' is out of range (not a finite float)"},
      {"render SAME", 1, "same.obj: all vertices coincide"},
      {"render TINY", 1, "tiny.obj: the scene is too small to frame (its extent, 1e-30"},
      {"render --max-input-mib 99999999999999999999", 2,
       "--max-input-mib: must be between 1 and 1048576, got 99999999999999999999"},
      {"render --max-texture-mib 0", 2, "--max-texture-mib: must be between 1 and 1048576, got 0"},
      {"render --stats-json ''", 2, "--stats-json: an empty file name"},
      {"render --env-map ''", 2, "--env-map: an empty file name"},
      {"render --integrator foo", 2, "--integrator: unknown integrator 'foo'"},
      {"render --integrator path --spp 0", 2, "--spp: must be between 1 and 1048576, got 0"},
      {"render --integrator ao --env 1,1,1", 2, "--env: only for --integrator path or whitted"},
      {"render --integrator ao --env-map x.exr", 2, "--env-map: only for --integrator path or whitted"},
      {"render --integrator path --env-map /nonexistent/sky.exr", 1, "/nonexistent/sky.exr: cannot open"},
      {"render --integrator path --env-map BADEXR", 1, "bad.exr: cannot read EXR"},
      {"render --integrator whitted --env-map BADHDR", 1,
       "bad.hdr: environment map of 4000000 x 4000000 texels is larger"},
      {"render --integrator path --env-map sky.txt", 1, "sky.txt: an environment map must be .exr or .hdr"},
      {"render --integrator path --env-map x.exr --env-rotation nan", 2, "--env-rotation: must be at least -1e+06"},
      {"render --integrator path --env-map x.exr --env-rotation 1e300", 2,
       "--env-rotation: must be at least -1e+06 and at most 1e+06, got 1e+300"},
      {"render --integrator path --env 1,-1,1", 2,
       "--env: each component must be in [0, 1e6] (the radiance limit of every format), got '1,-1,1'"},
      {"render --integrator path --env 1,1", 2, "--env: expected three numbers"},
      {"render --integrator path --light-sampling nee", 2, "--light-sampling: unknown light sampling 'nee'"},
      {"render --integrator path --checkpoint 0", 2, "--checkpoint: must be above 0"},
      {"render --frames 0", 2, "--frames: must be between 1 and 1000000, got 0"},
      {"render RANGE --stats-json RANGE", 2, "range.obj' is the input scene"},
      {"bench --variants ''", 2, "--variants: empty name in ''"},
      {"bench --scenes ,", 2, "--scenes: empty name in ','"},
      {"bench --size 32x32x99junk", 2, "--size: expected WxH (two whole numbers), got '32x32x99junk'"},
      {"bench --size 99999999999x2", 2, "--size width: must be between 1 and 16384, got 99999999999"},
      {"bench --threads 0", 2, "--threads: must be between 1 and 1024, got 0"},
      {"render --view nope --views VIEWS", 2, "--view: no view called 'nope' in "},
      {"render ''", 2, "--scene: an empty file name"},
      {"render -m ''", 2, "--scene: an empty file name"},
      {"render --view tri --views BADVIEWS", 1,
       "badviews.tsv:2: look: expected x,y,z (three finite numbers), got '0,0'"},
      {"render RANGE --view tri --views VIEWS", 2, "--view: view 'tri' is of "},
      {"bench --scenes nope --views VIEWS", 2, "--scenes: no view called 'nope'"},
  };
  for (const CliCase& c : cases) {
    std::string args = c.args;
    for (const auto& [key, file] : {std::pair{"NAN", "nan.obj"},
                                    {"RANGE", "range.obj"},
                                    {"EMPTY", "empty.obj"},
                                    {"SAME", "same.obj"},
                                    {"TINY", "tiny.obj"},
                                    {"BADEXR", "bad.exr"},
                                    {"BADHDR", "bad.hdr"},
                                    {"BADVIEWS", "badviews.tsv"},
                                    {"VIEWS", "tri-views.tsv"}}) {
      for (size_t p = args.find(key); p != std::string::npos; p = args.find(key))
        args.replace(p, std::string(key).size(), dir_ + "/" + file);
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
  // The film and its layers, from the flags alone, before the scene is read.
  const test::CommandResult big =
      test::run_tracer("render --width 16384 --height 16384 --aov albedo,normal,samples --max-memory-mib 16384 -q -o " +
                       dir_ + "/big.exr");
  EXPECT_EQ(big.exit_code, 2) << big.output;
  EXPECT_EQ(big.output.rfind("tracer: error: --width 16384 --height 16384 --aov albedo,normal,samples: the image's "
                             "film and layers (with adaptive sampling's, --noise-threshold): about 27.50 GiB needed, "
                             "more than the memory limit of 16.00 GiB",
                             0),
            0u)
      << big.output;
  EXPECT_FALSE(fs::exists(dir_ + "/big.exr"));
  // No temporary files were left behind either.
  for (const auto& entry : fs::directory_iterator(dir_)) {
    const fs::path ext = entry.path().extension();
    EXPECT_TRUE(ext == ".obj" || ext == ".tsv" || ext == ".exr" || ext == ".hdr") << entry.path();
  }
}

// --stats-json - writes the statistics to standard output.
TEST_F(Cli, StatsJsonDashIsStandardOutput) {
  const std::string cmd =
      std::string(TRACER_EXE) + " render -q --width 8 --height 8 -o " + dir_ + "/o.png --stats-json - 2>/dev/null";
  const test::CommandResult r = test::run_shell(cmd);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(nlohmann::json::parse(r.output)["width"], 8);
  EXPECT_FALSE(fs::exists(dir_ + "/-"));
  EXPECT_FALSE(fs::exists("-"));
}

// A scene with no light of its own is path-traced under a white sky that the statistics name as
// tracer's, not the file's; --env 0,0,0 keeps it black; the built-in box's lamp is its own.
TEST_F(Cli, TheDefaultSkyIsNamedInTheStatistics) {
  const auto lighting = [&](const std::string& flags) {
    // In braces: run_shell's 2>&1 applies to the group, and the note stays out of the JSON.
    const test::CommandResult r =
        test::run_shell("{ " + std::string(TRACER_EXE) + " render -q --width 8 --height 8 --spp 2 -o " + dir_ +
                        "/o.png --stats-json - " + flags + " 2>/dev/null; }");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return nlohmann::json::parse(r.output)["lighting"].get<std::string>();
  };
  EXPECT_EQ(lighting(dir_ + "/ok.obj"),
            "a uniform sky (1, 1, 1) added by tracer: the scene has no emissive surface (--env 0,0,0 for none)");
  EXPECT_EQ(lighting(dir_ + "/ok.obj --env 0,0,0"), "none");
  EXPECT_EQ(lighting(""), "2 emissive triangles");
}

// Two outputs of one bench that are one file, and an output that is an MTL file of a scene: both
// refused before any cell runs (no table printed).
TEST_F(Cli, BenchOutputsAreRefusedBeforeTheBenchmarkRuns) {
  std::ofstream(dir_ + "/m.obj") << "mtllib m.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nusemtl a\nf 1 2 3\n";
  std::ofstream(dir_ + "/m.mtl") << "newmtl a\nKd 0.5\n";
  const std::string bench = "bench --size 8x8 --runs 1 --best 1 --variants bvh --scenes " + dir_ + "/m.obj ";
  auto r = test::run_tracer(bench + "--json " + dir_ + "/x.json --plot " + dir_ + "/./x.json");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--json: '" + dir_ + "/x.json' is also the --plot file"), std::string::npos) << r.output;
  r = test::run_tracer(bench + "--json " + dir_ + "/m.mtl");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--json: '" + dir_ + "/m.mtl' is an input of this run"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("| m"), std::string::npos) << r.output;  // no cell ran
  EXPECT_EQ(slurp_text(dir_ + "/m.mtl"), "newmtl a\nKd 0.5\n");
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

// A --stats-json that cannot be written fails the run after the image was written, and says both.
TEST_F(Cli, AStatsJsonThatCannotBeWrittenSaysTheImageWas) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const auto r = test::run_tracer("render -q --width 8 --height 8 -o " + dir_ + "/kept.png --stats-json /dev/full");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_EQ(r.output.rfind("tracer: error: --stats-json: ", 0), 0u) << r.output;
  EXPECT_NE(r.output.find("(the image was written)"), std::string::npos) << r.output;
  EXPECT_EQ(read_image(dir_ + "/kept.png").width, 8);
}

TEST_F(Cli, StatsJsonNeverOverwritesInputsAndParsesBack) {
  // A scene path with a quote and a backslash: the JSON must escape both.
  const std::string scene = dir_ + "/a\"b\\c.obj";
  fs::copy_file(dir_ + "/ok.obj", scene);
  const std::string quoted_scene = "'" + scene + "'";
  auto r = test::run_tracer("render " + quoted_scene + " -q --width 8 --height 8 -o " + dir_ + "/x.png --stats-json " +
                            quoted_scene);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("is the input scene"), std::string::npos) << r.output;
  r = test::run_tracer("render " + quoted_scene + " -q --width 8 --height 8 -o " + dir_ + "/x.png --stats-json " +
                       dir_ + "/./x.png");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("is also the -o image"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir_ + "/x.png"));
  // Against the names the frames expand to: frame 1 of -o fr.png is fr-0001.png.
  r = test::run_tracer("render " + quoted_scene + " -q --width 8 --height 8 --frames 2 -o " + dir_ +
                       "/fr.png --stats-json " + dir_ + "/fr-0001.png");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("is also frame 1's image"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir_ + "/fr-0000.png"));
  EXPECT_FALSE(fs::exists(dir_ + "/fr-0001.png"));
  r = test::run_tracer("render " + quoted_scene + " -q --integrator ao --width 8 --height 6 --ao 2 -o " + dir_ +
                       "/x.png --stats-json " + dir_ + "/s.json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(dir_ + "/s.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["scene"], scene);
  EXPECT_EQ(j["rays"]["primary"], 48);
  EXPECT_EQ(j["width"], 8);
}

TEST_F(Cli, PathStatsCountSamplesAndCheckpoints) {
  // 16 spp runs in passes of 1, 1, 2, 4 and 8: with a checkpoint due after every pass, the output
  // is rewritten after each but the last (which writes the final image).
  const auto r = test::run_tracer("render -q --integrator path --spp 16 --checkpoint 1e-9 --width 8 --height 6 -o " +
                                  dir_ + "/p.png --stats-json " + dir_ + "/p.json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(dir_ + "/p.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["integrator"], "path");
  EXPECT_EQ(j["spp"], 16);
  EXPECT_EQ(j["rays"]["primary"], 8 * 6 * 16);
  EXPECT_GT(j["rays"]["shadow"].get<int>(), 0);
  EXPECT_GT(j["rays"]["secondary"].get<int>(), 0);
  EXPECT_EQ(j["rays"]["ao"], 0);
  EXPECT_EQ(j["checkpoints_written"], 4);
  EXPECT_GT(j["samples_per_s"].get<double>(), 0.0);
  EXPECT_EQ(read_image(dir_ + "/p.png").width, 8);
}

TEST_F(Cli, AdaptiveStatsAverageOverEveryFrame) {
  // --min-spp is --spp: every pixel of both frames takes all 16 samples.
  const auto r =
      test::run_tracer("render -q --integrator path --spp 16 --min-spp 16 --frames 2 --width 8 --height 6 -o " + dir_ +
                       "/f.png --stats --stats-json " + dir_ + "/f.json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("16.0 taken on average"), std::string::npos) << r.output;
  std::ifstream in(dir_ + "/f.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["frames"], 2);
  EXPECT_EQ(j["rays"]["primary"], 2 * 8 * 6 * 16);
}

TEST_F(Cli, SceneWithoutEmittersIsLitByAWhiteSkyWithANote) {
  const auto r = test::run_tracer("render " + dir_ + "/ok.obj --integrator path --spp 2 --width 8 --height 8 -o " +
                                  dir_ + "/e.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("tracer: note: "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("(--env 1,1,1; --env 0,0,0 for none)"), std::string::npos) << r.output;
  EXPECT_EQ(count_lines(r.output), 1) << r.output;
  // Given an environment, nothing to say.
  const auto lit = test::run_tracer("render " + dir_ + "/ok.obj --integrator path --spp 2 --width 8 --height 8 " +
                                    "--light 0,0,5 --env 0,0,0 -o " + dir_ + "/e.png");
  ASSERT_EQ(lit.exit_code, 0) << lit.output;
  EXPECT_EQ(lit.output, "");
}

// --no-scene-lights drops the emitters' emission too, not only their next-event list: the
// built-in box under a black sky with no --light is black, every pixel, whatever the integrator
// (a bounce that hit the lamp used to find it lit: 64 spp gave a mean of 36.8 of 255).
TEST_F(Cli, NoSceneLightsLeavesNothingThatEmits) {
  for (const char* integrator : {"path", "whitted"}) {
    const std::string out = dir_ + "/dark-" + integrator + ".png";
    // (whitted's ambient term, on by default, is a light of its own: turned off here)
    const auto r =
        test::run_tracer(std::string("render --integrator ") + integrator +
                         " --no-scene-lights --env 0,0,0 --ambient 0 --spp 16 --width 24 --height 24 -q -o " + out);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const Image8 image = read_image(out);
    EXPECT_TRUE(std::all_of(image.rgb.begin(), image.rgb.end(), [](uint8_t v) { return v == 0; })) << integrator;
  }
  // With the scene's lights kept, the same render is lit (the test sees a difference).
  const auto lit = test::run_tracer("render --integrator path --env 0,0,0 --spp 16 --width 24 --height 24 -q -o " +
                                    dir_ + "/lit.png");
  ASSERT_EQ(lit.exit_code, 0) << lit.output;
  const Image8 image = read_image(dir_ + "/lit.png");
  EXPECT_GT(std::count_if(image.rgb.begin(), image.rgb.end(), [](uint8_t v) { return v > 0; }), 100);
}

// A flag that takes a value each time it is given stops at that value: the scene after it is
// the positional argument (CLI11 took it as a second --light and said it was not x,y,z).
TEST_F(Cli, ARepeatableFlagTakesOneValueEachTime) {
  const auto r = test::run_tracer("render --light 0,0,2 --light 0,1,2 " + dir_ +
                                  "/ok.obj --eye 0,0,3 --look 0,0,0 --integrator ao --width 8 --height 8 -q -o " +
                                  dir_ + "/two.png --stats-json " + dir_ + "/two.json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(test::read_bytes(dir_ + "/two.json").find("2 point lights"), std::string::npos)
      << test::read_bytes(dir_ + "/two.json");
}

TEST_F(Cli, ASceneWithoutLightsTakesItsViewFromAViewsFileBesideIt) {
  // ok.obj has no emitter; a views.tsv beside it names it: a plain render uses that view's camera
  // and light, says so, and gives the image --view gives. Standard input has no "beside".
  fs::copy_file(dir_ + "/tri-views.tsv", dir_ + "/views.tsv");
  const std::string flags = " --integrator ao --width 24 --height 16 -o ";
  auto r = test::run_tracer("render " + dir_ + "/ok.obj" + flags + dir_ + "/plain.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("has no light of its own: using its view 'tri' (camera and light)"), std::string::npos)
      << r.output;
  // --no-scene-lights drops the view's light too, and the note says only the camera is used.
  r = test::run_tracer("render " + dir_ +
                       "/ok.obj --no-scene-lights --env 1,1,1 --integrator path --spp 1 "
                       "--width 8 --height 8 -o " +
                       dir_ + "/nolight.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("using its view 'tri' (camera)\n"), std::string::npos) << r.output;
  r = test::run_tracer("render --view tri --views " + dir_ + "/views.tsv -q" + flags + dir_ + "/view.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read_image(dir_ + "/plain.png").rgb, read_image(dir_ + "/view.png").rgb);
  // The view's own scene given beside --view, by another path to it: the same image.
  r = test::run_tracer("render " + dir_ + "/../" + fs::path(dir_).filename().string() + "/ok.obj --view tri --views " +
                       dir_ + "/views.tsv -q" + flags + dir_ + "/both.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read_image(dir_ + "/both.png").rgb, read_image(dir_ + "/view.png").rgb);
  r = test::run_tracer("render - -q" + flags + dir_ + "/stdin.png < " + dir_ + "/ok.obj");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(read_image(dir_ + "/stdin.png").rgb, read_image(dir_ + "/view.png").rgb);
}

TEST_F(Cli, CtrlCDuringAPathRenderWritesTheSamplesSoFar) {
  // After the first pass every pixel has a sample: Ctrl-C writes that complete (noisier) image.
  const std::string out = dir_ + "/progressive.png";
  const std::string cmd = "timeout --foreground --preserve-status -s INT 2 " + std::string(TRACER_EXE) +
                          " render -q --integrator path --spp 1000000 --width 64 --height 48 -o " + out + " 2>&1";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130);
  ASSERT_TRUE(fs::exists(out));
  const Image8 img = read_image(out);
  EXPECT_EQ(img.width, 64);
  EXPECT_EQ(img.height, 48);
}

// An EXR whose first pixel is NaN in every channel (encode_exr would write 0).
void write_nan_exr(const std::string& path, const Framebuffer& fb) {
  Imf::Header header(fb.width(), fb.height());
  std::vector<float> planes(3 * size_t(fb.width()) * size_t(fb.height()));
  Imf::FrameBuffer frame;
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    const size_t n = size_t(fb.width()) * size_t(fb.height());
    for (size_t i = 0; i < n; ++i) planes[size_t(c) * n + i] = fb.radiance(int(i) % fb.width(), int(i) / fb.width())[c];
    planes[size_t(c) * n] = std::numeric_limits<float>::quiet_NaN();
    header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
    frame.insert(names[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(&planes[size_t(c) * n]), sizeof(float),
                                      sizeof(float) * size_t(fb.width())));
  }
  Imf::OutputFile file(path.c_str(), header);
  file.setFrameBuffer(frame);
  file.writePixels(fb.height());
}

// An EXR of 4,000,000 x 1 pixels: larger than any image tracer writes.
void write_wide_exr_header(const std::string& path) {
  Imf::Header header(4000000, 1);
  header.channels().insert("R", Imf::Channel(Imf::HALF));
  header.channels().insert("G", Imf::Channel(Imf::HALF));
  header.channels().insert("B", Imf::Channel(Imf::HALF));
  std::vector<half> row(4000000);
  Imf::FrameBuffer frame;
  for (const char* c : {"R", "G", "B"})
    frame.insert(c, Imf::Slice(Imf::HALF, reinterpret_cast<char*>(row.data()), sizeof(half), 0));
  Imf::OutputFile file(path.c_str(), header);
  file.setFrameBuffer(frame);
  file.writePixels(1);
}

TEST_F(Cli, CompareGivesRmseAndRejectsMismatchedImages) {
  const std::string d = dir_ + "/";
  ASSERT_EQ(test::run_tracer("render -q --integrator path --spp 4 --width 8 --height 8 -o " + d + "a.exr").exit_code,
            0);
  ASSERT_EQ(
      test::run_tracer("render -q --integrator path --spp 4 --seed 1 --width 8 --height 8 -o " + d + "b.exr").exit_code,
      0);
  ASSERT_EQ(test::run_tracer("render -q --integrator path --spp 4 --width 8 --height 6 -o " + d + "c.exr").exit_code,
            0);
  ASSERT_EQ(test::run_tracer("render -q --integrator ao --width 8 --height 8 -o " + d + "a.png").exit_code, 0);
  auto r = test::run_tracer("compare " + d + "a.exr " + d + "a.exr");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("8x8, linear radiance: RMSE 0,"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(" (+0.00 %)"), std::string::npos) << r.output;  // the two means, equal
  // An image with one NaN texel, a 2048 x 1024 one cut after 400 bytes, a PNG header claiming
  // 8192 x 8192 with no pixels behind it, and an EXR header claiming 4000000 x 1 (sizes are read
  // from the headers, before any pixel is decoded).
  {
    Framebuffer fa = read_exr(d + "a.exr");
    write_nan_exr(d + "nan.exr", fa);
    Framebuffer big(2048, 1024);
    std::ofstream(d + "cut.exr", std::ios::binary) << encode_exr(big, ExrPixel::Float).substr(0, 400);
    std::string png = encode_png(read_image(d + "a.png"));
    png.replace(16, 8, std::string("\0\0\x20\0\0\0\x20\0", 8));
    std::ofstream(d + "claim.png", std::ios::binary) << png.substr(0, 33);
    write_wide_exr_header(d + "huge.exr");
  }
  r = test::run_tracer("compare " + d + "a.exr " + d + "b.exr");  // another seed: noise, not zero
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("RMSE 0,"), std::string::npos) << r.output;
  r = test::run_tracer("compare " + d + "a.png " + d + "a.png");
  EXPECT_NE(r.output.find("PSNR inf dB"), std::string::npos) << r.output;
  // Two EXR in display values: each channel tone-mapped at the exposure, not rounded to 8 bits.
  {
    const Framebuffer fa = read_exr(d + "a.exr"), fb = read_exr(d + "b.exr");
    double sum = 0.0, sum_b = 0.0;
    for (int y = 0; y < 8; ++y) {
      for (int x = 0; x < 8; ++x) {
        for (int c = 0; c < 3; ++c) {
          const double e = display_value(fa.radiance(x, y)[c], 0.5f) - display_value(fb.radiance(x, y)[c], 0.5f);
          sum += e * e;
          sum_b += display_value(fb.radiance(x, y)[c], 0.5f);
        }
      }
    }
    r = test::run_tracer("compare --exposure 0.5 " + d + "a.exr " + d + "b.exr");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    const size_t at = r.output.find("8x8, display values 0-1 at exposure 0.5: RMSE ");
    ASSERT_NE(at, std::string::npos) << r.output;
    const double rmse = std::stod(r.output.substr(at + 46));
    EXPECT_GT(rmse, 0.0);
    EXPECT_NEAR(rmse, std::sqrt(sum / 192.0), 1e-5 * rmse) << r.output;
    const size_t and_at = r.output.find(" and ", r.output.find("means "));
    ASSERT_NE(and_at, std::string::npos) << r.output;
    EXPECT_NEAR(std::stod(r.output.substr(and_at + 5)), sum_b / 192.0, 1e-5) << r.output;
  }
  for (const auto& [args, code, message] :
       {std::tuple{"a.exr c.exr", 2, "compare: sizes differ (8x8 and 8x6)"},
        std::tuple{"a.exr a.png", 2, "compare: both images must be EXR (linear) or both PNG/PPM (display)"},
        std::tuple{"--exposure 1.5 a.png a.png", 2, "compare: --exposure tone-maps .exr images"},
        std::tuple{"--exposure 0 a.exr a.exr", 2, "--exposure: Value 0 not in range"},
        std::tuple{"a.exr none.exr", 1, "none.exr: cannot open: no such file"},
        std::tuple{"a.exr nan.exr", 1, "nan.exr: 3 pixel values are not finite (NaN or infinity)"},
        std::tuple{"cut.exr cut.exr", 1, "cut.exr: "},
        std::tuple{"a.png claim.png", 2, "compare: sizes differ (8x8 and 8192x8192)"},
        std::tuple{"a.exr huge.exr", 1, "huge.exr: 4000000 x 1 pixels, outside the 1 to 16384 a side tracer reads"}}) {
    // The last two words are files in the test's folder.
    std::string a = " " + std::string(args);
    const size_t second = a.rfind(' ');
    a.insert(second + 1, d);
    a.insert(a.rfind(' ', second - 1) + 1, d);
    r = test::run_tracer("compare" + a);
    EXPECT_EQ(r.exit_code, code) << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << r.output;
    EXPECT_EQ(count_lines(r.output), 1) << r.output;
  }
}

TEST_F(Cli, FramesOrbitTheCameraAndNumberTheFiles) {
  const std::string flags = " -q --integrator ao --width 24 --height 18";
  auto r = test::run_tracer("render" + flags + " --frames 3 --orbit 90 -o " + dir_ + "/f.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = test::run_tracer("render" + flags + " -o " + dir_ + "/single.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* name : {"/f-0000.png", "/f-0001.png", "/f-0002.png"}) EXPECT_TRUE(fs::exists(dir_ + name)) << name;
  EXPECT_FALSE(fs::exists(dir_ + "/f.png"));
  // Frame 0 is the camera itself; the others have turned 30 and 60 degrees about the look point.
  EXPECT_EQ(read_image(dir_ + "/f-0000.png").rgb, read_image(dir_ + "/single.png").rgb);
  EXPECT_NE(read_image(dir_ + "/f-0001.png").rgb, read_image(dir_ + "/single.png").rgb);
  EXPECT_NE(read_image(dir_ + "/f-0002.png").rgb, read_image(dir_ + "/f-0001.png").rgb);
  // Turning 30 degrees is what frame 1 of 3 over 90 degrees is.
  r = test::run_tracer("render" + flags + " --frames 2 --orbit 60 -o " + dir_ + "/g.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read_image(dir_ + "/g-0001.png").rgb, read_image(dir_ + "/f-0001.png").rgb);
}

TEST_F(Cli, BenchJsonParsesBack) {
  const auto r = test::run_tracer(
      "bench --scenes builtin --variants sah,bvh8 --size 8x8 --ao 1 --runs 1 --best 1 --json " + dir_ + "/b.json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(dir_ + "/b.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j["cells"].size(), 2u);
  EXPECT_EQ(j["cells"][0]["scene"], "builtin");
  EXPECT_EQ(j["size"][0], 8);
}

// --scenes instanced: the bunny view's scene placed 100 times and kept once; the variants that
// trace no instances are not run (n/a), bvh8 and Embree are, on the same 100 placed triangles.
TEST_F(Cli, BenchTimesTheInstancedSceneWithTheVariantsThatTraceInstances) {
  std::ofstream(dir_ + "/bunny-views.tsv") << "scene\tobj\teye\tlook\tup\tfov\tlight\tnote\n"
                                           << "bunny\tok.obj\t0,0,3\t0,0,0\t0,1,0\t45\t0,0,2\tone triangle\n";
  const auto r = test::run_tracer("bench --scenes instanced --views " + dir_ +
                                  "/bunny-views.tsv --variants sah,bvh8,embree --size 8x8 --ao 1 --runs 1 --best 1 "
                                  "--json " +
                                  dir_ + "/i.json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("| Bunny x100 (instanced) | 100 | n/a |"), std::string::npos) << r.output;
  std::ifstream in(dir_ + "/i.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j["cells"].size(), 3u);
  for (const nlohmann::json& c : j["cells"]) {
    EXPECT_EQ(c["triangles"], 100);
    EXPECT_EQ(c["not_traced"], c["variant"] == "sah") << c.dump();
    if (c["variant"] != "sah") {
      EXPECT_GT(c["rays"].get<uint64_t>(), 0u) << c.dump();
    }
  }
}

TEST_F(Cli, MoreThreadsThanCoresRunAsAskedWithOurWarning) {
  const auto r = test::run_tracer("render -q --width 16 --height 16 --ao 1 --threads 64 --stats -o " + dir_ + "/t.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("TBB Warning"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("tbb, 64 threads"), std::string::npos) << r.output;
  if (std::thread::hardware_concurrency() < 64) {
    EXPECT_NE(r.output.find("tracer: warning: --threads 64"), std::string::npos) << r.output;
  }
}

TEST_F(Cli, OneAllowedCoreRunsOneThreadWithoutWarnings) {
  // Under taskset the default thread count follows the affinity mask, not the machine's cores.
  const std::string cmd = "taskset -c 0 " + std::string(TRACER_EXE) +
                          " render -q --width 16 --height 16 --ao 1 --stats -o " + dir_ + "/t.png 2>&1";
  FILE* pipe = ::popen(cmd.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string out;
  char buf[4096];
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) out.append(buf, n);
  ASSERT_EQ(::pclose(pipe), 0) << out;
  EXPECT_EQ(out.find("Warning"), std::string::npos) << out;
  EXPECT_NE(out.find("tbb, 1 threads"), std::string::npos) << out;
}

TEST_F(Cli, RendersAViewWithItsCameraAndLight) {
  // The view's camera and light, against the same given as flags: the same image.
  auto r = test::run_tracer("render --view tri --views " + dir_ + "/tri-views.tsv -q --width 24 --height 16 -o " +
                            dir_ + "/v.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = test::run_tracer("render " + dir_ +
                       "/ok.obj --eye 0,0,3 --look 0,0,0 --fov 45 --no-scene-lights --light 0,0,2 -q " +
                       "--width 24 --height 16 -o " + dir_ + "/f.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read_image(dir_ + "/v.png").rgb, read_image(dir_ + "/f.png").rgb);
  // bench times a view and, with --framed, the same scene framed from outside as its own row.
  r = test::run_tracer("bench --scenes tri --views " + dir_ +
                       "/tri-views.tsv --framed --variants sah --size 8x8 --runs 1 --best 1");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("| Tri | 1 |"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("| Tri (framed) | 1 |"), std::string::npos) << r.output;
}

TEST_F(Cli, DefaultIsTheFastestPathWithTheScalarImage) {
  // No flags: the 8-wide BVH with packets and AO streams; the same image as with AO bundles and
  // as the scalar binary BVH tracing every ray alone. --simd off alone asks for that scalar tree.
  const std::string common = " -q --integrator ao --width 24 --height 20 --ao 4";
  auto r = test::run_tracer("render" + common + " --stats-json " + dir_ + "/d.json -o " + dir_ + "/d.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(dir_ + "/d.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["accel"].get<std::string>().rfind("bvh8", 0), 0u) << j.dump();
  EXPECT_TRUE(j["packets"].get<bool>());
  EXPECT_TRUE(j["streams"].get<bool>());
  r = test::run_tracer("render" + common + " --accel bvh --no-packets -o " + dir_ + "/s.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read_image(dir_ + "/d.png").rgb, read_image(dir_ + "/s.png").rgb);
  r = test::run_tracer("render" + common + " --no-streams -o " + dir_ + "/b.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read_image(dir_ + "/d.png").rgb, read_image(dir_ + "/b.png").rgb);
  r = test::run_tracer("render" + common + " --simd off --stats-json " + dir_ + "/o.json -o " + dir_ + "/o.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in2(dir_ + "/o.json");
  const nlohmann::json k = nlohmann::json::parse(in2);
  EXPECT_EQ(k["accel"], "bvh-sah");
  EXPECT_FALSE(k["packets"].get<bool>()) << "--simd off: no SIMD bundles either";
}

// The build quality changes the tree, never the image: spatial splits keep every hit exact. By
// default a path render of at least 16 pixel samples per triangle builds at high, anything
// shorter at medium.
TEST_F(Cli, BuildQualityChangesTheTreeNotTheImage) {
  const std::string scene = test::have_shared_scenes() ? test::scene_path("cornell-box/CornellBox-Water.obj") : "";
  const std::string common = " -q";
  const auto accel_of = [&](const std::string& flags) {
    auto r = test::run_tracer("render " + flags + common + " --stats-json " + dir_ + "/d.json -o " + dir_ + "/d.png");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    std::ifstream in(dir_ + "/d.json");
    return nlohmann::json::parse(in)["accel"].get<std::string>();
  };
  const std::string size = " --width 32 --height 24";
  EXPECT_EQ(accel_of(scene + size + " --spp 2 --build-quality medium").find("-high"), std::string::npos);
  const std::vector<uint8_t> medium = read_image(dir_ + "/d.png").rgb;
  EXPECT_NE(accel_of(scene + size + " --spp 2 --build-quality high").find("-high"), std::string::npos);
  EXPECT_EQ(read_image(dir_ + "/d.png").rgb, medium);
  // The built-in box's 32 triangles: 32x24 pixels x 2 spp is 48 samples per triangle; 1 spp of
  // 8x4 pixels is 1; AO builds at medium.
  EXPECT_NE(accel_of("--spp 2" + size).find("-high"), std::string::npos);
  EXPECT_EQ(accel_of("--spp 1 --width 8 --height 4").find("-high"), std::string::npos);
  EXPECT_EQ(accel_of("--integrator ao" + size).find("-high"), std::string::npos);
}

TEST_F(Cli, ReadsTheSceneFromStandardInputAndPipes) {
  const std::string ref = dir_ + "/ref.png";
  ASSERT_EQ(test::run_tracer("render " + dir_ + "/ok.obj -q --width 16 --height 16 -o " + ref).exit_code, 0);
  auto r = test::run_tracer("render - -q --width 16 --height 16 -o " + dir_ + "/stdin.png < " + dir_ + "/ok.obj");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read_image(dir_ + "/stdin.png").rgb, read_image(ref).rgb);
  r = test::run_tracer("render /dev/stdin -q --width 16 --height 16 -o " + dir_ + "/pipe.png < " + dir_ + "/ok.obj");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read_image(dir_ + "/pipe.png").rgb, read_image(ref).rgb);
}

TEST_F(Cli, RendersPngPpmAndStats) {
  const std::string scene = dir_ + "/ok.obj";
  auto r =
      test::run_tracer("render " + scene + " -q --integrator ao --width 16 --height 12 --ao 2 --stats --stats-json " +
                       dir_ + "/s.json -o " + dir_ + "/a.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("Mrays/s"), std::string::npos);
  const Image8 png = read_image(dir_ + "/a.png");
  EXPECT_EQ(png.width, 16);
  EXPECT_EQ(png.height, 12);
  std::ifstream json(dir_ + "/s.json");
  const std::string text((std::istreambuf_iterator<char>(json)), {});
  EXPECT_NE(text.find("\"primary\": 192"), std::string::npos) << text;
  EXPECT_NE(text.find("\"mrays_per_s\""), std::string::npos);
  // The load split into its phases, which add up to no more than the whole.
  const nlohmann::json stats = nlohmann::json::parse(text);
  double phases = 0.0;
  for (const char* phase : {"read", "parse", "textures", "assembly"}) {
    ASSERT_TRUE(stats["load_phases_ms"].contains(phase)) << text;
    EXPECT_GE(stats["load_phases_ms"][phase].get<double>(), 0.0) << phase;
    phases += stats["load_phases_ms"][phase].get<double>();
  }
  EXPECT_LE(phases, stats["load_ms"].get<double>());
  EXPECT_NE(r.output.find("load "), std::string::npos);
  EXPECT_NE(r.output.find("(read "), std::string::npos) << r.output;
  r = test::run_tracer("render " + scene + " -q --integrator ao --width 16 --height 12 --ao 2 -o " + dir_ + "/a.ppm");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Image8 ppm = read_image(dir_ + "/a.ppm");
  EXPECT_EQ(ppm.rgb, png.rgb);  // same render, two containers
  // The 8-wide BVH with primary-ray packets: the same image, every primary ray counted once.
  r = test::run_tracer("render " + scene +
                       " -q --integrator ao --width 16 --height 12 --ao 2 --accel bvh8 --packets --stats-json " + dir_ +
                       "/p.json -o " + dir_ + "/p.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read_image(dir_ + "/p.png").rgb, png.rgb);
  std::ifstream pjson(dir_ + "/p.json");
  const std::string ptext((std::istreambuf_iterator<char>(pjson)), {});
  EXPECT_NE(ptext.find("\"packets\": true"), std::string::npos) << ptext;
  EXPECT_NE(ptext.find("\"primary\": 192"), std::string::npos) << ptext;
  // The binary BVH with AO bundles: the same image.
  r = test::run_tracer("render " + scene + " -q --integrator ao --width 16 --height 12 --ao 2 --packets -o " + dir_ +
                       "/b.png");
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
  // twice, and a second signal ends the process at once by design (no partial image then).
  const std::string scene = dir_ + "/many.obj";
  {
    std::ofstream f(scene);
    for (int i = 0; i < 2000; ++i) f << "v " << i % 50 << " " << i / 50 << " 0\n";
    for (int i = 1; i + 51 <= 2000; ++i) f << "f " << i << " " << i + 1 << " " << i + 50 << "\n";
  }
  const std::string exe = TRACER_EXE;
  for (const bool partial : {false, true}) {
    const std::string out = dir_ + (partial ? "/partial.png" : "/none.png");
    const std::string cmd = "timeout --foreground --preserve-status -s INT 2 " + exe + " render " + scene +
                            " -q --accel brute --width 2048 --height 2048 -o " + out +
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
  for (const auto& entry : fs::directory_iterator(dir_))
    EXPECT_EQ(entry.path().string().find(".tmp-"), std::string::npos);
}

// Runs `args` under `timeout --foreground --preserve-status -s SIG 1`: one signal after a second.
int run_signalled(const std::string& sig, const std::string& args) {
  const std::string cmd =
      "timeout --foreground --preserve-status -s " + sig + " 1 " + std::string(TRACER_EXE) + " " + args + " 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

TEST_F(Cli, TermAndHupStopLikeCtrlC) {
  const std::string scene = dir_ + "/many.obj";
  {
    std::ofstream f(scene);
    for (int i = 0; i < 2000; ++i) f << "v " << i % 50 << " " << i / 50 << " 0\n";
    for (int i = 1; i + 51 <= 2000; ++i) f << "f " << i << " " << i + 1 << " " << i + 50 << "\n";
  }
  for (const auto& [sig, code] : {std::pair{"TERM", 143}, {"HUP", 129}}) {
    SCOPED_TRACE(sig);
    const std::string out = dir_ + "/out.png";
    EXPECT_EQ(run_signalled(sig, "render " + scene + " -q --accel brute --width 2048 --height 2048 -o " + out), code);
    EXPECT_FALSE(fs::exists(out));
  }
  for (const auto& entry : fs::directory_iterator(dir_))
    EXPECT_EQ(entry.path().string().find(".tmp-"), std::string::npos);
}

TEST_F(Cli, CtrlCWhileTheSceneIsStillArrivingStopsWithoutAnImage) {
  // The scene is a FIFO whose writer never finishes: without a cancellable read this hangs.
  const std::string fifo = dir_ + "/slow.obj";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string out = dir_ + "/out.png";
  {
    std::ofstream script(dir_ + "/run.sh");
    script << "sleep 30 > " << fifo << " & holder=$!\n"
           << "timeout --foreground --preserve-status -s INT 1 " << TRACER_EXE << " render " << fifo
           << " -q --save-partial -o " << out << " > " << dir_ << "/log.txt 2>&1\necho $? > " << dir_
           << "/code.txt\nkill $holder\n";
  }
  ASSERT_EQ(std::system(("bash " + dir_ + "/run.sh").c_str()), 0);
  std::ifstream code(dir_ + "/code.txt");
  int exit_code = -1;
  code >> exit_code;
  EXPECT_EQ(exit_code, 130);
  std::ifstream log(dir_ + "/log.txt");
  const std::string text((std::istreambuf_iterator<char>(log)), {});
  EXPECT_NE(text.find("interrupted; no image written"), std::string::npos) << text;
  EXPECT_FALSE(fs::exists(out));
}

// --simd-target chooses the tree's kernels (its name says which), and the image is the same.
TEST_F(Cli, TheSimdTargetIsTheAcceleratorsAndChangesNoPixel) {
  const std::string common = "render --integrator ao --width 40 --height 30 -q --stats --exr float -o ";
  const test::CommandResult sse4 = test::run_tracer(common + dir_ + "/sse4.exr --simd-target sse4");
  ASSERT_EQ(sse4.exit_code, 0) << sse4.output;
  EXPECT_NE(sse4.output.find("bvh8-SSE4"), std::string::npos) << sse4.output;
  const test::CommandResult best = test::run_tracer(common + dir_ + "/best.exr");
  ASSERT_EQ(best.exit_code, 0) << best.output;
  EXPECT_EQ(slurp_text(dir_ + "/sse4.exr"), slurp_text(dir_ + "/best.exr"));
}

}  // namespace
}  // namespace tracer
