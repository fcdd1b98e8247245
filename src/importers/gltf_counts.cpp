#include "importers/gltf_counts.hpp"

#include "scene/scene.hpp"

namespace tracer::gltf {

Summary summary_of(const IndexedMesh& mesh, bool emissive) {
  Summary s;
  s.placed.primitives = 1;
  s.placed.triangles = mesh.triangle_count();
  s.vertices = mesh.positions.size();
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const uint32_t* ix = &mesh.indices[3 * t];
    if (Triangle{mesh.positions[ix[0]], mesh.positions[ix[1]], mesh.positions[ix[2]]}.degenerate()) ++s.degenerate;
  }
  for (const Vec3& v : mesh.positions) s.box.extend(v);
  s.emissive = emissive ? 1 : 0;
  return s;
}

}  // namespace tracer::gltf
