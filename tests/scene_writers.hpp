// Test data: a loaded scene written back out as glTF 2.0 (tinygltf's writer) and as PLY (a few
// lines of our own), so that an OBJ scene and its conversions can be rendered side by side.
#pragma once

#include <array>
#include <map>
#include <string>
#include <vector>

#include "scene/scene.hpp"

namespace tracer::test {

struct GltfWriteOptions {
  bool binary = false;  // .glb: one file, its buffer inside
  // Per tracer material index: a baseColorTexture image URI (relative to the file's folder).
  std::map<uint32_t, std::string> base_color_images;
  // Per geometry index: the transforms (column-major 4x4, glTF's node matrix) of the nodes that
  // place its mesh; a geometry not listed is placed once, untransformed.
  std::map<uint32_t, std::vector<std::array<double, 16>>> placements;
  // Each placement a mesh of its own (sharing the first's accessors): a file tracer loads flat,
  // the same triangles as the instanced one.
  bool distinct_meshes = false;
  // Every geometry a primitive of one mesh (a building as exporters write it), placed by the
  // transforms listed for geometry 0.
  bool one_mesh = false;
};

// Every triangle, one indexed primitive per run of one material within a geometry (corners equal
// in position, normal and texture coordinates shared); materials mapped as docs/FORMATS.md
// describes in reverse (Kd as base colour, Ks through KHR_materials_specular, illum 3 a smooth
// metal, illum 4-9 transmission with KHR_materials_ior, Ke through
// KHR_materials_emissive_strength); the scene's camera and point lights as nodes.
void write_gltf(const Scene& scene, const std::string& path, const GltfWriteOptions& options = {});

enum class PlyEncoding { Ascii, BinaryLittle, BinaryBig };
// The triangles as PLY: the distinct corners as vertices (with normals and u, v when the scene
// has them) and one face per triangle.
void write_ply(const Scene& scene, const std::string& path, PlyEncoding encoding);

}  // namespace tracer::test
