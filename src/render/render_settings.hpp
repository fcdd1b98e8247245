// What a render is asked to do: the integrator, its light sampling, and the numbers that shape
// the image (RenderSettings).
#pragma once

#include <cstdint>

#include "base/enum_names.hpp"
#include "math/ray.hpp"

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
  // path: adaptive sampling (film/convergence.hpp): a 4x4 block of pixels stops taking samples
  // once each has min_spp and a noise estimate below this; 0 gives every pixel spp samples.
  float noise_threshold = 0.0f;
  int min_spp = 16;
  // Trace rays together where the accelerator can (primary rays in 4x4-pixel packets, a block's
  // shadow rays, each hit's AO rays as one bundle): the same image, faster.
  bool packets = true;
  // With packets: each tile's AO rays gathered into streams, sorted by direction and origin and
  // traced together where the accelerator takes streams (render/stream_order.hpp): the same image.
  bool streams = true;
  // Count the nodes, leaf packs and triangles each query visits (--count; accelerators that can:
  // the 8-wide BVH): the same image, rendered through counting kernels.
  bool count_traversal = false;
};

}  // namespace tracer
