// The scene and camera a render's flags describe.
#pragma once

#include "driver/render_args.hpp"
#include "scene/scene.hpp"

namespace tracer::driver {

// Loads the OBJ (or builds the built-in scene) and applies --light / --no-scene-lights.
// "-" reads the OBJ from standard input. `quiet` drops the loader's warnings.
Scene load_scene(const SceneArgs& args, bool quiet, CancelFlag cancel = nullptr, LoadPhases* phases = nullptr);
CameraSpec camera_for(const Scene& scene, const RenderArgs& args);

}  // namespace tracer::driver
