// glTF 2.0 loading (.gltf with its buffers and images, binary .glb) through tinygltf: every node's
// transform applied to its meshes, glTF's metallic-roughness materials mapped onto tracer's, the
// perspective cameras and point lights the file places. What tracer cannot render (skins,
// animations, morph targets, unknown extensions, alpha) is one grouped warning each.
// docs/FORMATS.md gives the mapping.
#pragma once

#include <string>
#include <string_view>

#include "base/errors.hpp"
#include "importers/load_limits.hpp"
#include "importers/warning_log.hpp"
#include "scene/scene.hpp"
#include "scene/scene_info.hpp"

namespace tracer {

// Loads a .gltf or .glb file into a finalized Scene. External buffers and images must lie in the
// file's folder or below it (a URI that leaves it is refused); every file is read within
// limits.max_obj_bytes. Throws InputError with a one-line message naming the file; Cancelled
// when `cancel` is set during loading.
Scene load_gltf(const std::string& path, const WarningSink& warn = {}, CancelFlag cancel = nullptr,
                const LoadLimits& limits = {}, LoadPhases* phases = nullptr);

// What tracer info prints of a .gltf or .glb, without placing its instances: each node is
// counted once however often the node tree reaches it (2^24 instances of a triangle: 0.1 s, not a
// 1.9 GB scene), the bounds are those of the instances' boxes, and only the cameras and point
// lights are placed (emissive primitives are counted, not listed). Textures are not read.
SceneInfo gltf_info(const std::string& path, const WarningSink& warn = {}, CancelFlag cancel = nullptr,
                    const LoadLimits& limits = {});

// The same from memory (fuzzing, tests): `bytes` a .glb when they start with its magic, JSON
// otherwise; `name` stands for the file in messages. Only data: URIs resolve; an external URI is
// refused.
Scene load_gltf_from_memory(std::string_view bytes, const std::string& name, const WarningSink& warn = {},
                            const LoadLimits& limits = {});

}  // namespace tracer
