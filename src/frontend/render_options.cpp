#include "frontend/render_options.hpp"

#include "base/errors.hpp"
#include "frontend/parse.hpp"
#include "io/image_io.hpp"

namespace tracer::frontend {

RenderSettings settings_for(const RenderArgs& a) {
  RenderSettings s = a.settings;
  if (a.ao_distance) s.ao_distance = float(*a.ao_distance);
  s.integrator = a.integrator;
  const bool path = s.integrator == Integrator::Path;
  s.noise_threshold = path ? float(a.noise_threshold.value_or(a.denoise ? 0.0 : kDefaultNoiseThreshold)) : 0.0f;
  s.min_spp = a.min_spp.value_or(s.min_spp);
  // Every integrator anti-aliases with --spp; ao and whitted take one centred sample by default.
  s.spp = a.spp.value_or(path ? kDefaultPathSpp : 1);
  if (a.env)
    s.environment = *a.env;
  else if (!a.scene.env_map.empty())
    s.environment = Vec3{1.0f};
  // Rays together by default where the accelerator can, but not under --simd off (all scalar),
  // and not for whitted or path, whose rays go one at a time.
  const bool together = a.packets.value_or(s.packets && a.simd != SimdUse::Off);
  s.packets = together && traces_rays_together(accel_options_for(a).kind) && s.integrator == Integrator::Ao;
  s.streams = s.packets && a.streams.value_or(s.streams) && traces_streams(accel_options_for(a).kind);
  s.count_traversal = a.count;
  return s;
}

RenderSettings settings_for(const RenderArgs& a, const Scene& scene, std::string& note) {
  RenderSettings s = settings_for(a);
  note.clear();
  // The two-level tree (bvh8 on an instanced scene) traces AO rays in bundles: it has no stream kernel.
  if (scene.instanced() && accel_options_for(a).kind == AccelKind::Bvh8) s.streams = false;
  if (s.integrator == Integrator::Path && !a.env && scene.environment_map.empty() && scene.emitters.empty()) {
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
    } else if (name == "samples") {
      aovs.samples = true;
    } else if (name == "noisy" || name == "variance") {
      if (!a.denoise) throw UsageError("--aov " + name + ": only with --denoise");
      (name == "noisy" ? aovs.noisy : aovs.variance) = true;
    } else {
      throw UsageError("--aov: unknown layer '" + name + "' (expected albedo, normal, samples, noisy, variance)");
    }
  }
  if (image_format_for(a.output) != ImageFormat::Exr) throw UsageError("--aov: the layers need an .exr output (-o)");
  return aovs;
}

AccelOptions accel_options_for(const RenderArgs& a) {
  AccelOptions o;
  o.bvh = a.bvh;
  const bool scalar = a.simd == SimdUse::Off;
  // --simd off alone asks for the scalar baseline: the binary BVH, not the SIMD default.
  o.kind = a.accel.value_or(scalar ? AccelKind::Bvh : o.kind);
  if (o.kind == AccelKind::Bvh8 && scalar) {
    throw UsageError("--simd off: bvh8 is the SIMD tree; use --accel bvh for scalar traversal");
  }
  if (o.kind == AccelKind::BruteSimd && scalar) {
    throw UsageError("--simd off: simd-brute is the SIMD brute force; use --accel brute for the scalar one");
  }
  o.bvh.threads = a.threads.value_or(0);
  o.bvh.simd = a.simd_target;
  if (a.build_quality) {
    o.quality = *a.build_quality;
    if (!has_build_quality(o.kind)) throw UsageError("--build-quality: only bvh8 and embree build at a quality level");
    if (o.kind == AccelKind::EmbreeHigh && o.quality != BuildQuality::High) {
      throw UsageError("--build-quality " + std::string(name_of<BuildQuality>(kBuildQualityNames, o.quality)) +
                       ": --accel embree-high is Embree at high");
    }
  }
  return o;
}

BuildQuality default_build_quality(const RenderSettings& s, int frames, size_t triangles) {
  const double samples = double(s.width) * double(s.height) * double(s.spp) * double(frames);
  return s.integrator == Integrator::Path && samples >= kHighQualitySamplesPerTriangle * double(triangles)
             ? BuildQuality::High
             : BuildQuality::Medium;
}

SchedOptions sched_options_for(const RenderArgs& a) {
  SchedOptions o = a.sched;
  o.threads = a.threads.value_or(0);
  return o;
}

}  // namespace tracer::frontend
