#include "scene/scene.hpp"

#include <limits>
#include <map>
#include <string>
#include <utility>

#include "base/errors.hpp"
#include "math/sampling.hpp"
#include "scene/emission.hpp"

namespace tracer {

bool Triangle::degenerate() const {
  // Exact test in double: float rounding must not turn a collinear triple into a sliver.
  const double ax = double(v1.x) - v0.x, ay = double(v1.y) - v0.y, az = double(v1.z) - v0.z;
  const double bx = double(v2.x) - v0.x, by = double(v2.y) - v0.y, bz = double(v2.z) - v0.z;
  const double cx = ay * bz - az * by, cy = az * bx - ax * bz, cz = ax * by - ay * bx;
  return cx == 0.0 && cy == 0.0 && cz == 0.0;
}

void Scene::add_mesh(const std::string& name, const std::vector<Vec3>& vertices, const std::vector<uint32_t>& indices,
                     uint32_t material) {
  Geometry g;
  g.name = name;
  g.first_triangle = static_cast<uint32_t>(triangles.size());
  g.triangle_count = static_cast<uint32_t>(indices.size() / 3);
  const auto geom_id = static_cast<uint32_t>(geometries.size());
  for (size_t i = 0; i + 2 < indices.size(); i += 3) {
    triangles.push_back({vertices[indices[i]], vertices[indices[i + 1]], vertices[indices[i + 2]]});
    tri_geom.push_back(geom_id);
    tri_prim.push_back(static_cast<uint32_t>(i / 3));
    tri_material.push_back(material);
  }
  vertex_count += vertices.size();
  if (!corner_normals.empty()) corner_normals.resize(3 * triangles.size(), Vec3{0.0f});  // none for this mesh
  if (!corner_uvs.empty()) corner_uvs.resize(3 * triangles.size(), Vec2{});
  if (!corner_uvs1.empty()) corner_uvs1.resize(3 * triangles.size(), Vec2{});
  if (!corner_colors.empty()) corner_colors.resize(3 * triangles.size(), Vec3{1.0f});
  geometries.push_back(std::move(g));
}

Instance make_instance(uint32_t mesh, const Affine& world) {
  Instance in;
  in.mesh = mesh;
  in.to_world = Transform::of(world);
  in.to_object = Transform::of(world.inverse());
  in.mirrors = world.determinant() < 0.0;
  return in;
}

namespace {

// The world box of `box` moved by `m`: its corners' box, widened by a few float steps of its
// size, as the corners moved in float may land a rounding inside the moved triangles.
Aabb moved_box(const Aabb& box, const Transform& m) {
  Aabb out;
  if (box.empty()) return out;
  for (int k = 0; k < 8; ++k) {
    out.extend(m.point({(k & 1) ? box.hi.x : box.lo.x, (k & 2) ? box.hi.y : box.lo.y, (k & 4) ? box.hi.z : box.lo.z}));
  }
  const float pad = 4.0f * std::numeric_limits<float>::epsilon() * max_component(max(abs(out.lo), abs(out.hi)));
  out.lo = out.lo - Vec3{pad};
  out.hi = out.hi + Vec3{pad};
  return out;
}

}  // namespace

uint64_t Scene::instanced_size() const {
  if (!instanced()) return size();
  uint64_t n = 0;
  for (const Instance& in : instances) n += meshes[in.mesh].triangles.count;
  return n;
}

void Scene::finalize() {
  bounds = Aabb{};
  degenerate_count = 0;
  for (const Triangle& t : triangles) {
    if (!instanced()) bounds.extend(t.bounds());
    degenerate_count += t.degenerate() ? 1 : 0;
  }
  for (Mesh& m : meshes) {
    m.bounds = Aabb{};
    m.emissive = false;
    for (uint32_t i = m.triangles.first; i < m.triangles.first + m.triangles.count; ++i) {
      if (!triangles[i].degenerate()) m.bounds.extend(triangles[i].bounds());
      m.emissive = m.emissive || materials[tri_material[i]].emissive();
    }
  }
  for (Instance& in : instances) {
    in.bounds = moved_box(meshes[in.mesh].bounds, in.to_world);
    bounds.extend(in.bounds);
  }
  // One area light per (geometry, emissive material) and instance: the Cornell lamp is one quad,
  // one light.
  std::erase_if(lights, [](const Light& l) { return l.kind == LightKind::Area; });
  // A light's power is its emission times its area; with an emission texture, the sum of its
  // triangles' mean emission times area, and its position their centroids weighted by that.
  struct Accum {
    Vec3 weighted_centroid, normal, ke;
    float area = 0;
    bool textured = false;
    Vec3 power, power_centroid;
    float luminance = 0;
  };
  const auto add_lights = [&](TriangleRange range, uint32_t inst) {
    std::map<std::pair<uint32_t, uint32_t>, Accum> by_source;
    for (size_t i = range.first; i < size_t(range.first) + range.count; ++i) {
      const Material& m = materials[tri_material[i]];
      if (!m.emissive() || triangles[i].degenerate()) continue;
      Accum& a = by_source[{tri_geom[i], tri_material[i]}];
      const Triangle t = world_triangle(uint32_t(i), inst);
      const Vec3 n = face_normal(t, inst);
      const float area = 0.5f * length(n);
      a.weighted_centroid += t.centroid() * area;
      a.normal += n * 0.5f;
      a.area += area;
      a.ke = m.ke;
      if (m.emission_texture.present()) {
        const Vec3 power = mean_emission(*this, uint32_t(i)) * area;
        a.textured = true;
        a.power += power;
        a.power_centroid += t.centroid() * luminance(power);
        a.luminance += luminance(power);
      }
    }
    for (const auto& [key, a] : by_source) {
      if (a.area <= 0.0f || (a.textured && !(a.luminance > 0.0f))) continue;  // no area, or black texels only
      Light l;
      l.kind = LightKind::Area;
      l.position = a.textured ? a.power_centroid / a.luminance : a.weighted_centroid / a.area;
      const float n_len = length(a.normal);
      l.normal = n_len > 0.0f ? a.normal / n_len : Vec3{0.0f, -1.0f, 0.0f};
      l.power = a.textured ? a.power : a.ke * a.area;
      l.area = a.area;
      l.geomID = key.first;
      l.inst = inst;
      if (!is_finite(l.position) || !is_finite(l.power)) {
        throw InputError(source + ": the emissive surface of geometry " + std::to_string(key.first) + " (material " +
                         std::to_string(key.second) + ") has a light of non-finite position or power");
      }
      lights.push_back(l);
    }
  };
  if (!instanced()) {
    add_lights(TriangleRange::all(*this), kInvalidIndex);
  } else {
    for (uint32_t i = 0; i < instances.size(); ++i) {
      if (meshes[instances[i].mesh].emissive) add_lights(meshes[instances[i].mesh].triangles, i);
    }
  }
  emitters = Emitters(*this);
}

uint64_t Scene::memory_bytes() const {
  uint64_t bytes = triangles.capacity() * sizeof(Triangle) +
                   (tri_geom.capacity() + tri_prim.capacity() + tri_material.capacity()) * sizeof(uint32_t) +
                   corner_normals.capacity() * sizeof(Vec3) +
                   (corner_uvs.capacity() + corner_uvs1.capacity()) * sizeof(Vec2) +
                   corner_colors.capacity() * sizeof(Vec3) + geometries.capacity() * sizeof(Geometry) +
                   emitters.memory_bytes() + meshes.capacity() * sizeof(Mesh) + instances.capacity() * sizeof(Instance);
  for (const Texture& t : textures) bytes += t.srgb().size() * 4 / 3;  // and its mip levels
  return bytes;
}

}  // namespace tracer
