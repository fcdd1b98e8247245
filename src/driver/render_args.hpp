// The flags of a render (tracer render, bench, view and tracer-mpi): what they are, their
// defaults, and their check. What they become is render_options.hpp's (settings, accelerator and
// scheduler options), scene_setup.hpp's (the scene and camera) and prepare_render.hpp's (all of it).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "accel/accelerator.hpp"
#include "driver/render_driver.hpp"
#include "importers/load_limits.hpp"
#include "io/exr_io.hpp"
#include "render/render_image.hpp"

namespace CLI {
class Option;
class App;  // CLI11: only the files that add or parse flags include it (a heavy header)
}  // namespace CLI

namespace tracer::driver {

struct SceneArgs {
  std::string scene;  // empty: the built-in Cornell box; .obj, .gltf, .glb or .ply
  std::string view;   // a view of the views file: its scene, camera and light
  std::string views;  // empty: ../shared/scenes/views.tsv
  int builtin_spheres = 0;
  std::vector<std::string> lights;
  bool no_scene_lights = false;
  std::optional<double> light_intensity;
  std::string env_map;        // an equirectangular .exr or .hdr lighting the scene from beyond
  double env_rotation = 0.0;  // degrees about +y
  std::optional<int> camera;  // --camera: which of a glTF's cameras (default its first)
  long long max_input_mib = kDefaultMaxInputBytes >> 20;              // --max-input-mib: the scene file
  long long max_texture_mib = TextureLimits{}.max_total_bytes >> 20;  // --max-texture-mib: all textures
  std::optional<long long> max_memory_mib;  // --max-memory-mib: empty, the available memory less a margin
};

// The defaults are the library's own (RenderSettings, BvhBuildOptions, AccelOptions,
// SchedOptions): the flags bind to those structs, and named values start from their tables.
struct RenderArgs {
  SceneArgs scene;
  RenderSettings settings;  // --width --height --ao --ambient --exposure --seed --packets
  BvhBuildOptions bvh;      // --max-leaf --bins --traversal-cost
  SchedOptions sched;       // --tile --block
  std::string eye, look, up;
  std::optional<double> fov;
  std::optional<double> aperture;        // --aperture: the lens radius, in scene units
  std::optional<double> focus_distance;  // --focus-distance: default the look-at point's
  std::optional<double> ao_distance;
  std::optional<std::string> accel;          // empty: the library's default (scalar bvh with --simd off)
  std::optional<std::string> build_quality;  // empty: chosen by the work (default_build_quality)
  bool packets = false, no_packets = false;  // neither: packets where the accelerator can
  std::string split{name_of<BvhSplit>(kBvhSplitNames, BvhBuildOptions{}.split)};
  std::string build{name_of<Strategy>(kStrategyNames, BvhBuildOptions{}.strategy)};
  std::string sched_kind{name_of<Strategy>(kStrategyNames, SchedOptions{}.strategy)};
  // path for a user's render (every material, soft shadows, indirect light); the library's
  // default, and bench's, stays the study's ao.
  std::string integrator{name_of<Integrator>(kIntegratorNames, Integrator::Path)};
  std::string simd = "auto";
  std::string exr{name_of<ExrPixel>(kExrPixelNames, ExrPixel::Half)};
  std::string simd_target{name_of<SimdTarget>(kSimdTargetNames, SimdTarget::Auto)};
  std::string light_sampling{name_of<LightSampling>(kLightSamplingNames, RenderSettings{}.light_sampling)};
  std::optional<int> spp;                 // path: samples per pixel (default kDefaultPathSpp)
  std::string env;                        // path: uniform environment radiance r,g,b
  std::string aov;                        // path: albedo,normal layers in the EXR
  std::optional<double> checkpoint;       // path: seconds between rewrites of the output
  std::optional<double> noise_threshold;  // path: adaptive sampling's (default kDefaultNoiseThreshold)
  std::optional<int> min_spp;             // path: adaptive sampling's minimum samples per pixel
  int frames = 1;                         // --frames: an image sequence, the camera orbiting
  double orbit = 0.0;                     // --orbit: degrees the camera turns over the whole sequence
  std::optional<int> threads;
  std::string output = "render.png";
  bool stats = false, quiet = false, save_partial = false;
  bool count = false;    // --count: traversal counters in the statistics
  bool denoise = false;  // --denoise: path: the image denoised (denoise/nfor.hpp)
  std::string stats_json;
};

void add_scene_options(CLI::App& app, SceneArgs& args);
// A file-name option that refuses an empty name (`--stats-json ''` silently wrote nothing).
CLI::Option* file_option(CLI::Option* option);
void add_render_options(CLI::App& app, RenderArgs& args);
// -o/--output, --stats, --stats-json and -q/--quiet, as tracer render and tracer-mpi render share
// them; `writer` says who writes the files (e.g. " (written by rank 0)"), `stats` what --stats prints.
void add_output_options(CLI::App& app, RenderArgs& args, const std::string& writer, const std::string& stats);

// Checks every flag; throws UsageError naming the flag. Changes nothing.
void validate(const RenderArgs& args);

}  // namespace tracer::driver
