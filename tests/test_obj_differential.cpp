// tinyobjloader as the oracle of the OBJ reader on the statements real exporters write around
// the geometry: `o`, `g`, `s`, `usemtl` oddities, `vp`, `l` and `p` lines, comments after values,
// tabs and CRLF. Both must make the same triangles with the same material names.
#include <gtest/gtest.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <array>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "base/errors.hpp"
#include "importers/obj_loader.hpp"

namespace tracer {
namespace {

// A triangle as its corners (sorted, so the two readers' windings and splits compare) and its
// material's name ("" for none).
using Tri = std::pair<std::array<std::array<float, 3>, 3>, std::string>;

std::vector<Tri> tracer_triangles(const std::string& obj, const std::string& mtl) {
  const Scene s = load_obj_from_string(obj, mtl, "t.obj", [](const std::string&) {});
  std::vector<Tri> out;
  for (size_t t = 0; t < s.size(); ++t) {
    Tri tri;
    const Vec3 corners[3] = {s.triangles[t].v0, s.triangles[t].v1, s.triangles[t].v2};
    for (int c = 0; c < 3; ++c) tri.first[c] = {corners[c].x, corners[c].y, corners[c].z};
    std::sort(tri.first.begin(), tri.first.end());
    const Material& m = s.materials[s.tri_material[t]];
    tri.second = m.name == Material{}.name ? "" : m.name;
    out.push_back(tri);
  }
  std::sort(out.begin(), out.end());
  return out;
}

class StringMaterialReader : public tinyobj::MaterialReader {
 public:
  explicit StringMaterialReader(std::string mtl) : mtl_(std::move(mtl)) {}
  bool operator()(const std::string&, std::vector<tinyobj::material_t>* materials, std::map<std::string, int>* by_name,
                  std::string* warn, std::string* err) override {
    std::istringstream in(mtl_);
    tinyobj::LoadMtl(by_name, materials, &in, warn, err);
    return true;
  }

 private:
  std::string mtl_;
};

// tinyobjloader refuses a comment after the indices of `f`, `l` and `p` lines (it reads `#` as an
// index) though it takes one after a `v` line's numbers; tracer takes both. Given without them.
std::string without_trailing_comments(const std::string& obj) {
  std::string out;
  std::istringstream in(obj);
  for (std::string line; std::getline(in, line);) {
    for (size_t at = line.find('#'); at != std::string::npos; at = line.find('#', at + 1)) {
      if (at > 0 && (line[at - 1] == ' ' || line[at - 1] == '\t')) {
        line.erase(at);
        break;
      }
    }
    out += line + "\n";
  }
  return out;
}

std::vector<Tri> tinyobj_triangles(const std::string& obj_as_written, const std::string& mtl) {
  const std::string obj = without_trailing_comments(obj_as_written);
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  std::istringstream in(obj);
  StringMaterialReader reader(mtl);
  EXPECT_TRUE(tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &in, &reader, true)) << err;
  std::vector<Tri> out;
  for (const tinyobj::shape_t& shape : shapes) {
    for (size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f) {
      Tri tri;
      for (int c = 0; c < 3; ++c) {
        const int v = shape.mesh.indices[3 * f + size_t(c)].vertex_index;
        tri.first[c] = {attrib.vertices[3 * size_t(v)], attrib.vertices[3 * size_t(v) + 1],
                        attrib.vertices[3 * size_t(v) + 2]};
      }
      std::sort(tri.first.begin(), tri.first.end());
      const int m = shape.mesh.material_ids[f];
      tri.second = m < 0 ? "" : materials[size_t(m)].name;
      out.push_back(tri);
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string generated_obj(std::mt19937& rng) {
  const auto pick = [&](int n) { return int(rng() % uint32_t(n)); };
  const char* seps[] = {" ", "  ", "\t"};
  const char* ends[] = {"\n", "\r\n", " \n", " # note\n"};
  const auto sep = [&] { return std::string(seps[pick(3)]); };
  const auto end = [&] { return std::string(ends[pick(4)]); };
  std::string text = "mtllib m.mtl" + end();
  int vertices = 0;
  const int statements = 10 + pick(30);
  for (int k = 0; k < statements; ++k) {
    switch (pick(12)) {
      case 0:
      case 1:
      case 2:
      case 3:
        text += "v" + sep() + std::to_string(pick(9) - 4) + sep() + std::to_string(pick(9) - 4) + "." +
                std::to_string(pick(10)) + sep() + std::to_string(pick(5)) + end();
        ++vertices;
        break;
      case 4:
      case 5: {
        if (vertices < 3) break;
        std::string f = "f";
        std::vector<int> used;
        while (used.size() < 3) {
          const int v = 1 + pick(vertices);
          if (std::find(used.begin(), used.end(), v) == used.end()) used.push_back(v);
        }
        for (int v : used) f += sep() + (pick(3) == 0 ? std::to_string(v - vertices - 1) : std::to_string(v));
        text += f + end();
        break;
      }
      case 6:
        text += std::string("usemtl") + sep() + (pick(4) ? "m" + std::to_string(pick(3)) : "missing") + end();
        break;
      case 7:
        text += std::string(pick(2) ? "o" : "g") + sep() + "part" + std::to_string(pick(3)) + end();
        break;
      case 8:
        text += "s" + sep() + (pick(2) ? "off" : std::to_string(pick(4))) + end();
        break;
      case 9:
        text += "vp" + sep() + "0.5" + sep() + "0.5" + end();
        break;
      case 10:
        if (vertices >= 2) text += "l" + sep() + "1" + sep() + "2" + end();
        break;
      default:
        if (vertices >= 1) text += "p" + sep() + "1" + end();
        break;
    }
  }
  return text + "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n";
}

TEST(ObjDifferential, GeneratedScenesMakeTinyobjloadersTriangles) {
  const std::string mtl = "newmtl m0\nKd 1 0 0\nnewmtl m1\nKd 0 1 0\nnewmtl m2\nKd 0 0 1\n";
  std::mt19937 rng(41);
  for (int i = 0; i < 500; ++i) {
    const std::string obj = generated_obj(rng);
    ASSERT_EQ(tracer_triangles(obj, mtl), tinyobj_triangles(obj, mtl)) << "scene " << i << ":\n" << obj;
  }
}

}  // namespace
}  // namespace tracer
