#include "frontend/scene_setup.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "base/errors.hpp"
#include "base/text.hpp"
#include "frontend/memory_estimate.hpp"
#include "frontend/output_checks.hpp"
#include "frontend/parse.hpp"
#include "importers/gltf_loader.hpp"
#include "importers/scene_file.hpp"
#include "io/environment_io.hpp"
#include "parallel/executor.hpp"
#include "scene/builtin.hpp"
#include "scene/camera.hpp"
#include "scene/views.hpp"

namespace tracer::frontend {

namespace {

// --no-scene-lights and --light, on top of the scene's (or the view's) lights. Dropping the
// scene's lights drops their emission too: a bounce that hits a lamp finds it black, as next-event
// estimation (which samples the emitters) does.
void add_lights(Scene& scene, const SceneArgs& a) {
  if (a.no_scene_lights) {
    for (Material& m : scene.materials) m.ke = Vec3{0.0f};
    for (Mesh& m : scene.meshes) m.emissive = false;
    scene.lights.clear();
    scene.emitters = Emitters{};
  }
  const float intensity = a.light_intensity ? float(*a.light_intensity) : scene.default_light_intensity();
  for (const Vec3& position : a.lights) {
    Light l;
    l.position = position;
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
    say(std::to_string(map.clamped_values()) + " texel values above the radiance limit 1e6, read as 1e6");
  }
  if (map.black()) say("the environment map is black: it lights nothing");
}

}  // namespace

Scene load_scene(const SceneArgs& a, bool quiet, CancelFlag cancel, LoadPhases* phases, const MemoryBudget& memory) {
  check_range("--max-input-mib", a.max_input_mib, 1, 1 << 20);
  check_range("--max-texture-mib", a.max_texture_mib, 1, 1 << 20);
  if (a.max_memory_mib) check_range("--max-memory-mib", *a.max_memory_mib, 1, 1ll << 30);
  LoadLimits limits;
  limits.max_memory = memory.bytes ? memory.bytes : memory_limit(a);
  limits.accel_bytes_per_triangle = memory.accel_bytes_per_triangle;
  limits.keep_instances = memory.keep_instances;
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
    Scene scene = load_scene_file(view.obj, warn, cancel, limits, phases);
    apply_view_light(scene, view);
    scene.camera = view.camera;
    add_lights(scene, a);
    add_environment(scene, a, cancel, warn);
    return scene;
  }
  Scene scene =
      a.scene.empty() ? make_cornell_box(a.builtin_spheres) : load_scene_file(a.scene, warn, cancel, limits, phases);
  if (a.camera) {
    if (scene.cameras.empty()) throw UsageError("--camera: the scene places no cameras");
    if (*a.camera < 0 || size_t(*a.camera) >= scene.cameras.size()) {
      throw UsageError("--camera: " + std::to_string(*a.camera) + " is not one of the scene's " +
                       std::to_string(scene.cameras.size()) + " cameras (0 to " +
                       std::to_string(scene.cameras.size() - 1) + ")");
    }
    scene.camera = scene.cameras[size_t(*a.camera)];
  }
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
  const float fov = a.fov.value_or(kDefaultFovDegrees);
  const Vec3 extent = scene.bounds.extent();
  if (!a.eye && !a.look && !scene.camera && std::max({extent.x, extent.y, extent.z}) == 0.0f) {
    throw InputError(scene.source +
                     ": all vertices coincide, so there is nothing to frame (every triangle is degenerate)");
  }
  CameraSpec spec = scene.camera && !a.eye && !a.look && !a.fov ? *scene.camera : frame_bounds(scene.bounds, fov);
  if (a.eye) {
    spec.eye = *a.eye;
    if (!a.look) spec.look = scene.bounds.center();
  }
  if (a.look) spec.look = *a.look;
  if (a.up) {
    // Scaled first, so a huge but valid --up cannot overflow the cross products below.
    const Vec3 up = *a.up;
    spec.up = up * (1.0f / std::max({std::fabs(up.x), std::fabs(up.y), std::fabs(up.z)}));
  }
  // A narrow --fov backs the framed camera off; past kMaxCameraDistance its rays could not reach
  // the scene without overflow (and Embree refuses such rays).
  if (std::max({std::fabs(spec.eye.x), std::fabs(spec.eye.y), std::fabs(spec.eye.z)}) > kMaxCameraDistance) {
    throw UsageError("--fov: " + std::to_string(spec.fov_degrees) +
                     " degrees frames this scene from too far away (beyond 4e12); widen it or give --eye");
  }
  const Vec3 forward = spec.look - spec.eye;
  if (length(forward) == 0.0f && !a.eye && !a.look) {
    // Framed by tracer, not placed by the user: the scene's extent is below what floats resolve.
    char size[32];
    std::snprintf(size, sizeof size, "%g", double(std::max({extent.x, extent.y, extent.z})));
    throw InputError(scene.source + ": the scene is too small to frame (its extent, " + size +
                     ", is below what a float camera resolves); give --eye and --look");
  }
  if (length(forward) == 0.0f) throw UsageError("--eye/--look: the camera looks at its own position");
  if (a.aperture) spec.lens_radius = float(*a.aperture);
  if (a.focus_distance) {
    // Nearer than this, a lens focuses on nothing of the scene: every ray leaves sideways.
    const double diagonal = length(scene.bounds.extent());
    if (*a.focus_distance < 1e-6 * diagonal) {
      throw UsageError("--focus-distance " + format_number(*a.focus_distance) +
                       ": below a millionth of the scene's size (its diagonal, " + format_number(diagonal) +
                       "): a lens focused there shows nothing of the scene");
    }
    spec.focus_distance = float(*a.focus_distance);
  }
  if (length(cross(forward, spec.up)) == 0.0f) throw UsageError("--up: parallel to the viewing direction");
  return spec;
}

SceneInfo scene_info(const SceneArgs& a, bool quiet) {
  // A glTF as the file says (nothing added by flags) is counted without placing its instances.
  const bool as_file = a.view.empty() && a.lights.empty() && !a.no_scene_lights && !a.light_intensity &&
                       a.env_map.empty() && !a.camera && !a.scene.empty() && a.scene != "-";
  // The estimate is of the default accelerator's (bvh8, medium quality) over the scene.
  const uint64_t accel_per_triangle = build_bytes_per_triangle(AccelKind::Bvh8, BuildQuality::Medium);
  if (!as_file || scene_format(a.scene) != SceneFormat::Gltf) {
    const Scene scene = load_scene(a, quiet);
    SceneInfo info = info_of(scene);
    info.estimated_bytes = scene.memory_bytes() + uint64_t(scene.size()) * accel_per_triangle +
                           uint64_t(scene.instances.size()) * kBytesPerInstance;
    return info;
  }
  check_range("--max-input-mib", a.max_input_mib, 1, 1 << 20);
  LoadLimits limits;
  limits.max_obj_bytes = uint64_t(a.max_input_mib) << 20;
  limits.accel_bytes_per_triangle = accel_per_triangle;
  const WarningSink silent = [](const std::string&) {};
  return gltf_info(a.scene, quiet ? silent : WarningSink{}, nullptr, limits);
}

}  // namespace tracer::frontend
