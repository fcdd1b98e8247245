// One glTF primitive read into an IndexedMesh: its positions (finite, within the coordinates
// tracer holds), normals, first texture coordinates (v flipped), and its indices as triangles
// (lists, strips and fans); points and lines are skipped with a warning. Errors name the file
// (`file`) and the primitive (`what`).
#pragma once

#include <optional>
#include <string>

#include "importers/gltf_document.hpp"
#include "importers/indexed_mesh.hpp"
#include "importers/warning_log.hpp"

namespace tracer::gltf {

std::optional<IndexedMesh> primitive_mesh(const tinygltf::Model& model, const std::string& file, WarningLog& warnings,
                                          const tinygltf::Primitive& primitive, const std::string& what);

}  // namespace tracer::gltf
