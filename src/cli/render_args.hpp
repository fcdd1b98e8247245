// The flags shared by `tracer render` and `tracer bench`, and turning them into a scene, a camera,
// an accelerator and a scheduler.
#pragma once

#include <CLI/CLI.hpp>

#include <optional>
#include <string>
#include <vector>

#include "accel/accelerator.hpp"
#include "render/shading.hpp"
#include "scene/scene.hpp"
#include "sched/scheduler.hpp"

namespace tracer::cli {

struct SceneArgs {
  std::string scene;  // empty: the built-in Cornell box
  int builtin_spheres = 0;
  std::vector<std::string> lights;
  bool no_scene_lights = false;
  std::optional<double> light_intensity;
};

struct RenderArgs {
  SceneArgs scene;
  int width = 1024, height = 1024;
  std::string eye, look, up;
  std::optional<double> fov;
  int ao = 16;
  std::optional<double> ao_distance;
  double ambient = 0.25, exposure = 1.5;
  unsigned seed = 0;
  std::string accel = "bvh", split = "sah", build = "tasks";
  int max_leaf = 4, bins = 16;
  double traversal_cost = 1.5;  // SAH: a node step relative to a triangle test
  std::string simd = "auto";
  std::string simd_target = "auto";
  bool packets = false;
  std::string sched = "tbb";
  std::optional<int> threads;
  int tile = 16, block = 64;
  std::string output = "render.png";
  bool stats = false, quiet = false, save_partial = false;
  std::string stats_json;
};

void add_scene_options(CLI::App& app, SceneArgs& args);
void add_render_options(CLI::App& app, RenderArgs& args);

// Loads the OBJ (or builds the built-in scene) and applies --light / --no-scene-lights.
// "-" reads the OBJ from standard input. `quiet` drops the loader's warnings.
Scene load_scene(const SceneArgs& args, bool quiet, CancelFlag cancel = nullptr);
// -o and --stats-json: known formats, writable, and neither of them the input scene or each other.
void check_outputs(const RenderArgs& args);
CameraSpec camera_for(const Scene& scene, const RenderArgs& args);
RenderSettings settings_for(const RenderArgs& args);
AccelOptions accel_options_for(const RenderArgs& args);
SchedOptions sched_options_for(const RenderArgs& args);
void validate(const RenderArgs& args);  // throws UsageError naming the flag

}  // namespace tracer::cli
