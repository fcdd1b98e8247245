// What a render's flags become: the RenderSettings, and the accelerator's, scheduler's and
// output's options.
#pragma once

#include "frontend/render_args.hpp"
#include "scene/scene.hpp"

namespace tracer::frontend {

RenderSettings settings_for(const RenderArgs& args);
// The path integrator's samples per pixel when --spp is not given.
inline constexpr int kDefaultPathSpp = 64;
// Adaptive sampling's noise threshold when --noise-threshold is not given (docs/BENCHMARKS.md,
// adaptive sampling: how it was chosen); the library's default is off, and so is --denoise's
// (BENCHMARKS.md section 21: with the denoiser it saved no time and lowered a caustic's mean). --min-spp's default is
// RenderSettings'.
inline constexpr double kDefaultNoiseThreshold = 0.01;
// settings_for() plus what depends on the scene: a path render of a scene with no emissive
// surface and no --env is lit by a uniform white sky as well as any point lights (a point light
// alone leaves everything it does not see black), and `note` says so.
RenderSettings settings_for(const RenderArgs& args, const Scene& scene, std::string& note);
// Said whenever a finished image is black in every pixel: why, and the flags that light it.
std::string black_image_warning(const RenderSettings& settings, const Scene& scene);
// The accelerator the flags ask for; its quality is --build-quality's, else medium (see below).
AccelOptions accel_options_for(const RenderArgs& args);

// The 8-wide BVH's quality when --build-quality is not given: high for a path-traced render of at
// least kHighQualitySamplesPerTriangle pixel samples per triangle, medium otherwise. High's spatial
// splits cost about 0.4 us more build per triangle and save about 0.2 us per path sample (Sponza,
// Sibenik; docs/BENCHMARKS.md section 19), so a short render (a --spp 1 preview of a large scene,
// an AO or whitted image) keeps the faster build. tracer view asks for medium.
inline constexpr double kHighQualitySamplesPerTriangle = 16.0;
BuildQuality default_build_quality(const RenderSettings& settings, int frames, size_t triangles);
SchedOptions sched_options_for(const RenderArgs& args);
// --aov: a comma-separated list of albedo, normal and samples, only for path renders to .exr; throws UsageError.
Aovs aovs_for(const RenderArgs& args);

}  // namespace tracer::frontend
