// What a glTF node places besides meshes: a perspective camera (its node's transform gives the
// eye, the view along -z and the up +y) and a KHR_lights_punctual light. Other kinds are skipped
// with a warning (nothing returned); values tracer cannot hold are errors naming the file.
#pragma once

#include <optional>
#include <string>

#include "importers/gltf_document.hpp"
#include "importers/warning_log.hpp"
#include "math/affine.hpp"
#include "scene/scene.hpp"

namespace tracer::gltf {

std::optional<CameraSpec> camera_of(const tinygltf::Model& model, const std::string& file, WarningLog& warnings,
                                    int index, const Affine& world);
// A KHR_lights_punctual point, spot or directional light, its intensity converted from the
// file's photometric units (light_of's comment); an unknown type is a warning (nothing returned).
std::optional<Light> light_of(const tinygltf::Model& model, const std::string& file, WarningLog& warnings,
                              const tinygltf::Value& extension, const Affine& world);

}  // namespace tracer::gltf
