#include "importers/indexed_mesh.hpp"

#include <cmath>

namespace tracer {

void append_mesh(Scene& scene, const std::string& name, const IndexedMesh& mesh, uint32_t material,
                 const Affine& to_world) {
  const size_t first = scene.triangles.size();
  const size_t count = mesh.triangle_count();
  const bool mirrored = to_world.determinant() < 0.0;
  // Corner order: a mirroring map swaps the second and third corners.
  const int corner[3] = {0, mirrored ? 2 : 1, mirrored ? 1 : 2};
  std::vector<Vec3> moved(mesh.positions.size());
  for (size_t i = 0; i < moved.size(); ++i) moved[i] = to_world.point(mesh.positions[i]);
  scene.triangles.resize(first + count);
  scene.tri_geom.resize(first + count, uint32_t(scene.geometries.size()));
  scene.tri_material.resize(first + count, material);
  scene.tri_prim.resize(first + count);
  for (size_t t = 0; t < count; ++t) {
    const uint32_t* ix = &mesh.indices[3 * t];
    scene.triangles[first + t] = {moved[ix[corner[0]]], moved[ix[corner[1]]], moved[ix[corner[2]]]};
    scene.tri_prim[first + t] = uint32_t(t);
  }
  // Corner arrays exist for the whole scene once any mesh has them (zero where a mesh has none).
  if (!mesh.normals.empty() || !scene.corner_normals.empty()) {
    scene.corner_normals.resize(3 * (first + count), Vec3{0.0f});
    if (!mesh.normals.empty()) {
      const float sign = mirrored ? -1.0f : 1.0f;
      std::vector<Vec3> turned(mesh.normals.size());
      for (size_t i = 0; i < turned.size(); ++i) {
        // Not normalised: shading interpolates the corners' normals as the file gives them (as
        // for OBJ's vn) and normalises the result; the cofactor scales a mesh's normals alike.
        const Vec3 n = to_world.normal(mesh.normals[i]) * sign;
        turned[i] = is_finite(n) ? n : Vec3{0.0f};
      }
      for (size_t t = 0; t < count; ++t)
        for (int k = 0; k < 3; ++k) scene.corner_normals[3 * (first + t) + k] = turned[mesh.indices[3 * t + corner[k]]];
    }
  }
  const auto place_uvs = [&](const std::vector<Vec2>& uvs, LargeVector<Vec2>& corners) {
    if (uvs.empty() && corners.empty()) return;
    corners.resize(3 * (first + count), Vec2{});
    if (uvs.empty()) return;
    for (size_t t = 0; t < count; ++t)
      for (int k = 0; k < 3; ++k) corners[3 * (first + t) + k] = uvs[mesh.indices[3 * t + corner[k]]];
  };
  place_uvs(mesh.uvs, scene.corner_uvs);
  place_uvs(mesh.uvs1, scene.corner_uvs1);
  if (!mesh.colors.empty() || !scene.corner_colors.empty()) {  // white where a mesh has none
    scene.corner_colors.resize(3 * (first + count), Vec3{1.0f});
    for (size_t t = 0; t < count && !mesh.colors.empty(); ++t)
      for (int k = 0; k < 3; ++k)
        scene.corner_colors[3 * (first + t) + k] = mesh.colors[mesh.indices[3 * t + corner[k]]];
  }
  scene.vertex_count += mesh.positions.size();
  scene.geometries.push_back({name, uint32_t(first), uint32_t(count)});
}

}  // namespace tracer
