// Direct light, written once for every integrator: the shadow ray of a light sample, what the
// sample adds through a surface's reflectance, and the study's sum over every lamp (ao, whitted).
#pragma once

#include <bit>
#include <cstdint>

#include "render/accel_concepts.hpp"
#include "render/lights.hpp"

namespace tracer {

// The ray from `si` toward light sample `ls`, ending short of the light.
inline Ray shadow_ray(const SurfaceInteraction& si, const LightSample& ls) {
  Ray shadow;
  shadow.org = si.origin;
  shadow.dir = ls.wi;
  shadow.tfar = ls.distance;
  return shadow;
}

// What `ls` adds when nothing blocks it, through reflectance `f` (times the path's throughput),
// weighted by `weight` (a cosine, or a multiple-importance weight whose f holds the cosine).
inline Vec3 light_contribution(const LightSample& ls, Vec3 f, float weight) {
  return f * ls.L * (ls.falloff * weight / ls.pdf);
}

// light_contribution() where the shadow ray from `si` reaches the light, else black.
template <class Accel>
Vec3 direct_light(const Accel& accel, const SurfaceInteraction& si, const LightSample& ls, Vec3 f, float weight,
                  RayCounts& counts) {
  ++counts.shadow;
  if (occluded_leaving(accel, shadow_ray(si, ls), si.tri)) return Vec3{0.0f};
  return light_contribution(ls, f, weight);
}

// The study's direct light (ao, whitted): one shadow ray per lamp, toward its position or its
// area's centroid, through the diffuse reflectance albedo/pi at the shading normal's cosine.
// Returns false where `light` cannot light `si`.
inline bool lamp_sample_at(const Light& light, const SurfaceInteraction& si, LightSample& ls, float& cos_surface) {
  if (!sample_lamp(light, si, ls)) return false;
  cos_surface = dot(si.shading_n, ls.wi);
  return cos_surface > 0.0f;
}

// `radiance` plus what every lamp gives `si`, added in the lamps' order.
template <class Accel>
Vec3 add_lamp_light(const Accel& accel, const PassContext& ctx, const SurfaceInteraction& si, Vec3 radiance,
                    RayCounts& counts) {
  for (const Light& light : ctx.scene->lights) {
    LightSample ls;
    float cos_surface;
    if (!lamp_sample_at(light, si, ls, cos_surface)) continue;
    radiance += direct_light(accel, si, ls, si.albedo_over_pi, cos_surface, counts);
  }
  return radiance;
}

// add_lamp_light() for the lanes `lanes` of up to kPacketSize hits at once: per lamp, their
// shadow rays as one packet (one call where the accelerator takes occlusion packets). Each ray
// gets the answer it gets alone and each lane adds the lamps in the same order, so every
// radiance[k] is the single-hit one.
template <class Accel>
void add_lamp_light(const Accel& accel, const PassContext& ctx, const SurfaceInteraction* sis, uint32_t lanes,
                    Vec3* radiance, RayCounts& counts) {
  for (const Light& light : ctx.scene->lights) {
    RayPacket shadows;
    Vec3 contribution[kPacketSize];
    for (uint32_t bits = lanes; bits; bits &= bits - 1) {
      const int k = __builtin_ctz(bits);
      LightSample ls;
      float cos_surface;
      if (!lamp_sample_at(light, sis[k], ls, cos_surface)) continue;
      shadows.set(k, shadow_ray(sis[k], ls));
      contribution[k] = light_contribution(ls, sis[k].albedo_over_pi, cos_surface);
    }
    if (shadows.active == 0) continue;
    counts.shadow += uint64_t(std::popcount(shadows.active));
    uint32_t blocked = 0;
    if constexpr (OcclusionPacketAccelerator<Accel>) {
      blocked = accel.occluded_packet(shadows);
    } else {
      for (uint32_t bits = shadows.active; bits; bits &= bits - 1) {
        const int k = __builtin_ctz(bits);
        if (occluded_leaving(accel, shadows.ray(k), sis[k].tri)) blocked |= 1u << k;
      }
    }
    for (uint32_t bits = shadows.active & ~blocked; bits; bits &= bits - 1) {
      const int k = __builtin_ctz(bits);
      radiance[k] += contribution[k];
    }
  }
}

}  // namespace tracer
