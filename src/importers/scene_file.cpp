#include "importers/scene_file.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "base/errors.hpp"
#include "importers/gltf_loader.hpp"
#include "importers/obj_loader.hpp"
#include "importers/ply_loader.hpp"

namespace tracer {

SceneFormat scene_format(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".gltf" || ext == ".glb") return SceneFormat::Gltf;
  if (ext == ".ply") return SceneFormat::Ply;
  if (ext == ".obj" || ext.empty() || ext == ".") return SceneFormat::Obj;
  throw InputError(path + ": unknown scene format '" + ext + "' (tracer reads .obj, .gltf, .glb and .ply)");
}

Scene load_scene_file(const std::string& path, const WarningSink& warn, CancelFlag cancel, const LoadLimits& limits,
                      LoadPhases* phases) {
  switch (path == "-" ? SceneFormat::Obj : scene_format(path)) {
    case SceneFormat::Gltf:
      return load_gltf(path, warn, cancel, limits, phases);
    case SceneFormat::Ply:
      return load_ply(path, warn, cancel, limits, phases);
    case SceneFormat::Obj:
      break;
  }
  return load_obj(path, warn, cancel, limits, phases);
}

}  // namespace tracer
