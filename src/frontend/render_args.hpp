// The flags of a render (tracer render, view and tracer-mpi) as values. Their names, ranges and
// help are settings_table.hpp's; what they become is render_options.hpp's (settings, accelerator
// and scheduler options), scene_setup.hpp's (the scene and camera) and prepare_render.hpp's.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "accel/accelerator.hpp"
#include "frontend/render_driver.hpp"
#include "importers/load_limits.hpp"
#include "io/exr_io.hpp"
#include "math/vec.hpp"
#include "render/render_image.hpp"

namespace CLI {
class Option;
class App;  // CLI11: only the files that add or parse flags include it (a heavy header)
}  // namespace CLI

namespace tracer::frontend {

struct SceneArgs {
  std::string scene;  // empty: the built-in Cornell box; .obj, .gltf, .glb or .ply
  std::string view;   // a view of the views file: its scene, camera and light
  std::string views;  // empty: ../shared/scenes/views.tsv
  int builtin_spheres = 0;
  std::vector<Vec3> lights;
  bool no_scene_lights = false;
  std::optional<double> light_intensity;
  std::string env_map;        // an equirectangular .exr or .hdr lighting the scene from beyond
  double env_rotation = 0.0;  // degrees about +y
  std::optional<int> camera;  // --camera: which of a glTF's cameras (default its first)
  long long max_input_mib = kDefaultMaxInputBytes >> 20;              // --max-input-mib: the scene file
  long long max_texture_mib = TextureLimits{}.max_total_bytes >> 20;  // --max-texture-mib: all textures
  std::optional<long long> max_memory_mib;  // --max-memory-mib: empty, the available memory less a margin
};

// --simd: the SIMD kernels where the CPU has them, or scalar code only.
enum class SimdUse { Auto, Off };
inline constexpr EnumName<SimdUse> kSimdUseNames[] = {{SimdUse::Auto, "auto"}, {SimdUse::Off, "off"}};

// What a render's flags hold, typed as they are used; settings_table.hpp says each flag's range
// and help. The defaults are the library's own (RenderSettings, BvhBuildOptions, AccelOptions,
// SchedOptions): the flags write into those structs.
struct RenderArgs {
  SceneArgs scene;
  RenderSettings settings;  // --width --height --ao --ambient --exposure --seed --max-depth ...
  BvhBuildOptions bvh;      // --max-leaf --bins --traversal-cost --bvh-split --build
  SchedOptions sched;       // --sched --tile --block
  std::optional<Vec3> eye, look, up;
  std::optional<float> fov;
  std::optional<double> aperture;        // --aperture: the lens radius, in scene units
  std::optional<double> focus_distance;  // --focus-distance: default the look-at point's
  std::optional<double> ao_distance;
  std::optional<AccelKind> accel;             // empty: the library's default (scalar bvh with --simd off)
  std::optional<BuildQuality> build_quality;  // empty: chosen by the work (default_build_quality)
  std::optional<bool> packets;                // --packets / --no-packets; empty: where the accelerator can
  std::optional<bool> streams;                // --streams / --no-streams; empty: where the accelerator can
  // path for a user's render (every material, soft shadows, indirect light); the library's
  // default, and bench's, stays the study's ao.
  Integrator integrator = Integrator::Path;
  SimdUse simd = SimdUse::Auto;
  ExrPixel exr = ExrPixel::Half;
  SimdTarget simd_target = SimdTarget::Auto;
  std::optional<int> spp;                 // samples per pixel (default kDefaultPathSpp for path, else 1)
  std::optional<Vec3> env;                // path, whitted: uniform environment radiance
  std::string aov;                        // path: albedo,normal,... layers in the EXR
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

// A file-name option that refuses an empty name (`--stats-json ''` silently wrote nothing).
CLI::Option* file_option(CLI::Option* option);
// The flags of settings_table.hpp that a render reads (every row).
void add_render_options(CLI::App& app, RenderArgs& args);
// -o/--output, --stats, --stats-json and -q/--quiet, as tracer render and tracer-mpi render share
// them; `writer` says who writes the files (e.g. " (written by rank 0)"), `stats` what --stats prints.
void add_output_options(CLI::App& app, RenderArgs& args, const std::string& writer, const std::string& stats);

// Checks every flag; throws UsageError naming the flag. Changes nothing.
void validate(const RenderArgs& args);

}  // namespace tracer::frontend
