// What a render is asked to do (RenderSettings), what it counts (RayCounts) and what every tile
// shares (RenderContext).
#pragma once

#include <atomic>
#include <cstdint>

#include "base/enum_names.hpp"
#include "math/ray.hpp"
#include "render/framebuffer.hpp"
#include "scene/camera.hpp"
#include "scene/scene.hpp"

namespace tracer {

// What a pixel's radiance is made of: the study's workload (direct light from the lights'
// centroids, ambient occlusion, every surface diffuse), or Whitted ray tracing (direct light
// with hard shadows, perfect mirror reflection and dielectric refraction to max_depth).
enum class Integrator { Ao, Whitted };
inline constexpr EnumName<Integrator> kIntegratorNames[] = {{Integrator::Ao, "ao"}, {Integrator::Whitted, "whitted"}};

struct RenderSettings {
  int width = 1024;
  int height = 1024;
  int ao_samples = 16;            // 0 turns ambient occlusion off (the ambient term is then unoccluded)
  float ao_distance = kInfinity;  // tfar of the AO rays
  float ambient = 0.25f;          // ambient light, times Kd and the unoccluded AO fraction
  float exposure = 1.5f;          // tone-mapping exposure
  uint32_t seed = 0;
  Integrator integrator = Integrator::Ao;
  int max_depth = 8;  // whitted: reflections and refractions followed per path
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

// Everything one tile needs; shared read-only by all workers except the disjoint framebuffer pixels.
struct RenderContext {
  const Scene* scene = nullptr;
  Camera camera;
  RenderSettings settings;
  Framebuffer* framebuffer = nullptr;
};

}  // namespace tracer
