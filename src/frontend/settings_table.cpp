#include "frontend/settings_table.hpp"

#include <sstream>
#include <stdexcept>

#include "frontend/render_options.hpp"
#include "frontend/setting_rows.hpp"
#include "scene/camera.hpp"

namespace tracer::frontend {

namespace {

using namespace setting_rows;

std::string number_text(double v) { return (std::ostringstream() << v).str(); }

std::vector<Setting> make_table() {
  using G = SettingGroup;
  std::vector<Setting> t;
  // The scene: what is loaded (tracer info reads these too).
  t.push_back(row<std::string>(
      {.names = "scene,-m,--scene",
       .help = "scene to render: .obj, .gltf, .glb or .ply (default: the built-in Cornell box)",
       .role = Role::Scene,
       .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.scene; }, name_codec(true)));
  t.push_back(row<std::string>(
      {.names = "--view",
       .help = "render a named view: its scene, camera and light (e.g. sponza, cornell-water)",
       .role = Role::Scene,
       .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.view; }, name_codec(false)));
  t.push_back(row<std::string>(
      {.names = "--views",
       .help = "the views file for --view (default ../shared/scenes/views.tsv)",
       .role = Role::Scene,
       .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.views; }, name_codec(true)));
  t.push_back(row<int>(
      {.names = "--builtin-spheres",
       .help = "built-in scene: add two spheres of about this many triangles each",
       .role = Role::Scene,
       .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.builtin_spheres; }, whole<int>(0, 10'000'000)));
  t.push_back(points(
      {.names = "--light", .help = "add a point light at x,y,z (repeatable)", .role = Role::Scene, .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.lights; }));
  t.push_back(toggle(
      {.names = "--no-scene-lights",
       .help = "drop the scene's emissive lights, keep only --light ones",
       .role = Role::Scene,
       .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.no_scene_lights; }));
  t.push_back(row<std::optional<double>>(
      {.names = "--light-intensity",
       .help = "point light intensity (default: (scene diagonal / 2)^2)",
       .role = Role::Scene,
       .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.light_intensity; }, real<double>(0.0, kMaxLightIntensity)));
  t.push_back(row<std::string>(
      {.names = "--env-map",
       .help = "light the scene from beyond with this equirectangular environment map (.exr "
               "or .hdr, linear radiance; times --env)",
       .applies = kLit,
       .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.env_map; }, name_codec(true)));
  t.push_back(row<double>(
      {.names = "--env-rotation", .help = "degrees the --env-map turns about +y", .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.env_rotation; }, real<double>(-1e6, 1e6)));
  t.push_back(row<std::optional<int>>(
      {.names = "--camera",
       .help = "a glTF scene's camera N, counting from 0 in node order (default 0)",
       .role = Role::Scene,
       .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.camera; }, whole<int>(0, 1 << 30)));
  t.push_back(row<long long>(
      {.names = "--max-input-mib", .help = "largest scene file read, in MiB", .role = Role::Scene, .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.max_input_mib; }, whole<long long>(1, 1 << 20)));
  t.push_back(row<long long>(
      {.names = "--max-texture-mib",
       .help = "memory all the scene's textures may take, in MiB; past it a texture is not used",
       .role = Role::Scene,
       .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.max_texture_mib; }, whole<long long>(1, 1 << 20)));
  t.push_back(row<std::optional<long long>>(
      {.names = "--max-memory-mib",
       .help = "memory the scene, its accelerator and the image may take, in MiB (default: the memory available "
               "less a tenth); a render estimated above it is refused",
       .role = Role::Local,
       .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.max_memory_mib; }, whole<long long>(1, 1 << 30)));

  // The image.
  t.push_back(row<int>(
      {.names = "--width", .key = "width", .help = "image width in pixels"},
      [](RenderArgs & a) -> auto& { return a.settings.width; }, whole<int>(1, 16384)));
  t.push_back(row<int>(
      {.names = "--height", .key = "height", .help = "image height in pixels"},
      [](RenderArgs & a) -> auto& { return a.settings.height; }, whole<int>(1, 16384)));
  t.push_back(row<std::optional<Vec3>>(
      {.names = "--eye,-v", .key = "eye", .help = "camera position x,y,z (default: frame the scene from the front)"},
      [](RenderArgs & a) -> auto& { return a.eye; }, vector(VecKind::Point)));
  t.push_back(row<std::optional<Vec3>>(
      {.names = "--look,-l", .key = "look", .help = "point the camera looks at, x,y,z"},
      [](RenderArgs & a) -> auto& { return a.look; }, vector(VecKind::Point)));
  t.push_back(row<std::optional<Vec3>>(
      {.names = "--up", .key = "up", .help = "camera up vector x,y,z (default 0,1,0)"},
      [](RenderArgs & a) -> auto& { return a.up; }, vector(VecKind::Direction)));
  t.push_back(row<std::optional<float>>(
      {.names = "--fov", .key = "fov", .help = "vertical field of view in degrees (default 53.13)"},
      [](RenderArgs & a) -> auto& { return a.fov; }, real<float>(kMinFovDegrees, kMaxFovDegrees)));
  t.push_back(row<std::optional<double>>(
      {.names = "--aperture",
       .key = "aperture",
       .help = "depth of field: the radius of a thin lens, in scene units (default 0: a pinhole, all sharp)"},
      [](RenderArgs & a) -> auto& { return a.aperture; }, real<double>(0.0, 1e6)));
  t.push_back(row<std::optional<double>>(
      {.names = "--focus-distance",
       .key = "focus_distance",
       .help = "with --aperture: the distance of the plane in focus along the view (default: the look-at point's)"},
      [](RenderArgs & a) -> auto& { return a.focus_distance; }, real<double>(0.0, 1e12, LowEnd::Open)));
  t.push_back(row<Integrator>(
      {.names = "--integrator",
       .key = "integrator",
       .help = "what a pixel is made of: ao (the study's workload: direct light, ambient occlusion, every surface "
               "diffuse), whitted (mirrors and glass from the MTL, hard shadows) or path (path tracing: every "
               "material, emissive triangles as area lights, soft shadows, indirect light)"},
      [](RenderArgs & a) -> auto& { return a.integrator; }, choice<Integrator>(kIntegratorNames, "integrator")));
  t.push_back(row<int>(
      {.names = "--max-depth",
       .key = "max_depth",
       .help = "reflections and refractions followed (whitted), bounces per path (path)",
       .applies = kLit},
      [](RenderArgs & a) -> auto& { return a.settings.max_depth; }, whole<int>(0, 64)));
  t.push_back(row<std::optional<int>>(
      {.names = "--spp",
       .key = "spp",
       .help = "samples per pixel (default " + std::to_string(kDefaultPathSpp) +
               " for path, 1 through the pixel centre for ao and whitted)"},
      [](RenderArgs & a) -> auto& { return a.spp; }, whole<int>(1, 1 << 20)));
  t.push_back(row<std::optional<double>>(
      {.names = "--noise-threshold",
       .help = "adaptive sampling: a 4x4 block of pixels stops taking samples once each pixel's noise estimate is "
               "below this (default " +
               number_text(kDefaultNoiseThreshold) + ", 0 with --denoise; 0 gives every pixel --spp samples)",
       .applies = kPath},
      [](RenderArgs & a) -> auto& { return a.noise_threshold; }, real<double>(0.0, 1.0)));
  t.push_back(row<std::optional<int>>(
      {.names = "--min-spp",
       .help = "adaptive sampling: samples every pixel takes before it may stop (default " +
               std::to_string(RenderSettings{}.min_spp) + ")",
       .applies = kPath},
      [](RenderArgs & a) -> auto& { return a.min_spp; }, whole<int>(2, 1 << 20)));
  t.push_back(row<std::optional<Vec3>>(
      {.names = "--env",
       .help = "radiance r,g,b of a uniform environment, or the --env-map's scale (default black, 1,1,1 with "
               "--env-map; white when the scene has no light)",
       .applies = kLit},
      [](RenderArgs & a) -> auto& { return a.env; }, vector(VecKind::Radiance)));
  t.push_back(row<std::string>(
      {.names = "--aov",
       .help = "also write these layers into the .exr output: albedo and normal of the first hit, samples (each "
               "pixel's sample count), and with --denoise noisy (the image before denoising) and variance (of each "
               "pixel's mean); comma-separated",
       .applies = kPath,
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.aov; }, name_codec(false)));
  t.push_back(toggle(
      {.names = "--denoise",
       .help = "denoise the image (NFOR, a feature-guided regression on the albedo, normal and "
               "distance of the first surface that is not a mirror or glass); --aov noisy,variance "
               "keep what it started from",
       .applies = kPath},
      [](RenderArgs & a) -> auto& { return a.denoise; }));
  t.push_back(row<LightSampling>(
      {.names = "--light-sampling",
       .help = names_of<LightSampling>(kLightSamplingNames) +
               " (mis: emitter samples and BSDF samples combined; bsdf: BSDF samples only)",
       .applies = kPath},
      [](RenderArgs & a) -> auto& { return a.settings.light_sampling; },
      choice<LightSampling>(kLightSamplingNames, "light sampling")));
  t.push_back(row<int>(
      {.names = "--frames",
       .help = "render an image sequence of this many frames: -o NAME.png gives NAME-0000.png ..."},
      [](RenderArgs & a) -> auto& { return a.frames; }, whole<int>(1, 1'000'000)));
  t.push_back(row<double>(
      {.names = "--orbit",
       .help = "degrees the camera turns about the look point (around --up) over the --frames sequence"},
      [](RenderArgs & a) -> auto& { return a.orbit; }, real<double>(-1e6, 1e6)));
  t.push_back(row<std::optional<double>>(
      {.names = "--checkpoint",
       .help = "rewrite the output every this many seconds while samples accumulate",
       .applies = kPath,
       .role = Role::Work},
      [](RenderArgs & a) -> auto& { return a.checkpoint; }, real<double>(0.0, 1e9, LowEnd::Open)));
  t.push_back(row<int>(
      {.names = "--ao", .help = "ambient-occlusion rays per hit, 0 = off", .applies = kAo},
      [](RenderArgs & a) -> auto& { return a.settings.ao_samples; }, whole<int>(0, 4096)));
  t.push_back(row<std::optional<double>>(
      {.names = "--ao-distance", .help = "maximum distance of AO rays (default: unbounded)", .applies = kAo},
      [](RenderArgs & a) -> auto& { return a.ao_distance; }, real<double>(0.0, 1e30, LowEnd::Open)));
  t.push_back(row<float>(
      {.names = "--ambient", .help = "ambient light strength", .applies = kAo},
      [](RenderArgs & a) -> auto& { return a.settings.ambient; }, real<float>(0.0, 1e6)));
  t.push_back(row<float>(
      {.names = "--exposure", .key = "exposure", .help = "tone-mapping exposure of .png and .ppm outputs"},
      [](RenderArgs & a) -> auto& { return a.settings.exposure; }, real<float>(0.0, 1e6, LowEnd::Open)));
  t.push_back(row<uint32_t>(
      {.names = "--seed", .help = "seed of the sample patterns"},
      [](RenderArgs & a) -> auto& { return a.settings.seed; }, whole<uint32_t>(0, 4294967295LL)));

  // The work: how it is cut, which ranks must agree on.
  t.push_back(row<Strategy>(
      {.names = "--sched",
       .help = "how tiles are handed to threads: " + names_of<Strategy>(kStrategyNames),
       .role = Role::Work},
      [](RenderArgs & a) -> auto& { return a.sched.strategy; }, choice<Strategy>(kStrategyNames, "strategy")));
  t.push_back(row<int>(
      {.names = "--tile", .help = "tile edge in pixels for the atomic and tbb strategies", .role = Role::Work},
      [](RenderArgs & a) -> auto& { return a.sched.tile; }, whole<int>(1, 4096)));
  t.push_back(row<int>(
      {.names = "--block", .help = "pixels per row block for the queue strategy", .role = Role::Work},
      [](RenderArgs & a) -> auto& { return a.sched.block; }, whole<int>(1, 1 << 20)));

  // This process's means: the same image from each.
  t.push_back(row<ExrPixel>(
      {.names = "--exr",
       .help = "pixel type of .exr outputs (linear radiance, no tone mapping): half or float",
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.exr; }, choice<ExrPixel>(kExrPixelNames, "pixel type")));
  t.push_back(row<std::optional<AccelKind>>(
      {.names = "--accel",
       .help = "accelerator: " + names_of<AccelKind>(kAccelKindNames) + " (default " +
               std::string(name_of<AccelKind>(kAccelKindNames, AccelOptions{}.kind)) + ", the fastest)",
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.accel; }, choice<AccelKind>(kAccelKindNames, "accelerator")));
  t.push_back(row<std::optional<BuildQuality>>(
      {.names = "--build-quality",
       .help = "bvh8 and embree: " + names_of<BuildQuality>(kBuildQualityNames) +
               " (high: spatial splits, a slower build for faster closest hits; default high for a path render of "
               "at least 16 pixel samples per triangle, else medium, and medium in tracer view)",
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.build_quality; }, choice<BuildQuality>(kBuildQualityNames, "quality")));
  t.push_back(row<BvhSplit>(
      {.names = "--bvh-split",
       .help = "BVH split: " + names_of<BvhSplit>(kBvhSplitNames) + " (the study's)",
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.bvh.split; }, choice<BvhSplit>(kBvhSplitNames, "split")));
  t.push_back(row<Strategy>(
      {.names = "--build-sched,--build",
       .help = "how the BVH build forks: seq, async, queue or tbb (the strategies of --sched but atomic, which hands "
               "out tiles)",
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.bvh.strategy; }, choice<Strategy>(kStrategyNames, "strategy")));
  t.push_back(row<int>(
      {.names = "--max-leaf", .help = "SAH BVH: largest leaf", .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.bvh.max_leaf; }, whole<int>(1, 16)));
  t.push_back(row<int>(
      {.names = "--bins", .help = "SAH BVH: bins per axis", .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.bvh.bins; }, whole<int>(4, 32)));
  t.push_back(row<float>(
      {.names = "--traversal-cost",
       .help = "SAH BVH: cost of a node step relative to a triangle test",
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.bvh.traversal_cost; }, real<float>(0.0, 100.0, LowEnd::Open)));
  t.push_back(row<SimdUse>(
      {.names = "--simd",
       .help = "SIMD kernels: auto, or off (scalar traversal: --accel bvh by default)",
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.simd; }, choice<SimdUse>(kSimdUseNames, "SIMD use")));
  t.push_back(row<SimdTarget>(
      {.names = "--simd-target",
       .help =
           "bvh8 and the denoiser: " + names_of<SimdTarget>(kSimdTargetNames) + " (a narrower target than the CPU's)",
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.simd_target; }, choice<SimdTarget>(kSimdTargetNames, "target")));
  t.push_back(tristate(
      {.names = "--packets",
       .help = "trace rays together: each hit's AO rays as one bundle (bvh, bvh8, embree), primary rays and shadow "
               "rays per 4x4-pixel packet (bvh8, embree); same image (default: on where the accelerator can)",
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.packets; }, true));
  t.push_back(tristate(
      {.names = "--no-packets",
       .help = "trace every ray alone (same image, slower)",
       .role = Role::Local,
       .excludes = "--packets"},
      [](RenderArgs & a) -> auto& { return a.packets; }, false));
  t.push_back(tristate(
      {.names = "--streams",
       .help = "with packets, trace each tile's AO rays as sorted streams (bvh8, embree: rtcOccluded1M); same image "
               "(default: on where the accelerator can)",
       .applies = kAo,
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.streams; }, true));
  t.push_back(tristate(
      {.names = "--no-streams",
       .help = "with packets, trace each hit's AO rays as one bundle instead (same image)",
       .applies = kAo,
       .role = Role::Local,
       .excludes = "--streams"},
      [](RenderArgs & a) -> auto& { return a.streams; }, false));
  t.push_back(row<std::optional<int>>(
      {.names = "--threads", .help = "worker threads (default: all hardware threads)", .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.threads; }, whole<int>(1, 1024)));
  for (Setting& s : t) {
    if (!s.applies.is_all()) s.help = s.applies.names(", ") + ": " + s.help;
  }
  return t;
}

}  // namespace

const std::span<const Setting> settings_table() {
  static const std::vector<Setting> table = make_table();
  return table;
}

const Setting& setting(std::string_view flag) {
  for (const Setting& s : settings_table()) {
    if (s.flag() == flag) return s;
  }
  throw std::logic_error("no setting " + std::string(flag));
}

}  // namespace tracer::frontend
