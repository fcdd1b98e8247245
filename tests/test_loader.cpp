// Loading: the study's four scenes give the right counts, materials and light; every kind of bad
// input gives a one-line error that names the file and line.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <atomic>
#include <thread>

#include <filesystem>
#include <fstream>

#include "base/errors.hpp"
#include "importers/obj_loader.hpp"
#include "scene/builtin.hpp"
#include "scene/scene_checksum.hpp"
#include "test_util.hpp"

namespace tracer {
namespace {

struct Expected {
  const char* file;
  size_t triangles;
};

TEST(Loader, StudyScenesHaveTheRightCounts) {
  if (!test::have_shared_scenes()) GTEST_SKIP() << "../shared/scenes not present";
  for (const Expected& e : {Expected{"CornellBox-Original.obj", 36}, Expected{"CornellBox-Mirror.obj", 36},
                            Expected{"CornellBox-Sphere.obj", 2188}, Expected{"CornellBox-Water.obj", 7088}}) {
    SCOPED_TRACE(e.file);
    std::vector<std::string> warnings;
    const Scene s = load_obj(test::scene_path(std::string("cornell-box/") + e.file),
                             [&](const std::string& w) { warnings.push_back(w); });
    EXPECT_EQ(s.size(), e.triangles);
    EXPECT_EQ(s.tri_geom.size(), e.triangles);
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_GT(s.lights[0].power.x, 0.0f);
    EXPECT_NEAR(s.lights[0].position.y, 1.98f, 0.42f);  // the lamp hangs just under the ceiling
    EXPECT_GE(s.materials.size(), 7u);
    const auto light =
        std::find_if(s.materials.begin(), s.materials.end(), [](const Material& m) { return m.name == "light"; });
    ASSERT_NE(light, s.materials.end());
    EXPECT_TRUE(light->emissive());
    EXPECT_EQ(s.degenerate_count, 0u);
    // geomID and primID together name each triangle once
    for (size_t i = 0; i < s.size(); ++i) {
      const Geometry& g = s.geometries[s.tri_geom[i]];
      EXPECT_EQ(g.first_triangle + s.tri_prim[i], i);
    }
  }
}

TEST(Loader, OriginalMaterialsAreRead) {
  if (!test::have_shared_scenes()) GTEST_SKIP();
  const Scene s = load_obj(test::scene_path("cornell-box/CornellBox-Original.obj"));
  const auto red =
      std::find_if(s.materials.begin(), s.materials.end(), [](const Material& m) { return m.name == "leftWall"; });
  ASSERT_NE(red, s.materials.end());
  EXPECT_FLOAT_EQ(red->kd.x, 0.63f);
  EXPECT_FLOAT_EQ(red->kd.y, 0.065f);
  EXPECT_FLOAT_EQ(red->ni, 1.5f);
  EXPECT_EQ(red->illum, 2);
}

TEST(Loader, PolygonsNegativeIndicesAndCrlf) {
  const std::string obj = "v 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\nv 0 1 0\r\nv 0.5 1.5 0\r\ng quad\r\nf -5 -4 -3 -2 -1\r\n";
  const Scene s = load_obj_from_string(obj, "", "pentagon.obj");
  EXPECT_EQ(s.size(), 3u);  // a pentagon fans into three triangles
  EXPECT_EQ(s.geometries.size(), 1u);
  EXPECT_EQ(s.geometries[0].name, "quad");
  EXPECT_EQ(s.triangles[0].v0, (Vec3{0, 0, 0}));
}

// The parser's chunks: a text split into chunks of a few bytes must give the very scene the whole
// text gives as one chunk, whatever crosses the chunks (indices into earlier chunks, negative
// indices, a chunk mixing both, materials and groups set before it).
Scene load_in_chunks(const std::string& obj, const std::string& mtl, size_t chunk_bytes) {
  LoadLimits limits;
  limits.chunk_bytes = chunk_bytes;
  return load_obj_from_string(
      obj, mtl, "chunks.obj", [](const std::string&) {}, limits);
}

TEST(Loader, ChunksGiveTheSceneOneChunkGives) {
  const std::string mtl = "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n";
  std::string obj = "mtllib x.mtl\n";
  for (int i = 0; i < 40; ++i) {
    obj += "v " + std::to_string(i) + " " + std::to_string(i % 7) + " 0.5\nvt 0." + std::to_string(i) + " 1\n";
    obj += "vn 0 0 1\n";
    if (i % 9 == 0) obj += (i % 2 ? "usemtl red\n" : "usemtl blue\n");
    if (i % 13 == 0) obj += "g part" + std::to_string(i) + "\n";
    if (i >= 3) {
      obj += "f -1/-1/-1 -2/-2/-2 -3/-3/-3\n";                                 // relative
      obj += "f 1 " + std::to_string(i) + " " + std::to_string(i + 1) + "\n";  // absolute, into earlier chunks
      obj += "f 1//1 2//2 " + std::to_string(i + 1) + "//3 -1//-1\n";          // both in one face: a quad
    }
  }
  const Scene whole = load_in_chunks(obj, mtl, size_t(1) << 30);
  ASSERT_EQ(whole.size(), 37u * 4u);
  EXPECT_EQ(whole.geometries.size(), 4u);
  for (const size_t bytes : {1u, 7u, 64u, 300u, 4096u}) {
    SCOPED_TRACE(bytes);
    const Scene chunked = load_in_chunks(obj, mtl, bytes);
    EXPECT_EQ(scene_checksum(chunked), scene_checksum(whole));
    EXPECT_EQ(chunked.tri_geom, whole.tri_geom);
    EXPECT_EQ(chunked.tri_prim, whole.tri_prim);
    EXPECT_EQ(chunked.tri_material, whole.tri_material);
  }
}

TEST(Loader, LinesEndingInALoneCrAreReadInOnePass) {
  // 300,000 lines ended by '\r' alone: a search for each line's '\n' to the file's end would read
  // the file once per line (hours); the parser reads it once.
  std::string obj;
  for (int i = 0; i < 100000; ++i) obj += "v 0 0 0\rv 1 0 0\rf -2 -1 -2\r";
  const Scene s = load_in_chunks(obj, "", 0);
  EXPECT_EQ(s.size(), 100000u);
  EXPECT_EQ(s.vertex_count, 200000u);
}

TEST(Loader, AnErrorInALaterChunkNamesItsLine) {
  std::string obj;
  for (int i = 0; i < 500; ++i) obj += "v " + std::to_string(i) + " 0 0\n";
  obj += "f 1 2 3\nf -1 -2 -501\n";  // reaches one vertex before the first
  for (const size_t bytes : {size_t(16), size_t(1000), size_t(1) << 30}) {
    SCOPED_TRACE(bytes);
    try {
      load_in_chunks(obj, "", bytes);
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      EXPECT_STREQ(e.what(), "chunks.obj:502: vertex index -501 out of range (500 defined so far)");
    }
    try {
      load_in_chunks(obj.substr(0, obj.size() - 13) + "f 1 2 x\n", "", bytes);
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      EXPECT_STREQ(e.what(), "chunks.obj:502: malformed face index 'x'");
    }
  }
}

TEST(Loader, VertexNormalsAreKeptPerCorner) {
  // Two triangles, one with normals (given out of order) and one without: zero where none.
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 1 0\nf 1//2 2//1 3//1\nf 1 2 3\n";
  const Scene s = load_obj_from_string(obj, "", "normals.obj");
  ASSERT_EQ(s.corner_normals.size(), 6u);
  EXPECT_EQ(s.corner_normals[0], (Vec3{0, 1, 0}));
  EXPECT_EQ(s.corner_normals[1], (Vec3{0, 0, 1}));
  EXPECT_EQ(s.corner_normals[5], (Vec3{0.0f}));
  EXPECT_TRUE(load_obj_from_string("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "", "none.obj").corner_normals.empty());
}

TEST(Loader, GroupsBecomeGeometries) {
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\ng a\nf 1 2 3\ng b\nf 1 2 3\nf 3 2 1\n";
  const Scene s = load_obj_from_string(obj, "", "groups.obj");
  ASSERT_EQ(s.geometries.size(), 2u);
  EXPECT_EQ(s.tri_geom[2], 1u);
  EXPECT_EQ(s.tri_prim[2], 1u);
}

TEST(Loader, EmissiveMaterialMakesOneLightPerGeometry) {
  const std::string obj = "mtllib x.mtl\nv 0 1 0\nv 1 1 0\nv 1 1 1\nv 0 1 1\ng lamp\nusemtl glow\nf 1 2 3 4\n";
  const std::string mtl = "newmtl glow\nKd 0.5 0.5 0.5\nKe 2 3 4\n";
  const Scene s = load_obj_from_string(obj, mtl, "lamp.obj");
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_NEAR(s.lights[0].position.x, 0.5f, 1e-6f);
  EXPECT_NEAR(s.lights[0].position.z, 0.5f, 1e-6f);
  EXPECT_NEAR(s.lights[0].area, 1.0f, 1e-6f);
  EXPECT_NEAR(s.lights[0].power.y, 3.0f, 1e-5f);
}

struct BadObj {
  const char* name;
  const char* text;
  const char* message;  // must appear in the error
};

TEST(Loader, BadInputsGiveOneLineErrorsWithLine) {
  const BadObj cases[] = {
      {"nan", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", "bad.obj:2: non-finite coordinate 'nan'"},
      {"inf", "v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n", "bad.obj:3: non-finite coordinate 'inf'"},
      {"short_vertex", "v 0 0\n", "bad.obj:1: 'v' needs 3 numbers, got 2"},
      {"garbage_number", "v 0 0 x1\n", "bad.obj:1: malformed number 'x1'"},
      {"index_too_big", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
       "bad.obj:4: vertex index 4 out of range (3 defined so far)"},
      {"index_zero", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "bad.obj:4: vertex index 0 out of range"},
      {"negative_too_far", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n", "bad.obj:4: vertex index -4 out of range"},
      {"forward_reference", "v 0 0 0\nf 1 2 3\nv 1 0 0\nv 0 1 0\n", "bad.obj:2: vertex index 2 out of range"},
      {"normal_out_of_range", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n",
       "bad.obj:5: normal index 2 out of range"},
      {"two_corner_face", "v 0 0 0\nv 1 0 0\nf 1 2\n", "bad.obj:3: face needs at least 3 vertices, got 2"},
      {"bad_face_token", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 a\n", "bad.obj:4: malformed face index 'a'"},
      {"no_triangles", "v 0 0 0\nv 1 0 0\n", "bad.obj: scene has no triangles"},
      {"empty_file", "", "bad.obj: scene has no triangles"},
      {"huge_number", "v 0 0 1e999\n", "bad.obj:1: number out of range '1e999'"},
      {"beyond_supported_range", "v 0 0 1.0001e12\n",
       "bad.obj:1: number out of range '1.0001e12' (coordinates must lie within +-1e12)"},
      // A lone CR ends a line: the vertex after it is a line of its own, checked.
      {"cr_inside_comment", "# c\rv 1e39 0 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf -3 -2 -1\n",
       "bad.obj:2: number out of range '1e39'"},
      {"cr_only_lines", "v 0 0 0\rv 1 0 0\rf 1 2 3\r", "bad.obj:3: vertex index 3 out of range (2 defined so far)"},
      {"control_character", "v 0 0 0\nv 1\x01 0 0\n", "bad.obj:2: malformed number '1\\x01'"},
      {"zero_line_index", "v 0 0 0\nv 1 0 0\nl 0 1\n", "bad.obj:3: "},
  };
  for (const BadObj& c : cases) {
    SCOPED_TRACE(c.name);
    try {
      load_obj_from_string(c.text, "", "bad.obj", [](const std::string&) {});
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(c.message), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << "not one line: " << what;
    }
  }
}

TEST(Loader, UnusualButValidInputIsAccepted) {
  // A UTF-8 byte-order mark, a leading '+', exponents that underflow to zero, CR-only line ends.
  const std::string obj = "\xEF\xBB\xBFv 0 0 0\rv +1 0 1e-50\rv 0 1 1e-400\rf 1 +2 -1\r";
  const Scene s = load_obj_from_string(obj, "", "unusual.obj");
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s.triangles[0].v1, (Vec3{1, 0, 0}));
  EXPECT_EQ(s.triangles[0].v2, (Vec3{0, 1, 0}));
  EXPECT_EQ(s.vertex_count, 3u);
  // A BOM in the MTL too: the material's name is read without it.
  const Scene m = load_obj_from_string("mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n",
                                       "\xEF\xBB\xBFnewmtl red\nKd 1 0 0\n", "bom.obj",
                                       [](const std::string& w) { ADD_FAILURE() << w; });
  EXPECT_EQ(m.materials[m.tri_material[0]].name, "red");
}

TEST(Loader, ManyWarningsOfOneKindMakeOneLine) {
  std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  for (int i = 0; i < 20000; ++i) obj += "usemtl undefined" + std::to_string(i) + "\nf 1 2 3\n";
  std::vector<std::string> warnings;
  const Scene s = load_obj_from_string(obj, "", "many.obj", [&](const std::string& w) { warnings.push_back(w); });
  EXPECT_EQ(s.size(), 20000u);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("undefined0"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("20000 times"), std::string::npos) << warnings[0];
}

TEST(Loader, ReadsPipesAndNamesTheRealCauseOfOpenErrors) {
  const std::string dir = test::temp_dir();
  std::ofstream(dir + "/t.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  // A FIFO is read once, as it streams (opening it twice would hang).
  const std::string fifo = dir + "/fifo.obj";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::thread writer([&] { std::ofstream(fifo) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"; });
  const Scene s = load_obj(fifo);
  writer.join();
  EXPECT_EQ(s.size(), 1u);
  std::filesystem::create_symlink(dir + "/loop-a", dir + "/loop-b");
  std::filesystem::create_symlink(dir + "/loop-b", dir + "/loop-a");
  try {
    load_obj(dir + "/loop-a");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot open: too many levels of symbolic links"), std::string::npos)
        << e.what();
  }
  try {
    load_obj(dir);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot open: is a directory"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

TEST(Loader, CancelFlagStopsTheLoad) {
  const std::string dir = test::temp_dir();
  std::ofstream(dir + "/t.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  std::atomic<bool> cancel{true};
  EXPECT_THROW(load_obj(dir + "/t.obj", {}, &cancel), Cancelled);
  std::filesystem::remove_all(dir);
}

TEST(Loader, MissingFileAndDirectory) {
  EXPECT_THROW(load_obj("/nonexistent/scene.obj"), InputError);
  EXPECT_THROW(load_obj(std::filesystem::temp_directory_path().string()), InputError);
  try {
    load_obj("/nonexistent/scene.obj");
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "/nonexistent/scene.obj: cannot open: no such file");
  }
}

TEST(Loader, MissingMtlAndTexturesWarnAndFallBack) {
  const std::string dir = test::temp_dir();
  {
    std::ofstream(dir + "/a.obj") << "mtllib missing.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n";
    std::ofstream(dir + "/b.obj") << "mtllib b.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl t\nf 1 2 3\n";
    std::ofstream(dir + "/b.mtl") << "newmtl t\nKd 0.1 0.2 0.3\nmap_Kd nowhere.png\n";
  }
  std::vector<std::string> warnings;
  const auto sink = [&](const std::string& w) { warnings.push_back(w); };
  const Scene a = load_obj(dir + "/a.obj", sink);
  ASSERT_FALSE(warnings.empty());
  EXPECT_NE(warnings[0].find("missing.mtl"), std::string::npos) << warnings[0];
  EXPECT_EQ(a.size(), 1u);
  EXPECT_EQ(a.materials[a.tri_material[0]].name, "default");
  warnings.clear();
  const Scene b = load_obj(dir + "/b.obj", sink);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("nowhere.png"), std::string::npos);
  EXPECT_FLOAT_EQ(b.materials[b.tri_material[0]].kd.z, 0.3f);
  std::filesystem::remove_all(dir);
}

TEST(Loader, BuiltinCornellBox) {
  const Scene plain = make_cornell_box(0);
  EXPECT_EQ(plain.size(), 32u);  // 5 walls, lamp, 2 blocks of 5 faces: 16 quads
  ASSERT_EQ(plain.lights.size(), 1u);
  EXPECT_TRUE(plain.camera.has_value());
  const Scene spheres = make_cornell_box(1000);
  EXPECT_GT(spheres.size(), 32u + 2 * 800u);
  EXPECT_LT(spheres.size(), 32u + 2 * 1200u);
  EXPECT_EQ(spheres.degenerate_count, 0u);
}

}  // namespace
}  // namespace tracer
