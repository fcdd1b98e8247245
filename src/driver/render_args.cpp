#include "driver/render_args.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <numbers>
#include <sstream>

#include "base/errors.hpp"
#include "driver/parse.hpp"
#include "driver/render_options.hpp"
#include "importers/scene_file.hpp"
#include "io/environment_io.hpp"
#include "io/image_io.hpp"
#include "parallel/executor.hpp"
#include "scene/builtin.hpp"
#include "scene/camera.hpp"
#include "scene/value_limits.hpp"
#include "scene/views.hpp"

namespace tracer::driver {

namespace fs = std::filesystem;

CLI::Option* file_option(CLI::Option* option) {
  return option->check(CLI::Validator(
      [](const std::string& s) { return s.empty() ? std::string("an empty file name") : std::string(); }, "FILE"));
}

namespace {

// A whole number in [lo, hi], checked on the text as given (CLI11 saturates a number beyond
// long long, so the message would otherwise quote 9223372036854775807).
CLI::Option* whole_option(CLI::Option* option, long long lo, long long hi) {
  return option->check(CLI::Validator(
      [lo, hi](const std::string& s) {
        long long v = 0;
        const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
        if (ptr == s.data() + s.size() && ec == std::errc{} && v >= lo && v <= hi) return std::string();
        return "must be between " + std::to_string(lo) + " and " + std::to_string(hi) + ", got " + s;
      },
      "INT"));
}

}  // namespace

void add_scene_options(CLI::App& app, SceneArgs& a) {
  file_option(app.add_option("scene,-m,--scene", a.scene,
                             "scene to render: .obj, .gltf, .glb or .ply (default: the built-in Cornell box)"));
  app.add_option("--view", a.view, "render a named view: its scene, camera and light (e.g. sponza, cornell-water)");
  file_option(app.add_option("--views", a.views, "the views file for --view (default ../shared/scenes/views.tsv)"));
  app.add_option("--builtin-spheres", a.builtin_spheres,
                 "built-in scene: add two spheres of about this many triangles each");
  app.add_option("--light", a.lights, "add a point light at x,y,z (repeatable)");
  app.add_flag("--no-scene-lights", a.no_scene_lights, "drop the scene's emissive lights, keep only --light ones");
  app.add_option("--light-intensity", a.light_intensity, "point light intensity (default: (scene diagonal / 2)^2)");
  file_option(
      app.add_option("--env-map", a.env_map,
                     "path, whitted: light the scene from beyond with this equirectangular environment map (.exr or "
                     ".hdr, linear radiance; times --env)"));
  app.add_option("--env-rotation", a.env_rotation, "degrees the --env-map turns about +y")->capture_default_str();
  app.add_option("--camera", a.camera, "a glTF scene's camera N, counting from 0 in node order (default 0)");
  whole_option(app.add_option("--max-input-mib", a.max_input_mib, "largest scene file read, in MiB (1-1048576)"), 1,
               1 << 20)
      ->capture_default_str();
  whole_option(
      app.add_option("--max-texture-mib", a.max_texture_mib,
                     "memory all the scene's textures may take, in MiB (1-1048576); past it a texture is not used"),
      1, 1 << 20)
      ->capture_default_str();
  whole_option(app.add_option("--max-memory-mib", a.max_memory_mib,
                              "memory the scene, its accelerator and the image may take, in MiB (1-1073741824; "
                              "default: the memory available less a tenth); a render estimated above it is refused"),
               1, 1 << 30);
}

void add_output_options(CLI::App& app, RenderArgs& a, const std::string& writer, const std::string& stats) {
  file_option(app.add_option("-o,--output", a.output,
                             "output image: .png or .ppm (tone-mapped), .exr (linear radiance)" + writer))
      ->capture_default_str();
  app.add_flag("--stats", a.stats, "print " + stats);
  file_option(app.add_option("--stats-json", a.stats_json,
                             "write the statistics as JSON to this file ('-': standard output)" + writer));
  app.add_flag("-q,--quiet", a.quiet, "no progress bar, no loader warnings");
}

void add_render_options(CLI::App& app, RenderArgs& a) {
  add_scene_options(app, a.scene);
  RenderSettings& s = a.settings;
  app.add_option("--width", s.width, "image width in pixels (1-16384)")->capture_default_str();
  app.add_option("--height", s.height, "image height in pixels (1-16384)")->capture_default_str();
  app.add_option("--eye,-v", a.eye, "camera position x,y,z (default: frame the scene from the front)");
  app.add_option("--look,-l", a.look, "point the camera looks at, x,y,z");
  app.add_option("--up", a.up, "camera up vector x,y,z (default 0,1,0)");
  app.add_option("--fov", a.fov, "vertical field of view in degrees (default 53.13)");
  app.add_option("--aperture", a.aperture,
                 "depth of field: the radius of a thin lens, in scene units (default 0: a pinhole, all sharp)");
  app.add_option("--focus-distance", a.focus_distance,
                 "with --aperture: the distance of the plane in focus along the view (default: the look-at point's)");
  app.add_option("--integrator", a.integrator,
                 "what a pixel is made of: ao (the study's workload: direct light, ambient occlusion, every surface "
                 "diffuse), whitted (mirrors and glass from the MTL, hard shadows) or path (path tracing: every "
                 "material, emissive triangles as area lights, soft shadows, indirect light)")
      ->capture_default_str();
  app.add_option("--max-depth", s.max_depth,
                 "whitted: reflections and refractions followed; path: bounces per path (0-64)")
      ->capture_default_str();
  app.add_option("--spp", a.spp,
                 "samples per pixel (1-1048576; default " + std::to_string(kDefaultPathSpp) +
                     " for path, 1 through the pixel centre for ao and whitted)");
  app.add_option("--noise-threshold", a.noise_threshold,
                 "path: adaptive sampling: a 4x4 block of pixels stops taking samples once each pixel's noise "
                 "estimate is below this (0-1; default " +
                     (std::ostringstream() << kDefaultNoiseThreshold).str() +
                     ", 0 with --denoise; 0 gives every pixel --spp samples)");
  app.add_option("--min-spp", a.min_spp,
                 "path: adaptive sampling: samples every pixel takes before it may stop (2-1048576; default " +
                     std::to_string(RenderSettings{}.min_spp) + ")");
  app.add_option(
      "--env", a.env,
      "path, whitted: radiance r,g,b of a uniform environment, or the --env-map's scale (default black, 1,1,1 "
      "with --env-map; white when the scene has no light)");
  app.add_option("--aov", a.aov,
                 "path: also write these layers into the .exr output: albedo and normal of the first hit, samples "
                 "(each pixel's sample count), and with --denoise noisy (the image before denoising) and variance "
                 "(of each pixel's mean); comma-separated");
  app.add_flag("--denoise", a.denoise,
               "path: denoise the image (NFOR, a feature-guided regression on the albedo, normal and distance of "
               "the first surface that is not a mirror or glass); --aov noisy,variance keep what it started from");
  app.add_option("--light-sampling", a.light_sampling,
                 "path: " + names_of<LightSampling>(kLightSamplingNames) +
                     " (mis: emitter samples and BSDF samples combined; bsdf: BSDF samples only)")
      ->capture_default_str();
  app.add_option("--frames", a.frames,
                 "render an image sequence of this many frames: -o NAME.png gives NAME-0000.png ...")
      ->capture_default_str();
  app.add_option("--orbit", a.orbit,
                 "degrees the camera turns about the look point (around --up) over the --frames sequence")
      ->capture_default_str();
  app.add_option("--checkpoint", a.checkpoint,
                 "path: rewrite the output every this many seconds while samples accumulate");
  app.add_option("--ao", s.ao_samples, "ambient-occlusion rays per hit, 0 = off")->capture_default_str();
  app.add_option("--ao-distance", a.ao_distance, "maximum distance of AO rays (default: unbounded)");
  app.add_option("--ambient", s.ambient, "ambient light strength")->capture_default_str();
  app.add_option("--exposure", s.exposure, "tone-mapping exposure of .png and .ppm outputs")->capture_default_str();
  app.add_option("--exr", a.exr, "pixel type of .exr outputs (linear radiance, no tone mapping): half or float")
      ->capture_default_str();
  app.add_option("--seed", s.seed, "seed of the AO sample pattern")->capture_default_str();
  app.add_option("--accel", a.accel,
                 "accelerator: " + names_of<AccelKind>(kAccelKindNames) + " (default " +
                     std::string(name_of<AccelKind>(kAccelKindNames, AccelOptions{}.kind)) + ", the fastest)");
  app.add_option("--build-quality", a.build_quality,
                 "bvh8 and embree: " + names_of<BuildQuality>(kBuildQualityNames) +
                     " (high: spatial splits, a slower build for faster closest hits; default high for a path "
                     "render of at least 16 pixel samples per triangle, else medium, and medium in tracer view)");
  app.add_option("--bvh-split", a.split, "BVH split: " + names_of<BvhSplit>(kBvhSplitNames) + " (the study's)")
      ->capture_default_str();
  app.add_option("--build-sched", a.build, "how the BVH build forks: seq, async, queue or tbb")->capture_default_str();
  app.add_option("--max-leaf", a.bvh.max_leaf, "SAH BVH: largest leaf (1-16)")->capture_default_str();
  app.add_option("--bins", a.bvh.bins, "SAH BVH: bins per axis (4-32)")->capture_default_str();
  app.add_option("--traversal-cost", a.bvh.traversal_cost,
                 "SAH BVH: cost of a node step relative to a triangle test (0-100)")
      ->capture_default_str();
  app.add_option("--simd", a.simd, "SIMD kernels: auto, or off (scalar traversal: --accel bvh by default)")
      ->capture_default_str();
  app.add_option(
         "--simd-target", a.simd_target,
         "bvh8 kernels: " + names_of<SimdTarget>(kSimdTargetNames) + " (force a narrower target than the CPU's)")
      ->capture_default_str();
  app.add_flag("--packets", a.packets,
               "trace rays together: each hit's AO rays as one bundle (bvh, bvh8, embree), primary rays and shadow "
               "rays per 4x4-pixel block (bvh8, embree); same image (default: on where the accelerator can)");
  app.add_flag("--no-packets", a.no_packets, "trace every ray alone (same image, slower)")->excludes("--packets");
  app.add_option("--sched", a.sched_kind, "scheduler: " + names_of<Strategy>(kStrategyNames))->capture_default_str();
  app.add_option("--threads", a.threads, "worker threads (default: all hardware threads)");
  app.add_option("--tile", a.sched.tile, "tile edge in pixels for the atomic and tbb schedulers")
      ->capture_default_str();
  app.add_option("--block", a.sched.block, "pixels per row block for the queue scheduler")->capture_default_str();
}

void validate(const RenderArgs& a) {
  const RenderSettings& s = a.settings;
  check_range("--width", s.width, 1, 16384);
  check_range("--height", s.height, 1, 16384);
  check_range("--ao", s.ao_samples, 0, 4096);
  check_range("--max-depth", s.max_depth, 0, 64);
  if (a.spp) check_range("--spp", *a.spp, 1, 1 << 20);
  if (a.noise_threshold) check_range_real("--noise-threshold", *a.noise_threshold, 0.0, 1.0);
  if (a.min_spp) check_range("--min-spp", *a.min_spp, 2, 1 << 20);
  check_range("--frames", a.frames, 1, 1'000'000);
  check_range_real("--orbit", a.orbit, -1e6, 1e6);
  check_range_real("--env-rotation", a.scene.env_rotation, -1e6, 1e6);
  if (a.checkpoint) check_range_real("--checkpoint", *a.checkpoint, 0.0, 1e9, LowEnd::Open);
  if (!a.env.empty()) {
    const Vec3 env = parse_vec3("--env", a.env);
    if (env.x < 0.0f || env.y < 0.0f || env.z < 0.0f || max_component(env) > 1e30f) {
      throw UsageError("--env: each component must be in [0, 1e30], got '" + a.env + "'");
    }
  }
  if (a.ao_distance) check_range_real("--ao-distance", *a.ao_distance, 0.0, 1e30, LowEnd::Open);
  if (a.fov) check_range_real("--fov", *a.fov, kMinFovDegrees, kMaxFovDegrees);
  if (a.aperture) check_range_real("--aperture", *a.aperture, 0.0, 1e6);
  if (a.focus_distance) check_range_real("--focus-distance", *a.focus_distance, 0.0, 1e12, LowEnd::Open);
  check_range_real("--ambient", s.ambient, 0.0, 1e6);
  check_range_real("--exposure", s.exposure, 0.0, 1e6, LowEnd::Open);
  check_range("--builtin-spheres", a.scene.builtin_spheres, 0, 10'000'000);
  if (a.scene.light_intensity) check_range_real("--light-intensity", *a.scene.light_intensity, 0.0, kMaxLightIntensity);
  if (a.threads) check_range("--threads", *a.threads, 1, 1024);
  check_range("--tile", a.sched.tile, 1, 4096);
  check_range("--block", a.sched.block, 1, 1 << 20);
  check_range("--max-leaf", a.bvh.max_leaf, 1, 16);
  check_range("--bins", a.bvh.bins, 4, 32);
  check_range_real("--traversal-cost", a.bvh.traversal_cost, 0.0, 100.0, LowEnd::Open);
  if (!a.eye.empty()) parse_point("--eye", a.eye);
  if (!a.look.empty()) parse_point("--look", a.look);
  if (!a.up.empty()) {
    if (length(parse_vec3("--up", a.up)) == 0.0f) throw UsageError("--up: must not be the zero vector");
  }
  for (const auto& l : a.scene.lights) parse_point("--light", l);
  const AccelOptions accel = accel_options_for(a);
  if (a.packets && !traces_rays_together(accel.kind)) {
    throw UsageError("--packets: needs --accel bvh, bvh8 or embree (the accelerators with packet kernels)");
  }
  sched_options_for(a);
  simd_target_for(a);
  settings_for(a);
  if (a.denoise && a.integrator != name_of<Integrator>(kIntegratorNames, Integrator::Path)) {
    throw UsageError("--denoise: only for --integrator path (it is guided by path tracing's features)");
  }
  exr_pixel_for(a);
  aovs_for(a);
}

}  // namespace tracer::driver
