#include "driver/render_args.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <numbers>

#include "base/errors.hpp"
#include "driver/parse.hpp"
#include "importers/obj_loader.hpp"
#include "io/environment_io.hpp"
#include "io/image_io.hpp"
#include "parallel/executor.hpp"
#include "scene/builtin.hpp"
#include "scene/camera.hpp"
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
  file_option(app.add_option("scene,-m,--scene", a.scene, "OBJ file to render (default: the built-in Cornell box)"));
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
  whole_option(app.add_option("--max-input-mib", a.max_input_mib, "largest OBJ file read, in MiB (1-1048576)"), 1,
               1 << 20)
      ->capture_default_str();
  whole_option(
      app.add_option("--max-texture-mib", a.max_texture_mib,
                     "memory all the scene's textures may take, in MiB (1-1048576); past it a texture is not used"),
      1, 1 << 20)
      ->capture_default_str();
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
  app.add_option(
      "--env", a.env,
      "path, whitted: radiance r,g,b of a uniform environment, or the --env-map's scale (default black, 1,1,1 "
      "with --env-map; white when the scene has no light)");
  app.add_option("--aov", a.aov,
                 "path: also write these layers of the first hit into the .exr output, for a denoiser: albedo, "
                 "normal (comma-separated)");
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
  app.add_option("--bvh-split", a.split, "BVH split: " + names_of<BvhSplit>(kBvhSplitNames) + " (the study's)")
      ->capture_default_str();
  app.add_option("--build", a.build, "BVH build: " + names_of<BuildMode>(kBuildModeNames))->capture_default_str();
  app.add_option("--max-leaf", a.bvh.max_leaf, "SAH BVH: largest leaf (1-16)")->capture_default_str();
  app.add_option("--bins", a.bvh.bins, "SAH BVH: bins per axis (4-32)")->capture_default_str();
  app.add_option("--traversal-cost", a.bvh.traversal_cost,
                 "SAH BVH: cost of a node step relative to a triangle test (0-100)")
      ->capture_default_str();
  app.add_option("--simd", a.simd, "SIMD kernels: auto, or off (--accel brute: the scalar baseline)")
      ->capture_default_str();
  app.add_option(
         "--simd-target", a.simd_target,
         "bvh8 kernels: " + names_of<SimdTarget>(kSimdTargetNames) + " (force a narrower target than the CPU's)")
      ->capture_default_str();
  app.add_flag("--packets", a.packets,
               "trace rays together: each hit's AO rays as one bundle (bvh, bvh8, embree), primary rays and shadow "
               "rays per 4x4-pixel block (bvh8, embree); same image (default: on where the accelerator can)");
  app.add_flag("--no-packets", a.no_packets, "trace every ray alone (same image, slower)")->excludes("--packets");
  app.add_option("--sched", a.sched_kind, "scheduler: " + names_of<SchedKind>(kSchedKindNames))->capture_default_str();
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
  check_range("--frames", a.frames, 1, 1'000'000);
  check_range_real("--orbit", a.orbit, -1e6, 1e6);
  check_range_real("--env-rotation", a.scene.env_rotation, -1e6, 1e6);
  if (a.checkpoint) check_range_real("--checkpoint", *a.checkpoint, 0.0, 1e9, true);
  if (!a.env.empty()) {
    const Vec3 env = parse_vec3("--env", a.env);
    if (env.x < 0.0f || env.y < 0.0f || env.z < 0.0f || max_component(env) > 1e30f) {
      throw UsageError("--env: each component must be in [0, 1e30], got '" + a.env + "'");
    }
  }
  if (a.ao_distance) check_range_real("--ao-distance", *a.ao_distance, 0.0, 1e30, true);
  if (a.fov) check_range_real("--fov", *a.fov, 1e-3, 179.0);
  check_range_real("--ambient", s.ambient, 0.0, 1e6);
  check_range_real("--exposure", s.exposure, 0.0, 1e6, true);
  check_range("--builtin-spheres", a.scene.builtin_spheres, 0, 10'000'000);
  if (a.scene.light_intensity) check_range_real("--light-intensity", *a.scene.light_intensity, 0.0, 1e30);
  if (a.threads) check_range("--threads", *a.threads, 1, 1024);
  check_range("--tile", a.sched.tile, 1, 4096);
  check_range("--block", a.sched.block, 1, 1 << 20);
  check_range("--max-leaf", a.bvh.max_leaf, 1, 16);
  check_range("--bins", a.bvh.bins, 4, 32);
  check_range_real("--traversal-cost", a.bvh.traversal_cost, 0.0, 100.0, true);
  if (!a.eye.empty()) parse_point("--eye", a.eye);
  if (!a.look.empty()) parse_point("--look", a.look);
  if (!a.up.empty()) {
    if (length(parse_vec3("--up", a.up)) == 0.0f) throw UsageError("--up: must not be the zero vector");
  }
  for (const auto& l : a.scene.lights) parse_point("--light", l);
  const AccelOptions accel = accel_options_for(a);
  if (a.packets && !has_packet_kernels(accel.kind)) {
    throw UsageError("--packets: needs --accel bvh, bvh8 or embree (the accelerators with packet kernels)");
  }
  sched_options_for(a);
  simd_target_for(a);
  settings_for(a);
  exr_pixel_for(a);
  aovs_for(a);
}

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
  return fs::weakly_canonical(fs::absolute(a), ec) == fs::weakly_canonical(fs::absolute(b), ec);
}

void check_outputs(const RenderArgs& a) {
  image_format_for(a.output, "-o");
  if (!a.scene.scene.empty() && a.scene.scene != "-" && same_file(a.output, a.scene.scene)) {
    throw UsageError("-o: '" + a.output + "' is the input scene");
  }
  check_writable(a.output);
  if (a.stats_json.empty() || a.stats_json == "-") return;
  if (!a.scene.scene.empty() && a.scene.scene != "-" && same_file(a.stats_json, a.scene.scene)) {
    throw UsageError("--stats-json: '" + a.stats_json + "' is the input scene");
  }
  if (same_file(a.stats_json, a.output)) throw UsageError("--stats-json: '" + a.stats_json + "' is also the -o image");
  check_writable(a.stats_json);
}

void check_outputs_against_inputs(const RenderArgs& a) {
  for (int frame = 0; frame < a.frames; ++frame) check_output(frame_output(a.output, frame, a.frames), "-o");
  if (!a.stats_json.empty() && a.stats_json != "-") check_output(a.stats_json, "--stats-json");
}

namespace {

// --no-scene-lights and --light, on top of the scene's (or the view's) lights.
void add_lights(Scene& scene, const SceneArgs& a) {
  if (a.no_scene_lights) {
    scene.lights.clear();
    scene.emitters = Emitters{};
  }
  const float intensity = a.light_intensity ? float(*a.light_intensity) : scene.default_light_intensity();
  for (const std::string& text : a.lights) {
    Light l;
    l.position = parse_point("--light", text);
    l.power = Vec3{intensity};
    scene.lights.push_back(l);
  }
}

// --env-map: read once the scene is known good, so a bad scene is reported first. What the map
// holds that cannot light the scene as written is said, once each.
void add_environment(Scene& scene, const SceneArgs& a, CancelFlag cancel, const WarningSink& warn) {
  check_range_real("--env-rotation", a.env_rotation, -1e6, 1e6);
  if (a.env_map.empty()) return;
  scene.environment_map = load_environment_map(a.env_map, a.env_rotation, cancel);
  const EnvironmentMap& map = scene.environment_map;
  const auto say = [&](const std::string& what) {
    if (warn)
      warn(a.env_map + ": " + what);
    else
      std::cerr << "tracer: warning: " << a.env_map << ": " << what << "\n";
  };
  if (map.zeroed_values() > 0) {
    say(std::to_string(map.zeroed_values()) + " texel values negative or not finite, read as 0");
  }
  if (map.clamped_values() > 0) {
    say(std::to_string(map.clamped_values()) + " texel values above 1e30, read as 1e30");
  }
  if (map.black()) say("the environment map is black: it lights nothing");
}

}  // namespace

Scene load_scene(const SceneArgs& a, bool quiet, CancelFlag cancel, LoadPhases* phases) {
  check_range("--max-input-mib", a.max_input_mib, 1, 1 << 20);
  check_range("--max-texture-mib", a.max_texture_mib, 1, 1 << 20);
  LoadLimits limits;
  limits.max_obj_bytes = uint64_t(a.max_input_mib) << 20;
  limits.textures.max_total_bytes = uint64_t(a.max_texture_mib) << 20;
  // Textures are read and decoded on every thread the render may use.
  const Executor executor(Strategy::Tbb);
  limits.for_each = [&executor](size_t count, const std::function<void(size_t)>& body) {
    executor.for_each(count, body);
  };
  const WarningSink silent = [](const std::string&) {};
  const WarningSink warn = quiet ? silent : WarningSink{};
  if (!a.view.empty()) {
    const std::string path = a.views.empty() ? default_views_path() : a.views;
    const View view = find_view(load_views(path), a.view, path);
    // The view names its scene; a scene given too must be that file (by any path to it).
    if (!a.scene.empty() && !same_file(a.scene, view.obj)) {
      throw UsageError("--view: view '" + a.view + "' is of " + view.obj + ", not of the scene " + a.scene);
    }
    Scene scene = load_obj(view.obj, warn, cancel, limits, phases);
    apply_view_light(scene, view);
    scene.camera = view.camera;
    add_lights(scene, a);
    add_environment(scene, a, cancel, warn);
    return scene;
  }
  Scene scene = a.scene.empty() ? make_cornell_box(a.builtin_spheres) : load_obj(a.scene, warn, cancel, limits, phases);
  // A scene with no light of its own (Sponza, Sibenik, the Bunny) that a views.tsv beside it
  // knows: its view's camera, and its light unless --light gives one, so a plain render shows it
  // as the views mean it (from inside, lit) rather than framed from outside in the dark.
  if (!a.scene.empty() && a.scene != "-" && scene.lights.empty()) {
    std::string problem;
    const std::optional<View> view = view_of_scene_file(a.scene, &problem);
    if (!problem.empty() && !quiet) std::cerr << "tracer: warning: " << problem << " (its views are not used)\n";
    if (view) {
      // Its light unless another is given or --no-scene-lights drops it (add_lights, below).
      const bool view_light = a.lights.empty() && !a.no_scene_lights;
      if (view_light) apply_view_light(scene, *view);
      scene.camera = view->camera;
      if (!quiet) {
        std::cerr << "tracer: note: " << a.scene << " has no light of its own: using its view '" << view->name
                  << (view_light ? "' (camera and light)\n" : "' (camera)\n");
      }
    }
  }
  add_lights(scene, a);
  add_environment(scene, a, cancel, warn);
  return scene;
}

CameraSpec camera_for(const Scene& scene, const RenderArgs& a) {
  const float fov = a.fov ? float(*a.fov) : kDefaultFovDegrees;
  const Vec3 extent = scene.bounds.extent();
  if (a.eye.empty() && a.look.empty() && !scene.camera && std::max({extent.x, extent.y, extent.z}) == 0.0f) {
    throw InputError(scene.source +
                     ": all vertices coincide, so there is nothing to frame (every triangle is degenerate)");
  }
  CameraSpec spec =
      scene.camera && a.eye.empty() && a.look.empty() && !a.fov ? *scene.camera : frame_bounds(scene.bounds, fov);
  if (!a.eye.empty()) {
    spec.eye = parse_point("--eye", a.eye);
    if (a.look.empty()) spec.look = scene.bounds.center();
  }
  if (!a.look.empty()) spec.look = parse_point("--look", a.look);
  if (!a.up.empty()) {
    // Scaled first, so a huge but valid --up cannot overflow the cross products below.
    const Vec3 up = parse_vec3("--up", a.up);
    spec.up = up * (1.0f / std::max({std::fabs(up.x), std::fabs(up.y), std::fabs(up.z)}));
  }
  // A narrow --fov backs the framed camera off; past kMaxCameraDistance its rays could not reach
  // the scene without overflow (and Embree refuses such rays).
  if (std::max({std::fabs(spec.eye.x), std::fabs(spec.eye.y), std::fabs(spec.eye.z)}) > kMaxCameraDistance) {
    throw UsageError("--fov: " + std::to_string(spec.fov_degrees) +
                     " degrees frames this scene from too far away (beyond 4e12); widen it or give --eye");
  }
  const Vec3 forward = spec.look - spec.eye;
  if (length(forward) == 0.0f && a.eye.empty() && a.look.empty()) {
    // Framed by tracer, not placed by the user: the scene's extent is below what floats resolve.
    char size[32];
    std::snprintf(size, sizeof size, "%g", double(std::max({extent.x, extent.y, extent.z})));
    throw InputError(scene.source + ": the scene is too small to frame (its extent, " + size +
                     ", is below what a float camera resolves); give --eye and --look");
  }
  if (length(forward) == 0.0f) throw UsageError("--eye/--look: the camera looks at its own position");
  if (length(cross(forward, spec.up)) == 0.0f) throw UsageError("--up: parallel to the viewing direction");
  return spec;
}

CameraSpec frame_camera(const CameraSpec& spec, int frame, int frames, double orbit_degrees) {
  if (frames <= 1 || orbit_degrees == 0.0) return spec;
  const double angle = orbit_degrees * double(frame) / double(frames) * std::numbers::pi / 180.0;
  const Vec3 k = normalize(spec.up);
  const Vec3 v = spec.eye - spec.look;
  // Rodrigues: v cos + (k x v) sin + k (k . v)(1 - cos).
  const float c = float(std::cos(angle)), s = float(std::sin(angle));
  CameraSpec out = spec;
  out.eye = spec.look + v * c + cross(k, v) * s + k * (dot(k, v) * (1.0f - c));
  return out;
}

std::string frame_output(const std::string& output, int frame, int frames) {
  if (frames <= 1) return output;
  const fs::path p(output);
  // At least four digits, and as many as the last frame needs, so names sort in frame order.
  const int digits = std::max(4, int(std::to_string(frames - 1).size()));
  char number[24];
  std::snprintf(number, sizeof number, "-%0*d", digits, frame);
  return (p.parent_path() / (p.stem().string() + number + p.extension().string())).string();
}

RenderSettings settings_for(const RenderArgs& a) {
  RenderSettings s = a.settings;
  if (a.ao_distance) s.ao_distance = float(*a.ao_distance);
  s.integrator = parse_name<Integrator>(kIntegratorNames, a.integrator, "--integrator", "integrator");
  s.light_sampling =
      parse_name<LightSampling>(kLightSamplingNames, a.light_sampling, "--light-sampling", "light sampling");
  const bool path = s.integrator == Integrator::Path;
  if (a.checkpoint && !path) throw UsageError("--checkpoint: only for --integrator path");
  for (const auto& [flag, given] : {std::pair{"--env", !a.env.empty()}, {"--env-map", !a.scene.env_map.empty()}}) {
    if (given && s.integrator == Integrator::Ao)
      throw UsageError(std::string(flag) + ": only for --integrator path or whitted");
  }
  // Every integrator anti-aliases with --spp; ao and whitted take one centred sample by default.
  s.spp = a.spp.value_or(path ? kDefaultPathSpp : 1);
  if (!a.env.empty())
    s.environment = parse_vec3("--env", a.env);
  else if (!a.scene.env_map.empty())
    s.environment = Vec3{1.0f};
  // Packets by default where the accelerator has them, but not under --simd off (all scalar), and
  // not for whitted, whose rays go one at a time.
  const bool by_default = s.packets && !a.no_packets && a.simd != "off";
  s.packets =
      (a.packets || by_default) && has_packet_kernels(accel_options_for(a).kind) && s.integrator == Integrator::Ao;
  return s;
}

RenderSettings settings_for(const RenderArgs& a, const Scene& scene, std::string& note) {
  RenderSettings s = settings_for(a);
  note.clear();
  if (s.integrator == Integrator::Path && a.env.empty() && scene.environment_map.empty() && scene.emitters.empty()) {
    s.environment = Vec3{1.0f};
    note = scene.source +
           " has no emissive surface: a uniform white sky lights it too (--env 1,1,1; --env 0,0,0 for none)";
  }
  return s;
}

std::string black_image_warning(const RenderSettings& s, const Scene& scene) {
  std::string why;
  if (s.integrator == Integrator::Path) {
    why = scene.emitters.empty() && max_component(s.environment) == 0.0f
              ? "the scene has no emissive surface and --env is black"
              : "no light reaches what the camera sees (an emitter out of view or too small, or --exposure too low)";
  } else {
    why = scene.lights.empty() && s.ambient == 0.0f ? "the scene has no light and --ambient is 0"
                                                    : "no light reaches what the camera sees";
  }
  return "the image is black: " + why +
         "; --integrator path --env 1,1,1 lights it with a white sky, --light x,y,z adds a point light";
}

Aovs aovs_for(const RenderArgs& a) {
  Aovs aovs;
  if (a.aov.empty()) return aovs;
  for (const std::string& name : split_list("--aov", a.aov)) {
    if (name == "albedo") {
      aovs.albedo = true;
    } else if (name == "normal") {
      aovs.normal = true;
    } else {
      throw UsageError("--aov: unknown layer '" + name + "' (expected albedo, normal)");
    }
  }
  if (a.integrator != name_of<Integrator>(kIntegratorNames, Integrator::Path)) {
    throw UsageError("--aov: only for --integrator path");
  }
  if (image_format_for(a.output) != ImageFormat::Exr) throw UsageError("--aov: the layers need an .exr output (-o)");
  return aovs;
}

AccelOptions accel_options_for(const RenderArgs& a) {
  AccelOptions o;
  o.bvh = a.bvh;
  const std::string simd = a.simd;
  if (simd != "auto" && simd != "off") throw UsageError("--simd: expected auto or off, got '" + a.simd + "'");

  // --simd off alone asks for the scalar baseline: the binary BVH, not the SIMD default.
  const AccelKind fallback = simd == "off" ? AccelKind::Bvh : o.kind;
  o.kind = a.accel ? parse_name<AccelKind>(kAccelKindNames, *a.accel, "--accel", "accelerator") : fallback;
  if (o.kind == AccelKind::BruteSimd && simd == "off") o.kind = AccelKind::Brute;
  if (o.kind == AccelKind::Bvh8 && simd == "off") {
    throw UsageError("--simd off: bvh8 is the SIMD tree; use --accel bvh for scalar traversal");
  }
  o.bvh.split = parse_name<BvhSplit>(kBvhSplitNames, a.split, "--bvh-split", "split");
  o.bvh.mode = parse_name<BuildMode>(kBuildModeNames, a.build, "--build", "builder");
  o.bvh.threads = a.threads.value_or(0);
  return o;
}

SchedOptions sched_options_for(const RenderArgs& a) {
  SchedOptions o = a.sched;
  o.kind = parse_name<SchedKind>(kSchedKindNames, a.sched_kind, "--sched", "scheduler");
  o.threads = a.threads.value_or(0);
  return o;
}

ExrPixel exr_pixel_for(const RenderArgs& a) {
  return parse_name<ExrPixel>(kExrPixelNames, a.exr, "--exr", "pixel type");
}

SimdTarget simd_target_for(const RenderArgs& a) {
  return parse_name<SimdTarget>(kSimdTargetNames, a.simd_target, "--simd-target", "target");
}

}  // namespace tracer::driver
