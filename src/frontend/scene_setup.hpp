// The scene and camera a render's flags describe.
#pragma once

#include <cstdint>

#include "frontend/render_args.hpp"
#include "scene/scene.hpp"
#include "scene/scene_info.hpp"

namespace tracer::frontend {

// What a load may take in memory (LoadLimits::max_memory): `bytes` (0: memory_limit(args)) for the
// scene and, for each triangle, `accel_bytes_per_triangle` for the accelerator built over it.
struct MemoryBudget {
  uint64_t bytes = 0;
  uint64_t accel_bytes_per_triangle = 0;
  bool keep_instances = true;  // false: a glTF's instances expanded (LoadLimits::keep_instances)
};

// Loads the OBJ (or builds the built-in scene) and applies --light / --no-scene-lights.
// "-" reads the OBJ from standard input. `quiet` drops the loader's warnings.
Scene load_scene(const SceneArgs& args, bool quiet, CancelFlag cancel = nullptr, LoadPhases* phases = nullptr,
                 const MemoryBudget& memory = {});
// What tracer info prints: a glTF's counted without placing its instances (gltf_info), any other
// scene's from its load.
SceneInfo scene_info(const SceneArgs& args, bool quiet);
CameraSpec camera_for(const Scene& scene, const RenderArgs& args);

}  // namespace tracer::frontend
