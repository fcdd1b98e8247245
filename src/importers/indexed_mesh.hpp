// A triangle mesh as glTF and PLY give it (shared vertices, three indices per triangle) and its
// placement in the scene's flat per-triangle arrays.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "math/affine.hpp"
#include "math/vec.hpp"
#include "scene/scene.hpp"

namespace tracer {

struct IndexedMesh {
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;      // empty, or one per position
  std::vector<Vec2> uvs;          // empty, or one per position; v = 0 is the image's bottom row (OBJ's)
  std::vector<Vec2> uvs1;         // the second set (glTF's TEXCOORD_1), likewise
  std::vector<Vec3> colors;       // empty, or one per position: linear RGB (glTF's COLOR_0, PLY's)
  std::vector<uint32_t> indices;  // three per triangle, each below positions.size()
  size_t triangle_count() const { return indices.size() / 3; }
};

// Appends `mesh` moved by `to_world` as one geometry of material `material`: triangles, corner
// normals (moved by the transform's cofactor matrix, the inverse transpose up to scale, and
// turned with a mirroring map) and texture coordinates.
// A map that mirrors (negative determinant) also reverses each triangle's corners, so faces
// keep their front side (counter-clockwise seen from the front).
void append_mesh(Scene& scene, const std::string& name, const IndexedMesh& mesh, uint32_t material,
                 const Affine& to_world = {});

}  // namespace tracer
