// The MTL reader (importers/mtl_parser.hpp): the format's statements, the errors that keep a wrong
// image from being made, the oddities of real exporters as one grouped warning, and tinyobjloader
// as the oracle on the files in the repository and on generated ones.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "base/errors.hpp"
#include "importers/mtl_parser.hpp"
#include "importers/obj_loader.hpp"
#include "oracle/mtl_oracle.hpp"
#include "test_util.hpp"

namespace tracer {
namespace {

namespace fs = std::filesystem;

TEST(MtlParser, ReadsEveryNumericStatementAsTheFormatSays) {
  const std::vector<MtlMaterial> m =
      parse_mtl(
          "# comment\nnewmtl  Grey\t\nKd 0.5\nKs 0.1 0.2 0.3\nKe 17 12 4# glued comment\nNs 10\nNi 1.5\nd 0.25\n"
          "Tr 0.5\nillum 7\nmap_Kd -s 1 1 1 -o 0.5 0.5 my texture.png\nbump -bm 0.3 height.png\n"
          "newmtl Glass\nTf 0.9\nKd xyz 0.95047 1 1.08883\n",
          "t.mtl")
          .materials;
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0].name, "Grey");
  EXPECT_EQ(m[0].kd, Vec3(0.5f));
  EXPECT_EQ(m[0].ks, (Vec3{0.1f, 0.2f, 0.3f}));
  EXPECT_EQ(m[0].ke, (Vec3{17.0f, 12.0f, 4.0f}));
  EXPECT_EQ(m[0].ns, 10.0f);
  EXPECT_EQ(m[0].ni, 1.5f);
  EXPECT_EQ(m[0].dissolve, 0.25f);  // d wins over Tr
  EXPECT_EQ(m[0].illum, 7);
  EXPECT_EQ(m[0].diffuse_map, "my texture.png");
  EXPECT_EQ(m[0].bump_map, "height.png");
  EXPECT_FLOAT_EQ(m[0].bump_multiplier, 0.3f);
  EXPECT_EQ(m[1].tf, Vec3(0.9f));
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(m[1].kd[i], 1.0f, 2e-3f);  // D65 white is RGB white
}

// Values that would make the image wrong stay errors, each naming file:line.
TEST(MtlParser, BadValuesAreErrorsWithFileAndLine) {
  const std::pair<const char*, const char*> cases[] = {
      {"Kd nan", "t.mtl:2: 'Kd' value 'nan' is not a finite number"},
      {"Kd 0.5 -inf 0.5", "t.mtl:2: 'Kd' value '-inf' is not a finite number"},
      {"Kd red green blue", "t.mtl:2: malformed number 'red'"},
      {"Kd 1e", "t.mtl:2: malformed number '1e'"},
      {"Kd .", "t.mtl:2: malformed number '.'"},
      {"Kd 0.7 00.6ewmt 4", "t.mtl:2: malformed number '00.6ewmt'"},
      {"Ke nan", "t.mtl:2: 'Ke' value 'nan' is not a finite number"},
      {"Ke 3e38", "t.mtl:2: 'Ke' value '3e38' out of range [0, 1e+06]"},
      {"Kd 1e308", "t.mtl:2: 'Kd' value '1e308' out of range [0, 1]"},
      {"Kd 1e999", "t.mtl:2: 'Kd' value '1e999' is not a finite number"},
      {"Kd -0.5", "t.mtl:2: 'Kd' value '-0.5' out of range [0, 1]"},
      {"Kd 0.5 0.5", "t.mtl:2: 'Kd' needs one value or three, got two"},
      {"Kd 0.5 0.5 red", "t.mtl:2: 'Kd' needs one value or three, got two"},
      {"Kd", "t.mtl:2: 'Kd' needs a number"},
      {"Kd spectral a.rfl", "t.mtl:2: 'Kd spectral' is not supported"},
      {"Ns -1", "t.mtl:2: 'Ns' value '-1' out of range"},
      {"Ni 1e3", "t.mtl:2: 'Ni' value '1e3' out of range [0, 100]"},
      {"d 2", "t.mtl:2: 'd' value '2' out of range [0, 1]"},
      {"illum 11", "t.mtl:2: 'illum' value '11' out of range [0, 10]"},
      {"illum 99999999999999999999", "t.mtl:2: 'illum' value '99999999999999999999' out of range [0, 10]"},
      {"illum two", "t.mtl:2: malformed number 'two'"},
      {"map_Kd", "t.mtl:2: 'map_Kd' needs a file name"},
      {"map_Kd -clamp on", "t.mtl:2: 'map_Kd' option '-clamp' leaves no file name"},
      {"map_bump -bm tex.png", "t.mtl:2: malformed number 'tex.png'"},
      {"newmtl", "t.mtl:2: 'newmtl' needs a name"},
  };
  for (const auto& [line, message] : cases) {
    SCOPED_TRACE(line);
    try {
      parse_mtl(std::string("newmtl m\n") + line + "\n", "t.mtl");
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
}

// The classes seen in real exporters' files: read as tinyobjloader reads them, and said once per
// file with the lines.
TEST(MtlParser, RealExportersOdditiesAreOneGroupedWarning) {
  const MtlFile f = parse_mtl(
      "Ka 1 1 1\n"                          // 1: before any newmtl
      "newmtl a\n"                          // 2
      "Tr 0  0\n"                           // 3: a further value
      "Tr 0  illum 2\n"                     // 4: two statements on one line
      "Ka 0.0000 0.0000 0.0000c\n"          // 5: a letter glued to a number
      "map_Kd -o 0.5 0.5 -s 2 2 tex.png\n"  // 6: -o and -s with two values each
      "Kd 0.1 0.2 0.3 0.4\n"                // 7: a fourth value
      "illum 2.5\n"                         // 8: atoi reads 2
      "map_bump -foo 1 -bm 0.5 h.png\n"     // 9: an unknown option
      "Ns 10 20\r\n",                       // 10
      "t.mtl");
  ASSERT_EQ(f.materials.size(), 1u);
  const MtlMaterial& m = f.materials[0];
  EXPECT_EQ(m.dissolve, 1.0f);
  EXPECT_EQ(m.ka, Vec3(0.0f));
  EXPECT_EQ(m.diffuse_map, "tex.png");
  EXPECT_EQ(m.kd, (Vec3{0.1f, 0.2f, 0.3f}));
  EXPECT_EQ(m.illum, 2);
  EXPECT_EQ(m.bump_map, "h.png");
  EXPECT_EQ(m.bump_multiplier, 0.5f);
  EXPECT_EQ(m.ns, 10.0f);
  ASSERT_EQ(f.warnings.size(), 3u);
  EXPECT_EQ(f.warnings[0], "t.mtl: ignored trailing text on lines 3, 4, 5, 7, 8, 10 (first: 'Tr 0  0')");
  EXPECT_EQ(f.warnings[1], "t.mtl: statements before the first 'newmtl' ignored on line 1 (first: 'Ka 1 1 1')");
  EXPECT_EQ(f.warnings[2], "t.mtl: unknown texture options skipped with one value each on line 9 (first: '-foo')");
}

TEST(MtlParser, TheLoaderSaysTheWarningOnceAndAFileWithoutMaterialsIsNamed) {
  std::vector<std::string> warnings;
  const auto sink = [&](const std::string& w) { warnings.push_back(w); };
  load_obj_from_string("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n",
                       "newmtl a\nTr 0  0\nNs 1 2\nKd 0.5 0.5 0.5 0.5\n", "m.obj", sink);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0], "m.obj: <mtl>: ignored trailing text on lines 2, 3, 4 (first: 'Tr 0  0')");
  warnings.clear();
  load_obj_from_string("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "v 0 0 0\nf 1 2 3\n", "m.obj", sink);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0], "m.obj: <mtl>: defines no material (no 'newmtl'): is it an MTL file?");
}

TEST(MtlParser, OneValueIsGreyAndTwoSpacesStillNameTheMaterial) {
  const Scene s = load_obj_from_string("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl  Lamp\nf 1 2 3\n",
                                       "newmtl  Lamp\nKd 0.5\nKe 2\n", "m.obj");
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[s.tri_material[0]].name, "Lamp");
  EXPECT_EQ(s.materials[0].kd, Vec3(0.5f));
  EXPECT_EQ(s.materials[0].ke, Vec3(2.0f));
  EXPECT_EQ(s.lights.size(), 1u);
}

// Where tracer reads a file otherwise than tinyobjloader, on purpose (docs/RELIABILITY.md).
TEST(MtlParser, WhereTracerDepartsFromTinyobjloaderItFollowsTheFormat) {
  const MtlFile f = parse_mtl(
      "newmtl a\nKd 0.5\nmap_Kd -o 0.5 tex.png\n"    // one value is grey; -o takes one to three
      "newmtl b\nmap_Kd -cc on t.png # a comment\n"  // -cc is the format's; '#' starts a comment
      "newmtl c d\n",                                // the name is one word, as usemtl's
      "t.mtl");
  ASSERT_EQ(f.materials.size(), 3u);
  EXPECT_EQ(f.materials[0].kd, Vec3(0.5f));
  EXPECT_EQ(f.materials[0].diffuse_map, "tex.png");
  EXPECT_EQ(f.materials[1].kd, Vec3(0.6f));  // map_Kd without Kd, in every material
  EXPECT_EQ(f.materials[1].diffuse_map, "t.png");
  EXPECT_EQ(f.materials[2].name, "c");
  // The oracle agrees once the format's meaning is written out for tinyobjloader.
  EXPECT_EQ(oracle::mtl_disagreement("newmtl a\nKd 0.5 # grey\nnewmtl b\nmap_Kd t.png\n"), std::nullopt);
}

// Every MTL file of the repository's fuzz corpus and of ../shared/scenes: tracer loads what
// tinyobjloader loads, with the same values, or refuses it for a reason that keeps a wrong image
// from being made.
TEST(MtlDifferential, TheCorpusReadsAsTinyobjloaderReadsIt) {
  std::vector<fs::path> files;
  for (const char* dir : {TRACER_SOURCE_DIR "/fuzz/corpus/mtl", TRACER_SCENES_DIR}) {
    if (!fs::exists(dir)) continue;
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
      const std::string ext = e.path().extension().string();
      if (e.is_regular_file() && (ext == ".mtl" || ext.empty())) files.push_back(e.path());
    }
  }
  ASSERT_GT(files.size(), 100u);
  size_t loaded = 0;
  for (const fs::path& p : files) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    bool refused = false;
    const std::optional<std::string> d = oracle::mtl_disagreement(s.str(), &refused);
    EXPECT_EQ(d, std::nullopt) << p;
    loaded += refused ? 0 : 1;
  }
  EXPECT_GT(loaded, files.size() / 2);  // the comparison is made, not skipped
}

// Generated files: numbers in every spelling, glued letters, extra and missing values, texture
// options in every order, tabs, CRLF, comments after values, values out of range.
std::string generated_mtl(std::mt19937& rng) {
  const auto pick = [&](int n) { return int(rng() % uint32_t(n)); };
  const auto unit = [&] { return float(rng() % 1001) / 1000.0f; };
  const auto number = [&](float v) {
    char b[64];
    switch (pick(8)) {
      case 0:
        std::snprintf(b, sizeof b, "%.6f", double(v));
        break;
      case 1:
        std::snprintf(b, sizeof b, "%g", double(v));
        break;
      case 2:
        std::snprintf(b, sizeof b, "%e", double(v));
        break;
      case 3:
        std::snprintf(b, sizeof b, "+%.4f", double(v));
        break;
      case 4:
        std::snprintf(b, sizeof b, "%.4fc", double(v));
        break;  // a glued letter
      case 5:
        std::snprintf(b, sizeof b, "%.3E", double(v));
        break;
      case 6:
        std::snprintf(b, sizeof b, "%.2fx1", double(v));
        break;
      default:
        std::snprintf(b, sizeof b, "%.9g", double(v));
        break;
    }
    std::string s = b;
    if (s.rfind("0.", 0) == 0 && pick(4) == 0) s.erase(0, 1);  // ".5"
    return s;
  };
  const char* seps[] = {" ", "  ", "\t", " \t "};
  const char* ends[] = {"\n", "\r\n", " \n", "\t\r\n", " # note\n", "# glued\n"};
  const auto sep = [&] { return std::string(seps[pick(4)]); };
  const auto end = [&] { return std::string(ends[pick(6)]); };
  std::string text;
  const int materials = 1 + pick(3);
  for (int m = 0; m < materials; ++m) {
    text += "newmtl" + sep() + "mat" + std::to_string(m) + end();
    const int statements = pick(9);
    for (int k = 0; k < statements; ++k) {
      std::string line;
      switch (pick(12)) {
        case 0:
        case 1:
        case 2: {
          static const char* kColours[] = {"Ka", "Kd", "Ks", "Tf", "Kt"};
          line = kColours[pick(5)];
          const int values = pick(10) == 0 ? 2 : (pick(3) == 0 ? 1 : 3 + pick(2));
          for (int v = 0; v < values; ++v) line += sep() + number(unit());
          break;
        }
        case 3:
          line = "Ke" + sep() + number(unit() * 20.0f) + sep() + number(unit()) + sep() + number(unit());
          break;
        case 4:
          line = "Ns" + sep() + number(unit() * 1000.0f) + (pick(3) ? "" : sep() + "20");
          break;
        case 5:
          line = "Ni" + sep() + number(1.0f + unit());
          break;
        case 6:
          line = (pick(2) ? "d" : "Tr") + sep() + number(unit()) + (pick(3) ? "" : sep() + "illum 2");
          break;
        case 7:
          line = "illum" + sep() + std::to_string(pick(11)) + (pick(4) ? "" : ".5");
          break;
        case 8:
        case 9: {
          static const char* kMaps[] = {"map_Kd", "map_bump", "bump", "map_Bump"};
          line = kMaps[pick(4)];
          const int options = pick(4);
          for (int o = 0; o < options; ++o) {
            switch (pick(8)) {
              case 0:
                line += sep() + "-o " + number(unit()) + " " + number(unit()) + " " + number(unit());
                break;
              case 1:
                line += sep() + "-s " + number(2 * unit()) + " " + number(2 * unit()) + " 1";
                break;
              case 2:
                line += sep() + "-t 0 0 0";
                break;
              case 3:
                line += sep() + "-mm " + number(unit()) + " 1";
                break;
              case 4:
                line += sep() + "-bm " + number(unit());
                break;
              case 5:
                line += sep() + (pick(2) ? "-clamp on" : "-blendu off");
                break;
              case 6:
                line += sep() + "-imfchan r";
                break;
              default:
                line += sep() + "-texres 512";
                break;
            }
          }
          line += sep() + (pick(3) ? "tex" + std::to_string(pick(5)) + ".png" : "my tex.png");
          break;
        }
        case 10:
          line = pick(2) ? "Kd" + sep() + number(unit() + 1.5f) : "Ns" + sep() + "nan";
          break;  // refused
        default:
          line = "map_Ks" + sep() + "spec.png";
          break;  // not used by tracer
      }
      text += (pick(5) ? "" : sep()) + line + end();
    }
  }
  return text;
}

TEST(MtlDifferential, GeneratedFilesReadAsTinyobjloaderReadsThem) {
  std::mt19937 rng(20261203);
  const int files = 4000;
  int loaded = 0;
  for (int i = 0; i < files; ++i) {
    const std::string text = generated_mtl(rng);
    bool refused = false;
    const std::optional<std::string> d = oracle::mtl_disagreement(text, &refused);
    ASSERT_EQ(d, std::nullopt) << "file " << i << ":\n" << text;
    loaded += refused ? 0 : 1;
  }
  EXPECT_GT(loaded, files / 4);
  EXPECT_LT(loaded, files);  // and some are refused: the generator reaches the errors
}

}  // namespace
}  // namespace tracer
