// glTF 2.0 and PLY scenes: the OBJ scenes of ../shared converted (tests/scene_writers.hpp) load
// as the same triangles and render the same images; node transforms, cameras, materials and
// normal maps as docs/FORMATS.md says; every hostile file fails with one line naming it.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "frontend/render_args.hpp"
#include "frontend/scene_setup.hpp"
#include "importers/gltf_loader.hpp"
#include "importers/obj_loader.hpp"
#include "importers/ply_loader.hpp"
#include "importers/scene_file.hpp"
#include "io/image_io.hpp"
#include "render/lights.hpp"
#include "scene_writers.hpp"
#include "shade/material_bsdf.hpp"
#include "shade/texture_lookup.hpp"
#include "test_util.hpp"

namespace tracer {
namespace {

namespace fs = std::filesystem;

using test::base64;
using test::bytes_of;

// One triangle in a glTF of a data: URI buffer (positions then uint16 indices); `patch` edits the
// JSON text (a node's transform, a count) before it is loaded.
struct TinyGltf {
  std::string positions = bytes_of<float>({0, 0, 0, 1, 0, 0, 0, 1, 0});
  std::string indices = bytes_of<uint16_t>({0, 1, 2, 0});
  std::string node = R"({"mesh": 0})";
  std::string extra_nodes;
  std::string position_count = "3";
  std::string index_count = "3";
  std::string buffer_uri;  // empty: the data: URI
  std::string extra;       // more top-level members, each followed by a comma
  std::string material = R"({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 1, 1], "metallicFactor": 0}})";
  std::string json() const {
    const std::string data = positions + indices;
    const std::string uri = buffer_uri.empty() ? "data:application/octet-stream;base64," + base64(data) : buffer_uri;
    return R"({"asset": {"version": "2.0"}, )" + extra + R"("scene": 0, "scenes": [{"nodes": [0]}],
      "nodes": [)" +
           node + extra_nodes + R"(],
      "meshes": [{"name": "tri", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
      "materials": [)" +
           material + R"(],
      "buffers": [{"uri": ")" +
           uri + R"(", "byteLength": )" + std::to_string(data.size()) + R"(}],
      "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                      {"buffer": 0, "byteOffset": 36, "byteLength": 8}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": )" +
           position_count + R"(, "type": "VEC3",
                     "min": [0, 0, 0], "max": [1, 1, 0]},
                    {"bufferView": 1, "componentType": 5123, "count": )" +
           index_count + R"(, "type": "SCALAR"}]})";
  }
};

using test::gltf_load_error;

TEST(Gltf, OneTriangleLoadsWithItsMaterial) {
  const Scene s = load_gltf_from_memory(TinyGltf{}.json(), "t.gltf");
  ASSERT_EQ(s.triangles.size(), 1u);
  EXPECT_EQ(s.triangles[0].v1, (Vec3{1, 0, 0}));
  ASSERT_EQ(s.materials.size(), 1u);
  // The metallic-roughness BRDF: a dielectric (metallicFactor 0), roughness 1 (the default).
  const Material& m = s.materials[0];
  EXPECT_EQ(m.surface(), SurfaceKind::MetallicRoughness);
  EXPECT_EQ(m.kd, (Vec3{0.5f, 0.25f, 1.0f}));
  EXPECT_EQ(m.metallic, 0.0f);
  EXPECT_EQ(m.roughness, 1.0f);
  EXPECT_NEAR(m.specular_f0.x, 0.04f, 1e-7f);
  EXPECT_EQ(m.specular_f90, 1.0f);
}

// TinyGltf's triangle with a COLOR_0 of normalised unsigned bytes (VEC4) after its indices, the
// accessor's members besides those given by `members`.
std::string coloured_gltf(const std::string& members = R"("normalized": true)") {
  TinyGltf g;
  g.indices += bytes_of<uint8_t>({255, 51, 0, 255, 255, 51, 0, 128, 0, 0, 255, 7});
  std::string json = g.json();
  const auto replace = [&](const std::string& from, const std::string& to) {
    json.replace(json.find(from), from.size(), to);
  };
  replace(R"("attributes": {"POSITION": 0})", R"("attributes": {"POSITION": 0, "COLOR_0": 2})");
  replace(R"({"buffer": 0, "byteOffset": 36, "byteLength": 8}])",
          R"({"buffer": 0, "byteOffset": 36, "byteLength": 8}, {"buffer": 0, "byteOffset": 44, "byteLength": 12}])");
  replace(
      R"("type": "SCALAR"}]})",
      R"("type": "SCALAR"}, {"bufferView": 2, "componentType": 5121, "count": 3, "type": "VEC4", )" + members + "}]}");
  return json;
}

TEST(Gltf, VertexColoursMultiplyTheBaseColour) {
  const Scene s = load_gltf_from_memory(coloured_gltf(), "t.gltf");
  ASSERT_EQ(s.corner_colors.size(), 3u);
  EXPECT_EQ(s.corner_colors[0], (Vec3{1.0f, 0.2f, 0.0f}));  // linear, as glTF stores them; alpha unread
  Hit hit;
  hit.tri = 0;
  const MaterialPoint p = material_point(s, hit, s.materials[0]);  // at corner 0
  EXPECT_NEAR(p.color.x, 0.5f, 1e-6f);
  EXPECT_NEAR(p.color.y, 0.25f * 0.2f, 1e-6f);
  EXPECT_EQ(p.color.z, 0.0f);
  // Integers must be normalised (the specification's COLOR_0 types).
  EXPECT_EQ(gltf_load_error(coloured_gltf(R"("normalized": false)")),
            "t.gltf: mesh 0 'tri' primitive 0 COLOR_0 (accessor 2): not VEC3 or VEC4 of floats or normalised "
            "unsigned bytes or shorts");
}

// KHR_lights_punctual: a point, a spot and a directional light on child nodes of the triangle's,
// the spot and the directional turned to shine down (-90 degrees about x takes -z to -y).
TinyGltf lights_gltf(const std::string& spot_cone = R"("innerConeAngle": 0.2, "outerConeAngle": 0.5)") {
  TinyGltf g;
  g.extra = R"("extensionsUsed": ["KHR_lights_punctual"], "extensions": {"KHR_lights_punctual": {"lights": [
      {"type": "point", "color": [1, 0.5, 0.25], "intensity": 683},
      {"type": "spot", "intensity": 1366, "spot": {)" +
            spot_cone + R"(}},
      {"type": "directional", "intensity": 68.3}]}}, )";
  g.node = R"({"mesh": 0, "children": [1, 2, 3]})";
  const std::string down = R"("rotation": [-0.70710678, 0, 0, 0.70710678])";
  g.extra_nodes = R"(, {"translation": [0, 3, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
      {"translation": [0, 2, 0], )" +
                  down + R"(, "extensions": {"KHR_lights_punctual": {"light": 1}}},
      {)" + down + R"(, "extensions": {"KHR_lights_punctual": {"light": 2}}})";
  return g;
}

TEST(Gltf, PointSpotAndDirectionalLightsInTracersUnits) {
  const Scene s = load_gltf_from_memory(lights_gltf().json(), "t.gltf");
  ASSERT_EQ(s.lights.size(), 3u);
  // Candela and lux over 683 lm/W (Blender's importer's conversion).
  EXPECT_EQ(s.lights[0].kind, LightKind::Point);
  EXPECT_NEAR(s.lights[0].power.y, 0.5f, 1e-6f);
  const Light& spot = s.lights[1];
  EXPECT_EQ(spot.kind, LightKind::Spot);
  EXPECT_NEAR(spot.power.x, 2.0f, 1e-6f);
  EXPECT_NEAR(spot.normal.y, -1.0f, 1e-6f);
  EXPECT_NEAR(spot.cos_inner, std::cos(0.2f), 1e-6f);
  EXPECT_NEAR(spot.cos_outer, std::cos(0.5f), 1e-6f);
  const Light& sun = s.lights[2];
  EXPECT_EQ(sun.kind, LightKind::Directional);
  EXPECT_NEAR(sun.power.z, 0.1f, 1e-6f);
  EXPECT_NEAR(sun.normal.y, -1.0f, 1e-6f);
  // What a point below sees: inside the inner cone all of the spot, between the cones the
  // specification's smooth square ramp, outside nothing; the sun from straight above at any
  // distance, and nothing on a surface facing away.
  SurfaceInteraction si{};
  si.n = si.shading_n = Vec3{0.0f, 1.0f, 0.0f};
  si.geomID = si.inst = kInvalidIndex - 1;
  LightSample ls;
  ASSERT_TRUE(sample_lamp(spot, si, ls));
  EXPECT_NEAR(ls.falloff, 1.0f / 4.0f, 1e-6f);
  const float angle = 0.35f;  // between the cones
  si.origin = Vec3{2.0f * std::tan(angle), 0.0f, 0.0f};
  ASSERT_TRUE(sample_lamp(spot, si, ls));
  const float t = (std::cos(angle) - std::cos(0.5f)) / (std::cos(0.2f) - std::cos(0.5f));
  EXPECT_NEAR(ls.falloff, t * t * std::cos(angle) * std::cos(angle) / 4.0f, 1e-5f);
  si.origin = Vec3{2.0f * std::tan(0.55f), 0.0f, 0.0f};
  EXPECT_FALSE(sample_lamp(spot, si, ls));
  ASSERT_TRUE(sample_lamp(sun, si, ls));
  EXPECT_NEAR(ls.wi.y, 1.0f, 1e-6f);
  EXPECT_EQ(ls.falloff, 1.0f);
  EXPECT_EQ(ls.distance, kInfinity);
  si.n = Vec3{0.0f, -1.0f, 0.0f};
  EXPECT_FALSE(sample_lamp(sun, si, ls));
  // Cone angles outside the specification's range are an error naming the light.
  EXPECT_EQ(gltf_load_error(lights_gltf(R"("innerConeAngle": 0.5, "outerConeAngle": 0.5)").json()),
            "t.gltf: light 1: spot cone angles inner 0.5, outer 0.5 (the specification's 0 <= inner < outer <= "
            "pi/2)");
}

TEST(Gltf, NodeTransformsComposeAndAMirrorKeepsTheFrontFace) {
  TinyGltf g;
  // Parent: translate by (10, 0, 0); child: scale x by -2 (a mirror) and rotate 90 degrees about z.
  const double h = std::sqrt(0.5);
  g.node = R"({"translation": [10, 0, 0], "children": [1]})";
  g.extra_nodes =
      R"(, {"mesh": 0, "scale": [-2, 1, 1], "rotation": [0, 0, )" + std::to_string(h) + ", " + std::to_string(h) + "]}";
  const Scene s = load_gltf_from_memory(g.json(), "t.gltf");
  ASSERT_EQ(s.triangles.size(), 1u);
  const Triangle& t = s.triangles[0];
  // R(90 about z) * S(-2,1,1): (1,0,0) -> (-2,0,0) -> (0,-2,0); (0,1,0) -> (0,1,0) -> (-1,0,0).
  // The mirror swaps the second and third corners.
  EXPECT_NEAR(t.v0.x, 10.0f, 1e-5f);
  EXPECT_NEAR(t.v2.x, 10.0f, 1e-5f);
  EXPECT_NEAR(t.v2.y, -2.0f, 1e-5f);
  EXPECT_NEAR(t.v1.x, 9.0f, 1e-5f);
  EXPECT_NEAR(t.v1.y, 0.0f, 1e-5f);
  // The source triangle faces +z; rotated and mirrored, its front still faces +z.
  EXPECT_GT(t.normal().z, 0.0f);
}

TEST(Gltf, ACameraNodeIsTheDefaultCameraAndCameraPicksAnother) {
  TinyGltf g;
  g.extra = R"("cameras": [{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}},
                          {"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.1}}], )";
  // Camera 0 at (0,0,5) looking down -z; camera 1 at (5,0,0) turned 90 degrees about y (looks down -x).
  const double h = std::sqrt(0.5);
  g.node = R"({"mesh": 0, "children": [1, 2]})";
  g.extra_nodes = R"(, {"camera": 0, "translation": [0, 0, 5]}, {"camera": 1, "translation": [5, 0, 0],
                    "rotation": [0, )" +
                  std::to_string(h) + ", 0, " + std::to_string(h) + "]}";
  const Scene s = load_gltf_from_memory(g.json(), "t.gltf");
  ASSERT_EQ(s.cameras.size(), 2u);
  ASSERT_TRUE(s.camera);
  EXPECT_EQ(s.camera->eye, (Vec3{0, 0, 5}));
  EXPECT_NEAR(s.camera->fov_degrees, 0.5 * 180.0 / std::numbers::pi, 1e-4);
  const Vec3 d = normalize(s.cameras[1].look - s.cameras[1].eye);
  EXPECT_NEAR(d.x, -1.0f, 1e-6f);
  EXPECT_NEAR(s.cameras[1].up.y, 1.0f, 1e-6f);
  // The look-at point (the default focus) lies level with the scene's centre along the view.
  EXPECT_NEAR(s.camera->look.z, s.bounds.center().z, 1e-5f);

  const std::string dir = test::temp_dir();
  std::ofstream(dir + "/cams.gltf") << g.json();
  const auto ok =
      test::run_tracer("render " + dir + "/cams.gltf -q --camera 1 --width 8 --height 8 -o " + dir + "/a.ppm");
  EXPECT_EQ(ok.exit_code, 0) << ok.output;
  const auto bad =
      test::run_tracer("render " + dir + "/cams.gltf -q --camera 2 --width 8 --height 8 -o " + dir + "/b.ppm");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.output.find("--camera: 2 is not one of the scene's 2 cameras (0 to 1)"), std::string::npos)
      << bad.output;
  EXPECT_FALSE(fs::exists(dir + "/b.ppm"));
  fs::remove_all(dir);
}

TEST(Gltf, MetallicRoughnessMapsAsDocumented) {
  TinyGltf g;
  g.material = R"({"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.6, 0.4, 1], "metallicFactor": 1,
                   "roughnessFactor": 0}})";
  Scene s = load_gltf_from_memory(g.json(), "t.gltf");
  EXPECT_EQ(s.materials[0].surface(), SurfaceKind::Mirror);
  EXPECT_EQ(s.materials[0].ks, (Vec3{0.8f, 0.6f, 0.4f}));
  g.material = R"({"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.6, 0.4, 1], "metallicFactor": 0.5,
                   "roughnessFactor": 0.5}})";
  s = load_gltf_from_memory(g.json(), "t.gltf");
  EXPECT_EQ(s.materials[0].surface(), SurfaceKind::MetallicRoughness);
  EXPECT_EQ(s.materials[0].kd, (Vec3{0.8f, 0.6f, 0.4f}));  // the BRDF mixes metal and dielectric itself
  EXPECT_EQ(s.materials[0].metallic, 0.5f);
  EXPECT_EQ(s.materials[0].roughness, 0.5f);
  // KHR_materials_specular: F0 = 0.04 x colour x factor, F90 = the factor.
  g.extra = R"("extensionsUsed": ["KHR_materials_specular"], )";
  g.material = R"({"pbrMetallicRoughness": {"metallicFactor": 0}, "extensions": {"KHR_materials_specular":
                   {"specularFactor": 0.5, "specularColorFactor": [1, 0.5, 2]}}})";
  s = load_gltf_from_memory(g.json(), "t.gltf");
  EXPECT_NEAR(s.materials[0].specular_f0.x, 0.02f, 1e-7f);
  EXPECT_NEAR(s.materials[0].specular_f0.y, 0.01f, 1e-7f);
  EXPECT_NEAR(s.materials[0].specular_f0.z, 0.04f, 1e-7f);
  EXPECT_EQ(s.materials[0].specular_f90, 0.5f);
  g.extra =
      R"("extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_emissive_strength"], )";
  g.material = R"({"pbrMetallicRoughness": {"baseColorFactor": [1, 0.9, 0.8, 1], "roughnessFactor": 0},
                   "emissiveFactor": [1, 0.5, 0], "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                   "KHR_materials_ior": {"ior": 1.33}, "KHR_materials_emissive_strength": {"emissiveStrength": 4}}})";
  s = load_gltf_from_memory(g.json(), "t.gltf");
  EXPECT_EQ(s.materials[0].surface(), SurfaceKind::Dielectric);
  EXPECT_FLOAT_EQ(s.materials[0].ni, 1.33f);
  EXPECT_EQ(s.materials[0].tf, (Vec3{1.0f, 0.9f, 0.8f}));
  EXPECT_EQ(s.materials[0].ke, (Vec3{4.0f, 2.0f, 0.0f}));
}

TEST(Gltf, WhatCannotBeRenderedIsOneWarningEach) {
  TinyGltf g;
  g.extra = R"("extensionsUsed": ["EXT_unknown_thing", "KHR_materials_transmission"], "animations": [], )";
  g.material = R"({"alphaMode": "BLEND", "pbrMetallicRoughness": {"roughnessFactor": 0},
                   "extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.5}}})";
  std::vector<std::string> warnings;
  load_gltf_from_memory(g.json(), "t.gltf", [&](const std::string& w) { warnings.push_back(w); });
  ASSERT_EQ(warnings.size(), 3u);
  EXPECT_NE(warnings[0].find("t.gltf: extension 'EXT_unknown_thing' is not supported: ignored"), std::string::npos);
  EXPECT_NE(warnings[1].find("alpha"), std::string::npos);
  EXPECT_NE(warnings[2].find("partial transmission rendered as full transmission"), std::string::npos);
}

TEST(Gltf, HostileFilesFailWithOneLineNamingTheFile) {
  struct Case {
    const char* what;
    TinyGltf g;
    const char* expect;
  };
  std::vector<Case> cases;
  {
    TinyGltf g;
    g.index_count = "1000000000";
    cases.push_back({"a huge count with little data", g,
                     "t.gltf: mesh 0 'tri' primitive 0 indices (accessor 1): 1000000000 elements run past the end of "
                     "buffer view 1"});
  }
  {
    TinyGltf g;
    g.indices = bytes_of<uint16_t>({0, 1, 7, 0});
    cases.push_back(
        {"an index out of range", g, "t.gltf: mesh 0 'tri' primitive 0: index 7 out of range (3 vertices)"});
  }
  {
    TinyGltf g;
    g.node = R"({"mesh": 0, "children": [1]})";
    g.extra_nodes = R"(, {"children": [0]})";
    cases.push_back({"a cycle of nodes", g, "t.gltf: node 0 is its own ancestor"});
  }
  {
    // 40 levels, each naming the next twice: 2^40 instances of the triangle in a few hundred bytes
    // (with a memory limit, refused by it first: the reliability table's row).
    TinyGltf g;
    g.node = R"({"mesh": 0, "children": [1, 1]})";
    for (int i = 1; i < 40; ++i)
      g.extra_nodes += ", {\"mesh\": 0, \"children\": [" + std::to_string(i + 1) + ", " + std::to_string(i + 1) + "]}";
    g.extra_nodes += R"(, {"mesh": 0})";
    cases.push_back({"instances that expand without bound", g,
                     "t.gltf: its nodes, children of more than one parent, expand to more than 2097193 node instances, "
                     "more than tracer walks"});
  }
  {
    // The same with a camera at the bottom and no mesh below the root: no memory to estimate,
    // but 2^40 cameras to place.
    TinyGltf g;
    g.extra = R"("cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}], )";
    g.node = R"({"mesh": 0, "children": [1, 1]})";
    for (int i = 1; i < 40; ++i)
      g.extra_nodes += ", {\"children\": [" + std::to_string(i + 1) + ", " + std::to_string(i + 1) + "]}";
    g.extra_nodes += R"(, {"camera": 0})";
    cases.push_back({"cameras that expand without bound", g,
                     "t.gltf: its nodes, children of more than one parent, expand to more than 2097193 node "
                     "instances, more than tracer walks"});
  }
  {
    TinyGltf g;
    g.node = R"({"mesh": 5})";
    cases.push_back({"a mesh that does not exist", g, "t.gltf: mesh 5 does not exist (the file has 1)"});
  }
  {
    TinyGltf g;
    g.extra =
        R"("extensionsUsed": ["KHR_draco_mesh_compression"], "extensionsRequired": ["KHR_draco_mesh_compression"], )";
    cases.push_back({"a required extension", g,
                     "t.gltf: requires extension 'KHR_draco_mesh_compression', which tracer does not support"});
  }
  {
    TinyGltf g;
    g.positions = bytes_of<float>({0, 0, 0, 1, 0, 0, 0, 1e30f, 0});
    cases.push_back({"a vertex out of range", g,
                     "t.gltf: mesh 0 'tri' primitive 0 POSITION: vertex 2 is not finite or lies beyond +-1e12"});
  }
  {
    TinyGltf g;
    g.buffer_uri = "../../etc/passwd";
    cases.push_back({"an external buffer from memory", g, "t.gltf: "});
  }
  for (const Case& c : cases) {
    const std::string e = gltf_load_error(c.g.json());
    EXPECT_EQ(e.rfind(c.expect, 0), 0u) << c.what << ": " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << c.what << ": " << e;
  }
  EXPECT_EQ(gltf_load_error("{ not json").rfind("t.gltf: ", 0), 0u);
  EXPECT_EQ(gltf_load_error("glTF\x02\0\0\0\xff\xff\xff\x7f").rfind("t.gltf: ", 0), 0u);
}

// What tinygltf would read as absent, or let through, is named: the property, its value and why.
TEST(Gltf, WronglyTypedOrOutOfRangePropertiesAreNamed) {
  const auto with = [](std::string from, const std::string& old, const std::string& replacement) {
    const size_t at = from.find(old);
    EXPECT_NE(at, std::string::npos) << old;
    return at == std::string::npos ? from : from.replace(at, old.size(), replacement);
  };
  const std::string base = TinyGltf{}.json();
  const auto node = [](const std::string& n) {
    TinyGltf g;
    g.node = n;
    return g.json();
  };
  const auto top = [](const std::string& e) {
    TinyGltf g;
    g.extra = e;
    return g.json();
  };
  const std::string deep = std::string(20000, '[') + std::string(20000, ']');
  const std::string camera = R"("cameras": [{"type": "perspective", "perspective": )";
  const std::pair<std::string, std::string> cases[] = {
      {top(R"("extras": )" + deep + ", "), "t.gltf: its JSON nests deeper than 256 levels (at byte "},
      {with(base, R"("bufferView": 0, )", R"("bufferView": 0, "byteOffset": -12, )"),
       "t.gltf: accessors[0].byteOffset: -12 is not a non-negative integer"},
      {with(base, R"("bufferView": 0, )", R"("bufferView": 0, "byteOffset": 1.5, )"),
       "t.gltf: accessors[0].byteOffset: 1.5 is not a non-negative integer"},
      {top(R"("extensionsRequired": "KHR_materials_ior", )"),
       "t.gltf: extensionsRequired: \"KHR_materials_ior\" is not an array"},
      {node(R"({"mesh": 0, "scale": ["nan", 1, 1]})"), "t.gltf: nodes[0].scale[0]: \"nan\" is not a finite number"},
      {node(R"({"mesh": 0, "matrix": [1, 0, 0]})"), "t.gltf: nodes[0].matrix: 3 numbers, not 16"},
      {node(R"({"mesh": 0, "matrix": [1, 0, 0, 0.5, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]})"),
       "t.gltf: nodes[0].matrix: not affine (its last row is not 0 0 0 1)"},
      {with(base, R"("scene": 0)", R"("scene": 5)"), "t.gltf: scene: 5 names no scene (the file has 1)"},
      {with(base, R"("scene": 0)", R"("scene": -5)"), "t.gltf: scene: -5 is not a non-negative integer"},
      {with(base, R"("componentType": 5126)", R"("componentType": 5125)"),
       "t.gltf: mesh 0 'tri' primitive 0 POSITION (accessor 0): component type 5125 (UNSIGNED_INT) is not allowed"},
      {with(base, R"("byteLength": 44})", R"("byteLength": 50})"),
       "t.gltf: buffers[0]: its data: URI holds 44 bytes, its byteLength says 50"},
      {node(R"({"mesh": 0, "camera": 0})").replace(0, 1, "{" + camera + R"({"znear": 0.1}}], )"),
       "t.gltf: cameras[0].perspective.yfov: missing"},
      {node(R"({"mesh": 0, "camera": 0})").replace(0, 1, "{" + camera + R"({"yfov": 1e300, "znear": 0.1}}], )"),
       "t.gltf: camera 0: yfov 1e+300 ("},
      {node(R"({"mesh": 0, "camera": 0})").replace(0, 1, "{" + camera + R"({"yfov": 1e-30, "znear": 0.1}}], )"),
       "t.gltf: camera 0: yfov 1e-30 (5.72958e-29 degrees) is not in [0.001, 179] degrees"},
  };
  for (const auto& [json, expect] : cases) {
    const std::string e = gltf_load_error(json);
    EXPECT_EQ(e.rfind(expect, 0), 0u) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
  // One rule per quantity: glTF's emission is held to MTL's limit for Ke.
  TinyGltf bright;
  bright.extra = R"("extensionsUsed": ["KHR_materials_emissive_strength"], )";
  bright.material =
      R"({"emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 1e38}}})";
  EXPECT_EQ(gltf_load_error(bright.json())
                .rfind("t.gltf: material 'material 0': emission 1e+38 (emissiveFactor x "
                       "emissiveStrength) above 1e+06",
                       0),
            0u)
      << gltf_load_error(bright.json());
  // A GLB of another version than 2.
  for (const uint32_t version : {1u, 3u}) {
    std::string glb = "glTF";
    glb.append(reinterpret_cast<const char*>(&version), 4);
    glb += std::string(12, '\0');
    EXPECT_EQ(gltf_load_error(glb),
              "t.gltf: GLB version " + std::to_string(version) + ": tracer reads glTF 2.0 (version 2)");
  }
  // A perspective camera without the znear tracer never uses loads, with a warning.
  std::vector<std::string> warnings;
  const std::string no_znear = node(R"({"mesh": 0, "camera": 0})").replace(0, 1, "{" + camera + R"({"yfov": 0.8}}], )");
  const Scene s = load_gltf_from_memory(no_znear, "t.gltf", [&](const std::string& w) { warnings.push_back(w); });
  EXPECT_EQ(s.cameras.size(), 1u);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("cameras[0].perspective: no znear"), std::string::npos) << warnings[0];
}

// Buffer URIs that name no file inside the folder say so, whether or not such a file exists.
TEST(Gltf, AbsoluteSchemeAndShellUrisAreRefusedAsSuch) {
  const std::string root = test::temp_dir();
  for (const std::string uri : {"/dev/zero", "/proc/self/environ", "file:///etc/passwd", "~/x.bin", "$HOME/x.bin"}) {
    TinyGltf g;
    g.buffer_uri = uri;
    std::ofstream(root + "/t.gltf") << g.json();
    std::string e;
    try {
      load_gltf(root + "/t.gltf");
    } catch (const InputError& error) {
      e = error.what();
    }
    EXPECT_NE(e.find("buffers[0].uri: '" + uri + "' is refused: a URI names a file inside the scene's folder"),
              std::string::npos)
        << e;
  }
  fs::remove_all(root);
}

// tracer info counts a glTF's nodes once however often they are reached: the counts and bounds
// of the loaded scene, and 2^40 instances are counted, not placed.
TEST(Gltf, InfoCountsEachNodeOnceAndAgreesWithTheLoad) {
  const std::string dir = test::temp_dir();
  TinyGltf g;
  // Node 2 is reached by three paths (from the root, and through nodes 1 and 3), each placing
  // it elsewhere (coincident placements are placed once: CoincidentPlacementsArePlacedOnce).
  g.node = R"({"children": [1, 3, 2]})";
  g.extra_nodes = R"(, {"mesh": 0, "translation": [2, 0, 0], "children": [2]}, {"mesh": 0, "scale": [1, 3, 1]},
                     {"mesh": 0, "translation": [-2, 0, 0], "children": [2]})";
  std::ofstream(dir + "/i.gltf") << g.json();
  LoadLimits flat;
  flat.keep_instances = false;
  const Scene s = load_gltf(dir + "/i.gltf", {}, nullptr, flat);
  const Scene kept = load_gltf(dir + "/i.gltf");
  ASSERT_TRUE(kept.instanced());
  const auto info = test::run_tracer("info " + dir + "/i.gltf");
  EXPECT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("triangles   " + std::to_string(s.size()) + " (0 degenerate)"), std::string::npos)
      << info.output;
  EXPECT_NE(info.output.find("vertices    " + std::to_string(s.vertex_count)), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("geometries  " + std::to_string(s.geometries.size())), std::string::npos) << info.output;
  char bounds[128];
  std::snprintf(bounds, sizeof bounds, "bounds      (%g, %g, %g) - (%g, %g, %g)", s.bounds.lo.x, s.bounds.lo.y,
                s.bounds.lo.z, s.bounds.hi.x, s.bounds.hi.y, s.bounds.hi.z);
  EXPECT_NE(info.output.find(bounds), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("placed by 5 instances of 1 meshes holding 1 unique"), std::string::npos) << info.output;
  EXPECT_EQ(kept.instanced_size(), s.size());
  EXPECT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept.instances.size(), 5u);
  // 40 levels each naming the next twice: counted, not expanded (a render refuses it).
  TinyGltf huge;
  huge.node = R"({"mesh": 0, "children": [1, 1]})";
  for (int i = 1; i < 40; ++i)
    huge.extra_nodes += ", {\"mesh\": 0, \"children\": [" + std::to_string(i + 1) + ", " + std::to_string(i + 1) + "]}";
  huge.extra_nodes += R"(, {"mesh": 0})";
  std::ofstream(dir + "/huge.gltf") << huge.json();
  const auto counted = test::run_tracer("info " + dir + "/huge.gltf");
  EXPECT_EQ(counted.exit_code, 0) << counted.output;
  EXPECT_NE(counted.output.find("triangles   2199023255551 (0 degenerate)"), std::string::npos) << counted.output;
  // A camera below them: info lists cameras where they are placed, and refuses 2^40 of them as a
  // load does.
  huge.extra = R"("cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}], )";
  huge.extra_nodes.replace(huge.extra_nodes.rfind(R"({"mesh": 0})"), std::string::npos, R"({"camera": 0})");
  std::ofstream(dir + "/cameras.gltf") << huge.json();
  const auto cameras = test::run_tracer("info " + dir + "/cameras.gltf");
  EXPECT_EQ(cameras.exit_code, 1) << cameras.output;
  EXPECT_NE(cameras.output.find("cameras.gltf: its nodes, children of more than one parent, expand to more than "
                                "2097193 node instances"),
            std::string::npos)
      << cameras.output;
  fs::remove_all(dir);
}

// A glTF whose instances would not fit the memory limit is refused before they are expanded.
TEST(Gltf, InstancesAboveTheMemoryLimitAreRefusedBeforeExpanding) {
  TinyGltf g;  // 2^20 instances of a triangle: 144 bytes each with the accelerator, 72 a geometry
  // Twenty levels of two nodes (index 2j - 1 moved by 2^j, 2j not), each naming both of the next
  // level's: 2^20 paths to the leaves, each placing the triangle elsewhere.
  const auto level = [](int j) { return "[" + std::to_string(2 * j) + ", " + std::to_string(2 * j - 1) + "]"; };
  g.node = R"({"children": )" + level(1) + "}";
  for (int j = 1; j <= 20; ++j) {
    const std::string below = j < 20 ? R"("children": )" + level(j + 1) : R"("mesh": 0)";
    g.extra_nodes += R"(, {"translation": [)" + std::to_string(1 << j) + ", 0, 0], " + below + "}";
    g.extra_nodes += ", {" + below + "}";
  }
  LoadLimits limits;
  limits.max_memory = uint64_t(64) << 20;
  limits.accel_bytes_per_triangle = 96;
  std::string e;
  try {
    load_gltf_from_memory(
        g.json(), "t.gltf", [](const std::string&) {}, limits);
  } catch (const InputError& error) {
    e = error.what();
  }
  EXPECT_EQ(e.rfind("t.gltf: its 1 unique triangles, 1048576 instances and their accelerator: about 352 MiB needed", 0),
            0u)
      << e;
  EXPECT_NE(e.find("needed, more than the memory limit of 64 MiB (--max-memory-mib"), std::string::npos) << e;
  // Expanded (for an accelerator that traces no instances): the triangles they expand to.
  limits.keep_instances = false;
  try {
    load_gltf_from_memory(
        g.json(), "t.gltf", [](const std::string&) {}, limits);
  } catch (const InputError& error) {
    e = error.what();
  }
  EXPECT_EQ(
      e.rfind("t.gltf: the 1048576 triangles its instances expand to and their accelerator: about 216 MiB needed", 0),
      0u)
      << e;
  limits.max_memory = uint64_t(1) << 30;
  EXPECT_EQ(load_gltf_from_memory(g.json(), "t.gltf", {}, limits).size(), 1u << 20);
  limits.keep_instances = true;
  const Scene kept = load_gltf_from_memory(g.json(), "t.gltf", {}, limits);
  EXPECT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept.instances.size(), 1u << 20);
}

// Nodes whose subtrees hold no mesh, camera or light place nothing: they are not walked, however
// many paths reach them (40 levels each naming the next twice: 2^40 paths).
TEST(Gltf, SubtreesThatPlaceNothingAreNotWalked) {
  TinyGltf g;
  g.node = R"({"mesh": 0, "children": [1, 1]})";
  for (int i = 1; i < 40; ++i)
    g.extra_nodes += ", {\"children\": [" + std::to_string(i + 1) + ", " + std::to_string(i + 1) + "]}";
  g.extra_nodes += R"(, {"translation": [1e300, 0, 0]})";  // not finite in a float; never applied
  const Scene s = load_gltf_from_memory(g.json(), "t.gltf");
  EXPECT_EQ(s.triangles.size(), 1u);
  EXPECT_EQ(s.cameras.size(), 0u);
}

// The same mesh placed again by the same transform is placed once (2^20 coincident placements
// of a 1 KB file cost a descent each on every ray: a 64x64 render ran past a minute), with one
// grouped warning; a placement that differs by a float's last bit is kept.
TEST(Gltf, CoincidentPlacementsArePlacedOnce) {
  TinyGltf g;
  g.node = R"({"children": [1, 1]})";
  for (int i = 1; i < 20; ++i)
    g.extra_nodes += ", {\"children\": [" + std::to_string(i + 1) + ", " + std::to_string(i + 1) + "]}";
  g.extra_nodes += R"(, {"mesh": 0})";
  for (const bool instanced : {true, false}) {
    LoadLimits limits;
    limits.keep_instances = instanced;
    std::vector<std::string> warnings;
    const Scene s = load_gltf_from_memory(
        g.json(), "t.gltf", [&](const std::string& w) { warnings.push_back(w); }, limits);
    EXPECT_EQ(s.instanced_size(), 1u) << instanced;
    ASSERT_EQ(warnings.size(), 1u) << instanced;
    EXPECT_NE(warnings[0].find("placed once (1048575 times"), std::string::npos) << warnings[0];
  }
  TinyGltf two;
  two.node = R"({"children": [1, 2]})";
  two.extra_nodes = R"(, {"mesh": 0}, {"mesh": 0, "translation": [0, 0, 1e-7]})";
  EXPECT_EQ(load_gltf_from_memory(two.json(), "t.gltf").instanced_size(), 2u);
}

// What the specification does not allow but exporters have written is read as its intent and
// said, once per kind: a matrix beside TRS (the matrix), a zero quaternion (no rotation),
// integer positions without KHR_mesh_quantization declared.
TEST(Gltf, LenientReadingsAreWarnings) {
  const auto warnings_of = [](const TinyGltf& g) {
    std::vector<std::string> w;
    load_gltf_from_memory(g.json(), "t.gltf", [&](const std::string& m) { w.push_back(m); });
    return w;
  };
  TinyGltf both;
  both.node = R"({"mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 2,0,0,1], "translation": [5, 0, 0]})";
  std::vector<std::string> w = warnings_of(both);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("nodes[0]: both a matrix and translation/rotation/scale"), std::string::npos) << w[0];
  EXPECT_EQ(load_gltf_from_memory(both.json(), "t.gltf").triangles[0].v0.x, 2.0f);  // the matrix's
  TinyGltf zero;
  zero.node = R"({"mesh": 0, "rotation": [0, 0, 0, 0]})";
  w = warnings_of(zero);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("zero rotation quaternion"), std::string::npos) << w[0];
  TinyGltf quantized;
  quantized.positions = bytes_of<uint16_t>({0, 0, 0, 1, 0, 0, 0, 1, 0}) + std::string(18, '\0');
  const std::string json = quantized.json();
  std::string as_ushort = json;  // every float accessor read as unsigned short
  for (size_t at = 0; (at = as_ushort.find(R"("componentType": 5126)", at)) != std::string::npos;)
    as_ushort.replace(at + 17, 4, "5123");
  std::vector<std::string> qw;
  const Scene q = load_gltf_from_memory(as_ushort, "t.gltf", [&](const std::string& m) { qw.push_back(m); });
  EXPECT_EQ(q.triangles[0].v1.x, 1.0f);
  ASSERT_EQ(qw.size(), 1u);
  EXPECT_NE(qw[0].find("without KHR_mesh_quantization in extensionsUsed"), std::string::npos) << qw[0];
  const std::string declared = R"({"extensionsUsed": ["KHR_mesh_quantization"], )" + as_ushort.substr(1);
  std::vector<std::string> none;
  load_gltf_from_memory(declared, "t.gltf", [&](const std::string& m) { none.push_back(m); });
  EXPECT_TRUE(none.empty()) << none[0];
}

// --stats of an instanced scene counts the triangles its instances place, and the accelerator's
// bytes per placed triangle (divided by the unique ones it printed 28535104 bytes a triangle).
TEST(Gltf, StatsOfAnInstancedSceneCountPlacedTriangles) {
  TinyGltf g;
  g.node = R"({"children": [1, 2]})";
  g.extra_nodes = R"(, {"mesh": 0}, {"mesh": 0, "translation": [2, 0, 0]})";
  const std::string dir = test::temp_dir();
  std::ofstream(dir + "/two.gltf") << g.json();
  const auto r = test::run_tracer("render " + dir + "/two.gltf --stats --integrator ao --width 8 --height 8 -q -o " +
                                  dir + "/two.png");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("(2 triangles: 1 unique, placed by 2 instances)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(" bytes/placed triangle"), std::string::npos) << r.output;
  std::filesystem::remove_all(dir);
}

TEST(Gltf, ExternalFilesMustLieInsideTheScenesFolder) {
  const std::string root = test::temp_dir();
  fs::create_directories(root + "/scene/textures");
  TinyGltf g;
  std::ofstream(root + "/secret.bin", std::ios::binary) << g.positions + g.indices;
  std::ofstream(root + "/scene/ok.bin", std::ios::binary) << g.positions + g.indices;
  g.buffer_uri = "ok.bin";
  std::ofstream(root + "/scene/ok.gltf") << g.json();
  EXPECT_EQ(load_gltf(root + "/scene/ok.gltf").triangles.size(), 1u);
  g.buffer_uri = "../secret.bin";
  std::ofstream(root + "/scene/escape.gltf") << g.json();
  const auto r =
      test::run_tracer("render " + root + "/scene/escape.gltf -q --width 8 --height 8 -o " + root + "/o.ppm");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("lies outside the scene's folder: refused"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(root + "/o.ppm"));
  // A symbolic link inside the folder that points out of it is refused too.
  fs::create_symlink(root + "/secret.bin", root + "/scene/link.bin");
  g.buffer_uri = "link.bin";
  std::ofstream(root + "/scene/link.gltf") << g.json();
  EXPECT_THROW(load_gltf(root + "/scene/link.gltf", [](const std::string&) {}), InputError);
  fs::remove_all(root);
}

TEST(Gltf, BaseColourTexturesAndTheirFactorAreRead) {
  const std::string dir = test::temp_dir();
  const Image8 img{2, 1, {255, 0, 0, 0, 0, 255}};
  write_image(dir + "/tex.png", img);
  Scene src = test::scene_of({Triangle{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}});
  src.corner_uvs = {{0.25f, 0.5f}, {0.75f, 0.5f}, {0.25f, 0.5f}};
  test::GltfWriteOptions options;
  options.base_color_images[0] = "tex.png";
  test::write_gltf(src, dir + "/t.gltf", options);
  const Scene s = load_gltf(dir + "/t.gltf");
  ASSERT_EQ(s.textures.size(), 1u);
  ASSERT_TRUE(s.materials[0].diffuse_texture.present());
  EXPECT_EQ(s.textures[0].texel(0, 0), (Vec3{1.0f, 0.0f, 0.0f}));
  EXPECT_NEAR(s.corner_uvs[1].x, 0.75f, 1e-7f);
  EXPECT_NEAR(s.corner_uvs[1].y, 0.5f, 1e-7f);
  fs::remove_all(dir);
}

// Each base colour factor on a texture is a tinted copy of it; the copies count against the
// texture budget, and past it a material takes the untinted image, said once.
TEST(Gltf, TintedCopiesOfATextureStayWithinTheBudget) {
  const std::string png = encode_png(Image8{2, 1, {255, 0, 0, 0, 0, 255}});
  std::string materials, primitives;
  for (int i = 0; i < 5; ++i) {
    materials += std::string(i ? ", " : "") + R"({"pbrMetallicRoughness": {"baseColorFactor": [)" +
                 std::to_string(0.5 + 0.1 * i) + R"(, 1, 1, 1], "metallicFactor": 0,
                 "baseColorTexture": {"index": 0}}})";
    primitives += std::string(i ? ", " : "") + R"({"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": )" +
                  std::to_string(i) + "}";
  }
  const std::string data = bytes_of<float>({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1});
  const std::string json = R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [)" +
                           primitives + R"(]}], "materials": [)" + materials + R"(],
    "textures": [{"source": 0}], "images": [{"uri": "data:image/png;base64,)" +
                           base64(png) + R"("}],
    "buffers": [{"uri": "data:application/octet-stream;base64,)" +
                           base64(data) + R"(", "byteLength": 60}],
    "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                  {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}]})";
  std::vector<std::string> warnings;
  const auto collect = [&](const std::string& w) { warnings.push_back(w); };
  Scene s = load_gltf_from_memory(json, "t.gltf", collect);
  EXPECT_EQ(s.textures.size(), 5u);  // five tints, each its own copy
  EXPECT_TRUE(warnings.empty());
  // The 2x1 texture takes 8 bytes decoded and 34 while it decodes: a budget of 34 holds it and
  // three tinted copies, not five.
  LoadLimits limits;
  limits.textures.max_total_bytes = 34;
  s = load_gltf_from_memory(json, "t.gltf", collect, limits);
  EXPECT_EQ(s.textures.size(), 4u);  // three tinted, one untinted for the other two
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0],
            "t.gltf: image 0: base colour factors past the texture budget: the untinted image is used (2 times; the "
            "first shown)");
  EXPECT_EQ(s.materials[3].diffuse_texture, s.materials[4].diffuse_texture);
  EXPECT_EQ(s.textures[s.materials[4].diffuse_texture.texture].texel(0, 0), (Vec3{1.0f, 0.0f, 0.0f}));
}

TEST(Gltf, ANormalMapTiltsTheShadingNormalInTheTangentFrame) {
  // A triangle in the xy plane, u along +x and v along +y; a normal map texel (x, y, z) in [-1, 1]
  // tilts the normal to normalize(x * scale, y * scale, z) in (dp/du, dp/dv, n).
  Scene s = test::scene_of({Triangle{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}});
  s.corner_uvs = {{0, 0}, {1, 0}, {0, 1}};
  const uint8_t tx = 200, ty = 100, tz = 220;
  s.textures.push_back(Texture(1, 1, {tx, ty, tz}));
  s.materials[0].normal_texture.texture = 0;
  s.materials[0].normal_scale = 0.5f;
  Hit hit;
  hit.tri = 0;
  hit.u = 0.2f;
  hit.v = 0.3f;
  const Vec3 n = bumped_normal(s, hit, s.materials[0], Vec3{0, 0, 1}, Vec3{0, 0, 1});
  const float x = (tx / 255.0f * 2 - 1) * 0.5f, y = (ty / 255.0f * 2 - 1) * 0.5f, z = tz / 255.0f * 2 - 1;
  const Vec3 want = normalize(Vec3{x, y, z});
  EXPECT_NEAR(n.x, want.x, 1e-5f);
  EXPECT_NEAR(n.y, want.y, 1e-5f);
  EXPECT_NEAR(n.z, want.z, 1e-5f);
  // Texture coordinates mirrored in v flip the bitangent, so the map's y follows v.
  s.corner_uvs = {{0, 1}, {1, 1}, {0, 0}};
  const Vec3 m = bumped_normal(s, hit, s.materials[0], Vec3{0, 0, 1}, Vec3{0, 0, 1});
  EXPECT_NEAR(m.y, -want.y, 1e-5f);
}

// --- OBJ scenes and their conversions -------------------------------------------------------------

void expect_same_geometry(const Scene& a, const Scene& b, bool uv_rounding) {
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  for (size_t i = 0; i < a.triangles.size(); ++i) {
    ASSERT_EQ(a.triangles[i].v0, b.triangles[i].v0) << i;
    ASSERT_EQ(a.triangles[i].v1, b.triangles[i].v1) << i;
    ASSERT_EQ(a.triangles[i].v2, b.triangles[i].v2) << i;
  }
  ASSERT_EQ(a.corner_normals.size(), b.corner_normals.size());
  for (size_t i = 0; i < a.corner_normals.size(); ++i) ASSERT_EQ(a.corner_normals[i], b.corner_normals[i]) << i;
  ASSERT_EQ(a.corner_uvs.size(), b.corner_uvs.size());
  for (size_t i = 0; i < a.corner_uvs.size(); ++i) {
    const float tol = uv_rounding ? 1e-6f * std::max(1.0f, std::fabs(a.corner_uvs[i].y)) : 0.0f;
    ASSERT_EQ(a.corner_uvs[i].x, b.corner_uvs[i].x) << i;
    ASSERT_LE(std::fabs(a.corner_uvs[i].y - b.corner_uvs[i].y), tol) << i;
  }
}

Scene load_as_user_does(const std::string& path) {
  frontend::SceneArgs args;
  args.scene = path;
  return frontend::load_scene(args, /*quiet=*/true);
}

class Conversions : public ::testing::TestWithParam<const char*> {};

// Every scene: the same triangles from OBJ, glTF, GLB and PLY of all three encodings.
TEST_P(Conversions, LoadAsTheSameTriangles) {
  if (!test::have_shared_scenes()) GTEST_SKIP() << "../shared/scenes not found";
  const Scene obj = load_obj(test::scene_path(GetParam()), [](const std::string&) {});
  const std::string dir = test::temp_dir();
  test::write_gltf(obj, dir + "/s.gltf");
  test::write_gltf(obj, dir + "/s.glb", {.binary = true});
  const auto quiet = [](const std::string&) {};
  expect_same_geometry(obj, load_scene_file(dir + "/s.gltf", quiet), true);
  expect_same_geometry(obj, load_scene_file(dir + "/s.glb", quiet), true);
  for (const auto e : {test::PlyEncoding::Ascii, test::PlyEncoding::BinaryLittle, test::PlyEncoding::BinaryBig}) {
    test::write_ply(obj, dir + "/s.ply", e);
    expect_same_geometry(obj, load_scene_file(dir + "/s.ply", quiet), false);
  }
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Scenes, Conversions,
                         ::testing::Values("cornell-box/CornellBox-Original.obj", "cornell-box/CornellBox-Water.obj",
                                           "bunny/bunny.obj", "sponza/sponza.obj"));

// The image check: an OBJ scene and its glTF conversion render the same picture. The Cornell
// boxes (framed from their bounds, lit by their lamps, materials mapped both ways) byte for byte;
// Sponza and the Bunny through the camera and light their views give, which the glTF carries as a
// camera node and a KHR_lights_punctual light: the camera's direction is rebuilt from its matrix
// (float rounding), so there the golden tolerance, PSNR >= 40 dB. The Bunny's PLY, given its
// view's camera and light as flags, byte for byte.
TEST(ConvertedScenes, RenderTheSameImageAsTheirObj) {
  if (!test::have_shared_scenes()) GTEST_SKIP() << "../shared/scenes not found";
  struct Case {
    const char* obj;
    const char* flags;
    bool exact;
  };
  const Case cases[] = {
      {"cornell-box/CornellBox-Original.obj", "--integrator path --spp 4", true},
      {"cornell-box/CornellBox-Mirror.obj", "--integrator whitted", true},
      {"cornell-box/CornellBox-Water.obj", "--integrator path --spp 2", true},
      {"sponza/sponza.obj", "--integrator ao", false},
      {"bunny/bunny.obj", "--integrator ao", false},
  };
  const std::string dir = test::temp_dir();
  for (const Case& c : cases) {
    const std::string obj = test::scene_path(c.obj);
    test::write_gltf(load_as_user_does(obj), dir + "/s.glb", {.binary = true});
    const std::string size = " -q --width 48 --height 36 --threads 2 ";
    const auto a = test::run_tracer("render " + obj + size + c.flags + " -o " + dir + "/obj.png");
    const auto b = test::run_tracer("render " + dir + "/s.glb" + size + c.flags + " -o " + dir + "/glb.png");
    ASSERT_EQ(a.exit_code, 0) << a.output;
    ASSERT_EQ(b.exit_code, 0) << b.output;
    if (c.exact) {
      EXPECT_EQ(test::read_bytes(dir + "/obj.png"), test::read_bytes(dir + "/glb.png")) << c.obj;
    } else {
      EXPECT_GE(test::psnr(read_image(dir + "/obj.png"), read_image(dir + "/glb.png")), 40.0) << c.obj;
    }
  }
  // PLY carries no camera or light: the Bunny's PLY through its view's flags is its OBJ's image.
  test::write_ply(load_obj(test::scene_path("bunny/bunny.obj"), [](const std::string&) {}), dir + "/b.ply",
                  test::PlyEncoding::BinaryLittle);
  const std::string flags = " -q --width 48 --height 36 --integrator ao ";
  const auto obj = test::run_tracer("render " + test::scene_path("bunny/bunny.obj") + flags + "-o " + dir + "/o.png");
  const auto ply = test::run_tracer("render " + dir + "/b.ply" + flags +
                                    "--eye -0.15,0.9,3 --look -0.15,0.83,0.07 --up 0,1,0 --fov 40 --light 1,3,3 -o " +
                                    dir + "/p.png");
  ASSERT_EQ(obj.exit_code, 0) << obj.output;
  ASSERT_EQ(ply.exit_code, 0) << ply.output;
  EXPECT_EQ(test::read_bytes(dir + "/o.png"), test::read_bytes(dir + "/p.png"));
  fs::remove_all(dir);
}

// --- PLY ----------------------------------------------------------------------------------------

std::string ply_error(const std::string& text) {
  try {
    load_ply_from_memory(text, "t.ply", [](const std::string&) {});
  } catch (const InputError& e) {
    return e.what();
  }
  return "(loaded)";
}

TEST(Ply, PolygonsOfAnyIndexTypeAreTriangulated) {
  const std::string header =
      "ply\nformat ascii 1.0\ncomment a quad and a triangle\nelement vertex 5\nproperty double x\n"
      "property double y\nproperty double z\nproperty uchar red\nelement face 2\n"
      "property list ushort uint vertex_index\nelement edge 1\nproperty int vertex1\nproperty int "
      "vertex2\nend_header\n";
  std::vector<std::string> warnings;
  const Scene s =
      load_ply_from_memory(header + "0 0 0 1\n1 0 0 1\n1 1 0 1\n0 1 0 1\n2 2 2 1\n4 0 1 2 3\n3 1 2 4\n0 1\n", "t.ply",
                           [&](const std::string& w) { warnings.push_back(w); });
  EXPECT_EQ(s.triangles.size(), 3u);
  EXPECT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].kd, Material{}.kd);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_EQ(warnings[0], "t.ply: vertex colours without all of red, green and blue not used");
  EXPECT_EQ(warnings[1], "t.ply: element 'edge' ignored");
}

// Integer channels are sRGB codes, float ones linear; they multiply the diffuse colour at a hit.
TEST(Ply, VertexColoursMultiplyTheDiffuseColour) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  const Scene s = load_ply_from_memory(header + "0 0 0 255 128 0\n1 0 0 255 128 0\n0 1 0 0 0 0\n3 0 1 2\n", "t.ply");
  ASSERT_EQ(s.corner_colors.size(), 3u);
  EXPECT_EQ(s.corner_colors[0].x, 1.0f);
  EXPECT_NEAR(s.corner_colors[0].y, 0.21586f, 1e-4f);  // sRGB 128
  Hit hit;
  hit.tri = 0;
  hit.u = 0.5f, hit.v = 0.0f;  // halfway between the first two corners: their colour
  const Vec3 c = diffuse_color(s, hit, s.materials[0]);
  EXPECT_NEAR(c.x, Material{}.kd.x, 1e-6f);
  EXPECT_NEAR(c.y, Material{}.kd.y * 0.21586f, 1e-4f);
  EXPECT_EQ(c.z, 0.0f);
  const std::string floats =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "property float r\nproperty float g\nproperty float b\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n0 0 0 0.5 0.5 0.5\n1 0 0 0.5 0.5 0.5\n"
      "0 1 0 0.5 0.5 0.5\n3 0 1 2\n";
  EXPECT_EQ(load_ply_from_memory(floats, "f.ply").corner_colors[2], Vec3{0.5f});  // linear as given
}

// Faces whose triangles would not fit the memory limit are refused at the header, before they are
// read; an OBJ's once parsed, before the scene's arrays are allocated.
TEST(Ply, FacesAboveTheMemoryLimitAreRefusedAtTheHeader) {
  std::string text =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 100000\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
  std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  for (int i = 0; i < 100000; ++i) text += "3 0 1 2\n", obj += "f 1 2 3\n";
  LoadLimits limits;  // 100,000 triangles of 48 bytes, and 96 each for the accelerator: 13.7 MiB, printed whole
  limits.max_memory = uint64_t(8) << 20;
  limits.accel_bytes_per_triangle = 96;
  const std::string tail = " triangles and their accelerator: about 13 MiB needed, more than the memory limit of 8 MiB";
  const auto error = [&](const auto& load) {
    try {
      load();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("(loaded)");
  };
  const auto ply = [&] {
    load_ply_from_memory(
        text, "t.ply", [](const std::string&) {}, limits);
  };
  const auto obj_load = [&] {
    load_obj_from_string(
        obj, "", "t.obj", [](const std::string&) {}, limits);
  };
  EXPECT_EQ(error(ply).rfind("t.ply: its 100000" + tail, 0), 0u) << error(ply);
  EXPECT_EQ(error(obj_load).rfind("t.obj: its 100000" + tail, 0), 0u) << error(obj_load);
  limits.max_memory = uint64_t(16) << 20;
  EXPECT_EQ(load_ply_from_memory(
                text, "t.ply", [](const std::string&) {}, limits)
                .size(),
            100000u);
  EXPECT_EQ(load_obj_from_string(
                obj, "", "t.obj", [](const std::string&) {}, limits)
                .size(),
            100000u);
}

TEST(Ply, HostileFilesFailWithOneLineNamingTheFileAndLine) {
  const std::string vertex = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string face = "element face 1\nproperty list uchar int vertex_indices\n";
  const std::string ascii = "ply\nformat ascii 1.0\n";
  struct Case {
    std::string text;
    const char* expect;
  };
  const Case cases[] = {
      {"plx\n", "t.ply:1: not a PLY file (its first line is not 'ply')"},
      {ascii + vertex + face, "t.ply:8: the header has no end_header line"},
      {ascii + "element vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n",
       "t.ply:3: element 'vertex' declares 4000000000 rows, more than the 6 bytes after the header can hold"},
      {ascii + vertex + face + "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
       "t.ply:13: face 0: vertex index 3 out of range (3 vertices)"},
      {ascii + vertex + face + "end_header\n0 0 0\n1 0 zero\n0 1 0\n3 0 1 2\n", "t.ply:11: malformed number 'zero'"},
      {ascii + vertex + face + "end_header\n0 0 0\n1 0 1e13\n0 1 0\n3 0 1 2\n",
       "t.ply:11: vertex 1 is not finite or lies beyond +-1e12"},
      {"ply\nformat binary_little_endian 1.0\n" + vertex + face + "end_header\n" + std::string(36, '\0') + "\x03" +
           std::string(3, '\0'),
       "t.ply: the file ends inside a face"},
      {ascii + "property float x\n", "t.ply:3: a property before any element"},
      {ascii + "element vertex 1\nproperty quad x\nend_header\n", "t.ply:4: unknown property type 'quad'"},
      {ascii + "element vertex 1\nproperty float y\nend_header\n0\n", "t.ply:3: vertex has no x, y and z"},
      {ascii + vertex + face + "end_header\n0 0 0 7\n1 0 0\n0 1 0\n3 0 1 2\n",
       "t.ply:10: more values than element 'vertex' declares properties ('7' is one too many)"},
      {ascii + vertex + face + "end_header\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n",
       "t.ply:11: the line ends inside a row (fewer values than its element's properties)"},
      {ascii + "element vertex 1\nproperty float x\nproperty float x\n",
       "t.ply:5: property 'x' declared twice in element 'vertex'"},
      {"", "t.ply: an empty file, not a PLY file"},
  };
  for (const Case& c : cases) {
    const std::string e = ply_error(c.text);
    EXPECT_EQ(e, c.expect);
  }
}

}  // namespace
}  // namespace tracer
