// What a render is asked to do (RenderSettings), what it counts (RayCounts) and what every tile
// shares (RenderContext).
#pragma once

#include <atomic>
#include <cstdint>

#include "base/enum_names.hpp"
#include "film/framebuffer.hpp"
#include "math/ray.hpp"
#include "scene/camera.hpp"
#include "scene/scene.hpp"

namespace tracer {

// What a pixel's radiance is made of: the study's workload (direct light from the lights'
// centroids, ambient occlusion, every surface diffuse), Whitted ray tracing (direct light with
// hard shadows, perfect mirror reflection and dielectric refraction to max_depth), or unbiased
// path tracing (every material of the MTL, emissive triangles as area lights).
enum class Integrator { Ao, Whitted, Path };
inline constexpr EnumName<Integrator> kIntegratorNames[] = {
    {Integrator::Ao, "ao"}, {Integrator::Whitted, "whitted"}, {Integrator::Path, "path"}};

// How the path integrator finds light: next-event estimation combined with BSDF sampling by
// multiple importance sampling, or BSDF sampling alone (the unbiased reference NEE must match).
enum class LightSampling { Mis, Bsdf };
inline constexpr EnumName<LightSampling> kLightSamplingNames[] = {{LightSampling::Mis, "mis"},
                                                                  {LightSampling::Bsdf, "bsdf"}};

struct RenderSettings {
  int width = 1024;
  int height = 1024;
  int ao_samples = 16;            // 0 turns ambient occlusion off (the ambient term is then unoccluded)
  float ao_distance = kInfinity;  // tfar of the AO rays
  float ambient = 0.25f;          // ambient light, times Kd and the unoccluded AO fraction
  float exposure = 1.5f;          // tone-mapping exposure
  uint32_t seed = 0;
  Integrator integrator = Integrator::Ao;
  int max_depth = 8;       // whitted: reflections and refractions followed; path: bounces per path
  int spp = 1;             // samples per pixel (every integrator)
  Vec3 environment{0.0f};  // path: radiance arriving from every direction no surface blocks
  LightSampling light_sampling = LightSampling::Mis;
  // Trace rays together where the accelerator can (primary rays in 4x4-pixel packets, a block's
  // shadow rays, each hit's AO rays as one bundle): the same image, faster.
  bool packets = true;
};

struct RayCounts {
  uint64_t primary = 0, shadow = 0, ao = 0, secondary = 0;  // secondary: reflected and refracted rays
  uint64_t total() const { return primary + shadow + ao + secondary; }
  RayCounts& operator+=(const RayCounts& o) {
    primary += o.primary;
    shadow += o.shadow;
    ao += o.ao;
    secondary += o.secondary;
    return *this;
  }
};

// Thread-safe accumulation of per-tile counts (one atomic add per tile, never per ray).
struct AtomicRayCounts {
  std::atomic<uint64_t> primary{0}, shadow{0}, ao{0}, secondary{0};
  void add(const RayCounts& c) {
    primary.fetch_add(c.primary, std::memory_order_relaxed);
    shadow.fetch_add(c.shadow, std::memory_order_relaxed);
    ao.fetch_add(c.ao, std::memory_order_relaxed);
    secondary.fetch_add(c.secondary, std::memory_order_relaxed);
  }
  RayCounts load() const { return {primary.load(), shadow.load(), ao.load(), secondary.load()}; }
};

// The samples of each pixel one pass adds: [first, first + count).
struct SampleRange {
  uint32_t first = 0, count = 1;
};

// Everything one tile needs; shared read-only by all workers except the disjoint framebuffer pixels.
struct RenderContext {
  const Scene* scene = nullptr;
  Camera camera;
  RenderSettings settings;
  Framebuffer* framebuffer = nullptr;
  SampleRange samples;  // path: this pass's samples (ao and whitted take one, at the pixel centre)
  // path, --aov: where each sample's first hit adds its albedo and shading normal (for a
  // denoiser), summed and counted as the radiance is; null when not asked for.
  Framebuffer* albedo = nullptr;
  Framebuffer* normal = nullptr;
};

}  // namespace tracer
