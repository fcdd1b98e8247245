// The study's workload, defined once so every accelerator and scheduler traces the same rays:
// per pixel one primary ray through the pixel centre; at a hit one shadow ray per light (its
// centroid) and N ambient-occlusion rays; every surface diffuse. Its images are the golden ones.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "math/rng.hpp"
#include "parallel/tiles.hpp"
#include "render/accel_concepts.hpp"
#include "render/surface_point.hpp"

namespace tracer {

// Uniform direction on the sphere, mirrored into n's hemisphere when below it (the study's
// trick: no rejection loop, same distribution as uniform hemisphere sampling).
inline Vec3 ao_direction(Vec3 n, float r1, float r2) {
  const float z = 1.0f - 2.0f * r1;
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * std::numbers::pi_v<float> * r2;
  Vec3 d{r * std::cos(phi), r * std::sin(phi), z};
  return dot(d, n) < 0.0f ? -d : d;
}

// The shadow ray from `sp` toward `light` and what the light adds if nothing blocks it; false
// when the light cannot contribute (it is the surface's own emitter, or behind the surface).
inline bool light_sample(const SurfacePoint& sp, const Light& light, Ray& shadow, Vec3& contribution) {
  if (light.geomID == sp.geomID) return false;  // an emitter does not light itself
  const Vec3 to_light = light.position - sp.origin;
  const float d2 = dot(to_light, to_light);
  if (!(d2 > 0.0f)) return false;
  const float d = std::sqrt(d2);
  const Vec3 wi = to_light / d;
  if (dot(sp.n, wi) <= 0.0f) return false;  // below the surface itself, whatever the shading normal
  const float cos_surface = dot(sp.shading_n, wi);
  if (cos_surface <= 0.0f) return false;
  // Irradiance from a light of area A at distance d: power * cos_l / (d^2 + A/pi), exact on the
  // axis of a disk of that area and free of the 1/d^2 blow-up near the lamp; 1/d^2 for points.
  const float cos_light = light.is_point() ? 1.0f : std::fabs(dot(light.normal, wi));
  const float falloff = cos_light / (d2 + light.area * std::numbers::inv_pi_v<float>);
  shadow = Ray{};
  shadow.org = sp.origin;
  shadow.dir = wi;
  shadow.tfar = d * (1.0f - 1e-4f);  // stop short of the light's own surface
  contribution = sp.albedo_over_pi * light.power * (falloff * cos_surface);
  return true;
}

// Adds the ambient term, scaled by the fraction of `sp`'s AO rays that escape, and returns the
// pixel's colour.
template <class Accel>
Vec3 finish_with_ambient(const Accel& accel, const RenderContext& ctx, int x, int y, const SurfacePoint& sp,
                         RayCounts& counts, uint32_t sample = 0) {
  const RenderSettings& s = ctx.settings;
  float unoccluded = 1.0f;
  if (s.ao_samples > 0) {
    const uint32_t pixel = uint32_t(y) * uint32_t(s.width) + uint32_t(x);
    // Sample k of the pixel takes AO rays k * ao_samples ... of its stream: distinct per sample,
    // and sample 0's are the one-sample image's.
    const uint32_t first_ray = sample * uint32_t(s.ao_samples);
    const auto direction = [&](int i) {
      const SampleRng rng(pixel, first_ray + uint32_t(i), s.seed);
      return ao_direction(sp.n, rng.draw(0), rng.draw(1));
    };
    int open = 0;
    bool bundled = false;
    if constexpr (BundleAccelerator<Accel>) {
      if (s.packets) {
        // Up to 16 rays at a time; each gets the answer it gets alone, so the image is the same.
        for (int first = 0; first < s.ao_samples; first += kPacketSize) {
          RayBundle bundle;
          bundle.org = sp.origin;
          bundle.tfar = s.ao_distance;
          const int count = std::min(kPacketSize, s.ao_samples - first);
          for (int k = 0; k < count; ++k) bundle.set_direction(k, direction(first + k));
          open += count - std::popcount(accel.occluded_bundle_from(bundle, sp.tri));
        }
        bundled = true;
      }
    }
    if (!bundled) {
      for (int i = 0; i < s.ao_samples; ++i) {
        Ray ao;
        ao.org = sp.origin;
        ao.dir = direction(i);
        ao.tfar = s.ao_distance;
        open += occluded_leaving(accel, ao, sp.tri) ? 0 : 1;
      }
    }
    counts.ao += uint64_t(s.ao_samples);
    unoccluded = float(open) / float(s.ao_samples);
  }
  return sp.color + sp.mat->kd * (s.ambient * unoccluded);
}

// Adds to sp.color what every light gives it, one shadow ray per light, in the lights' order.
template <class Accel>
void add_direct_light(const Accel& accel, const RenderContext& ctx, SurfacePoint& sp, RayCounts& counts) {
  for (const Light& light : ctx.scene->lights) {
    Ray shadow;
    Vec3 contribution;
    if (!light_sample(sp, light, shadow, contribution)) continue;
    ++counts.shadow;
    if (!occluded_leaving(accel, shadow, sp.tri)) sp.color += contribution;
  }
}

// The colour of pixel (x, y) whose primary ray `primary` found `hit` (invalid: nothing).
template <class Accel>
Vec3 shade_hit(const Accel& accel, const RenderContext& ctx, int x, int y, const Ray& primary, const Hit& hit,
               RayCounts& counts, uint32_t sample = 0) {
  if (!hit.valid()) return Vec3{0.0f};
  SurfacePoint sp = surface_point(ctx, primary, hit);
  add_direct_light(accel, ctx, sp, counts);
  return finish_with_ambient(accel, ctx, x, y, sp, counts, sample);
}

template <class Accel>
Vec3 shade_pixel(const Accel& accel, const RenderContext& ctx, int x, int y, RayCounts& counts) {
  const Ray primary = ctx.camera.primary_ray(x, y);
  ++counts.primary;
  Hit hit;
  accel.intersect(primary, hit);
  return shade_hit(accel, ctx, x, y, primary, hit, counts);
}

// A 4x4 pixel block at (bx, by), clipped to the tile: its primary rays as one packet, then per
// light its shadow rays as one packet (one call where the accelerator takes occlusion packets),
// then each hit's AO rays. Each ray gets the answer it gets alone and every pixel sums its lights
// in the same order, so the image is the one shade_pixel() makes.
template <class Accel>
void shade_block(const Accel& accel, const RenderContext& ctx, const Tile& tile, int bx, int by, RayCounts& counts) {
  RayPacket packet;
  Ray rays[kPacketSize];
  for (int k = 0; k < kPacketSize; ++k) {
    const int x = bx + k % kPacketEdge, y = by + k / kPacketEdge;
    if (x >= tile.x1 || y >= tile.y1) continue;
    rays[k] = ctx.camera.primary_ray(x, y);
    packet.set(k, rays[k]);
  }
  Hit hits[kPacketSize];
  accel.intersect_packet(packet, hits);
  counts.primary += uint64_t(std::popcount(packet.active));
  SurfacePoint sps[kPacketSize];
  uint32_t lit = 0;  // lanes that hit something
  for (uint32_t bits = packet.active; bits; bits &= bits - 1) {
    const int k = __builtin_ctz(bits);
    if (!hits[k].valid()) {
      ctx.framebuffer->add(bx + k % kPacketEdge, by + k / kPacketEdge, Vec3{0.0f});
      continue;
    }
    sps[k] = surface_point(ctx, rays[k], hits[k]);
    lit |= 1u << k;
  }
  for (const Light& light : ctx.scene->lights) {
    RayPacket shadows;
    Vec3 contribution[kPacketSize];
    for (uint32_t bits = lit; bits; bits &= bits - 1) {
      const int k = __builtin_ctz(bits);
      Ray shadow;
      if (light_sample(sps[k], light, shadow, contribution[k])) shadows.set(k, shadow);
    }
    if (shadows.active == 0) continue;
    counts.shadow += uint64_t(std::popcount(shadows.active));
    uint32_t blocked = 0;
    if constexpr (OcclusionPacketAccelerator<Accel>) {
      blocked = accel.occluded_packet(shadows);
    } else {
      for (uint32_t bits = shadows.active; bits; bits &= bits - 1) {
        const int k = __builtin_ctz(bits);
        if (occluded_leaving(accel, shadows.ray(k), sps[k].tri)) blocked |= 1u << k;
      }
    }
    for (uint32_t bits = shadows.active & ~blocked; bits; bits &= bits - 1) {
      const int k = __builtin_ctz(bits);
      sps[k].color += contribution[k];
    }
  }
  for (uint32_t bits = lit; bits; bits &= bits - 1) {
    const int k = __builtin_ctz(bits);
    const int x = bx + k % kPacketEdge, y = by + k / kPacketEdge;
    ctx.framebuffer->add(x, y, finish_with_ambient(accel, ctx, x, y, sps[k], counts));
  }
}

}  // namespace tracer
