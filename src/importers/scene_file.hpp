// Which importer reads a scene file: by its extension (.obj, .gltf, .glb, .ply, in any case).
// Standard input and a path without an extension (a pipe, /dev/fd/N) are read as OBJ; another
// extension is refused (an .stl read as OBJ gave "no triangles" or, worse, an image).
#pragma once

#include <string>

#include "importers/load_limits.hpp"
#include "importers/warning_log.hpp"
#include "scene/scene.hpp"

namespace tracer {

enum class SceneFormat { Obj, Gltf, Ply };

// Throws InputError naming the file and the formats read for an unknown extension.
SceneFormat scene_format(const std::string& path);

// Loads `path` with the importer its format calls for (importers/obj_loader.hpp,
// gltf_loader.hpp, ply_loader.hpp): the same errors, warnings, limits and cancellation.
Scene load_scene_file(const std::string& path, const WarningSink& warn = {}, CancelFlag cancel = nullptr,
                      const LoadLimits& limits = {}, LoadPhases* phases = nullptr);

}  // namespace tracer
