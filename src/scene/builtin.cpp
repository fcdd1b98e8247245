#include "scene/builtin.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace tracer {

IndexedMesh make_uv_sphere(Vec3 center, float radius, int slices, int stacks) {
  IndexedMesh m;
  slices = std::max(3, slices);
  stacks = std::max(2, stacks);
  m.vertices.push_back(center + Vec3{0.0f, radius, 0.0f});  // north pole
  for (int i = 1; i < stacks; ++i) {
    const double theta = std::numbers::pi * i / stacks;
    for (int j = 0; j < slices; ++j) {
      const double phi = 2.0 * std::numbers::pi * j / slices;
      m.vertices.push_back(center + Vec3{float(radius * std::sin(theta) * std::cos(phi)),
                                         float(radius * std::cos(theta)),
                                         float(-radius * std::sin(theta) * std::sin(phi))});
    }
  }
  m.vertices.push_back(center - Vec3{0.0f, radius, 0.0f});  // south pole
  const auto ring = [&](int i, int j) { return static_cast<uint32_t>(1 + (i - 1) * slices + (j % slices)); };
  const auto south = static_cast<uint32_t>(m.vertices.size() - 1);
  for (int j = 0; j < slices; ++j) m.indices.insert(m.indices.end(), {0u, ring(1, j), ring(1, j + 1)});
  for (int i = 1; i + 1 < stacks; ++i) {
    for (int j = 0; j < slices; ++j) {
      m.indices.insert(m.indices.end(), {ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
      m.indices.insert(m.indices.end(), {ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
    }
  }
  for (int j = 0; j < slices; ++j)
    m.indices.insert(m.indices.end(), {ring(stacks - 1, j), south, ring(stacks - 1, j + 1)});
  return m;
}

IndexedMesh make_box(Vec3 lo, Vec3 hi) {
  IndexedMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.push_back({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z});
  // Each face as two counter-clockwise triangles seen from outside.
  const uint32_t faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : faces) m.indices.insert(m.indices.end(), {f[0], f[1], f[2], f[0], f[2], f[3]});
  return m;
}

namespace {

// Cornell's measured data is in millimetres with the box 548.8 mm tall.
constexpr float kScale = 2.0f / 548.8f;

Vec3 mm(float x, float y, float z) { return Vec3{x, y, z} * kScale; }

void add_quads(Scene& s, const std::string& name, std::initializer_list<Vec3> corners, uint32_t material) {
  IndexedMesh m;
  m.vertices.assign(corners.begin(), corners.end());
  for (uint32_t q = 0; q + 3 < m.vertices.size(); q += 4)
    m.indices.insert(m.indices.end(), {q, q + 1, q + 2, q, q + 2, q + 3});
  s.add_mesh(name, m.vertices, m.indices, material);
}

}  // namespace

Scene make_cornell_box(int sphere_triangles) {
  Scene s;
  s.source = "builtin:cornell";
  // Reflectances approximating Cornell's measured spectra, in linear RGB.
  s.materials = {
      Material{.name = "white", .kd = {0.725f, 0.71f, 0.68f}},
      Material{.name = "red", .kd = {0.63f, 0.065f, 0.05f}},
      Material{.name = "green", .kd = {0.14f, 0.45f, 0.091f}},
      Material{.name = "light", .kd = {0.78f, 0.78f, 0.78f}, .ke = {17.0f, 12.0f, 4.0f}},
      Material{.name = "sphere", .kd = {0.35f, 0.45f, 0.75f}},
  };
  add_quads(s, "floor", {mm(552.8f, 0, 0), mm(0, 0, 0), mm(0, 0, 559.2f), mm(549.6f, 0, 559.2f)}, 0);
  add_quads(s, "ceiling", {mm(556, 548.8f, 0), mm(556, 548.8f, 559.2f), mm(0, 548.8f, 559.2f), mm(0, 548.8f, 0)}, 0);
  add_quads(s, "back_wall", {mm(549.6f, 0, 559.2f), mm(0, 0, 559.2f), mm(0, 548.8f, 559.2f), mm(556, 548.8f, 559.2f)},
            0);
  add_quads(s, "green_wall", {mm(0, 0, 559.2f), mm(0, 0, 0), mm(0, 548.8f, 0), mm(0, 548.8f, 559.2f)}, 2);
  add_quads(s, "red_wall", {mm(552.8f, 0, 0), mm(549.6f, 0, 559.2f), mm(556, 548.8f, 559.2f), mm(556, 548.8f, 0)}, 1);
  // The lamp hangs 0.1 mm below the ceiling so it is not coplanar with it.
  add_quads(s, "light", {mm(343, 548.7f, 227), mm(343, 548.7f, 332), mm(213, 548.7f, 332), mm(213, 548.7f, 227)}, 3);
  add_quads(s, "short_block",
            {mm(130, 165, 65),  mm(82, 165, 225),  mm(240, 165, 272), mm(290, 165, 114), mm(290, 0, 114),
             mm(290, 165, 114), mm(240, 165, 272), mm(240, 0, 272),   mm(130, 0, 65),    mm(130, 165, 65),
             mm(290, 165, 114), mm(290, 0, 114),   mm(82, 0, 225),    mm(82, 165, 225),  mm(130, 165, 65),
             mm(130, 0, 65),    mm(240, 0, 272),   mm(240, 165, 272), mm(82, 165, 225),  mm(82, 0, 225)},
            0);
  add_quads(s, "tall_block",
            {mm(423, 330, 247), mm(265, 330, 296), mm(314, 330, 456), mm(472, 330, 406), mm(423, 0, 247),
             mm(423, 330, 247), mm(472, 330, 406), mm(472, 0, 406),   mm(472, 0, 406),   mm(472, 330, 406),
             mm(314, 330, 456), mm(314, 0, 456),   mm(314, 0, 456),   mm(314, 330, 456), mm(265, 330, 296),
             mm(265, 0, 296),   mm(265, 0, 296),   mm(265, 330, 296), mm(423, 330, 247), mm(423, 0, 247)},
            0);
  if (sphere_triangles > 0) {
    // 2*slices*(stacks-1) triangles with slices = 2*stacks: pick stacks to match the request.
    const int stacks = std::max(2, static_cast<int>(std::lround(std::sqrt(sphere_triangles / 4.0))));
    const IndexedMesh a = make_uv_sphere(mm(186, 165 + 60, 169), 60 * kScale, 2 * stacks, stacks);
    const IndexedMesh b = make_uv_sphere(mm(150, 80, 420), 80 * kScale, 2 * stacks, stacks);
    s.add_mesh("sphere_on_block", a.vertices, a.indices, 4);
    s.add_mesh("sphere_on_floor", b.vertices, b.indices, 4);
  }
  s.camera = CameraSpec{mm(278, 273, -800), mm(278, 273, 0), {0, 1, 0}, 37.5f};
  s.finalize();
  return s;
}

std::vector<Affine> grid_placements(const Aabb& bounds, uint32_t n) {
  const Vec3 e = bounds.extent();
  const double step = 1.1 * double(std::max(e.x, e.z));
  const auto side = uint32_t(std::ceil(std::sqrt(double(n))));
  std::vector<Affine> out;
  out.reserve(n);
  for (uint32_t k = 0; k < n; ++k) {
    const double a = 0.37 * double(k % side + 3 * (k / side)), c = std::cos(a), s = std::sin(a);
    Affine m;
    m.m = {{{c, 0, s, double(k % side) * step}, {0, 1, 0, 0}, {-s, 0, c, -double(k / side) * step}}};
    out.push_back(m);
  }
  return out;
}

Scene place_instances(Scene scene, const std::vector<Affine>& placements) {
  scene.meshes = {Mesh{scene.source, TriangleRange::all(scene), {}, false}};
  scene.instances.clear();
  for (const Affine& m : placements) scene.instances.push_back(make_instance(0, m));
  scene.finalize();
  return scene;
}

}  // namespace tracer
