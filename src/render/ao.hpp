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
#include "render/direct_light.hpp"

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

// `direct` (the hit's emission and lamp light) plus the ambient term, scaled by the fraction of
// `si`'s AO rays that escape: the pixel's colour.
template <class Accel>
Vec3 finish_with_ambient(const Accel& accel, const RenderContext& ctx, int x, int y, const SurfaceInteraction& si,
                         Vec3 direct, RayCounts& counts, uint32_t sample = 0) {
  const RenderSettings& s = ctx.settings;
  float unoccluded = 1.0f;
  if (s.ao_samples > 0) {
    const uint32_t pixel = uint32_t(y) * uint32_t(s.width) + uint32_t(x);
    // Sample k of the pixel takes AO rays k * ao_samples ... of its stream: distinct per sample,
    // and sample 0's are the one-sample image's.
    const uint32_t first_ray = sample * uint32_t(s.ao_samples);
    const auto direction = [&](int i) {
      const SampleRng rng(pixel, first_ray + uint32_t(i), s.seed);
      return ao_direction(si.n, rng.draw(0), rng.draw(1));
    };
    int open = 0;
    bool bundled = false;
    if constexpr (BundleAccelerator<Accel>) {
      if (s.packets) {
        // Up to 16 rays at a time; each gets the answer it gets alone, so the image is the same.
        for (int first = 0; first < s.ao_samples; first += kPacketSize) {
          RayBundle bundle;
          bundle.org = si.origin;
          bundle.tfar = s.ao_distance;
          const int count = std::min(kPacketSize, s.ao_samples - first);
          for (int k = 0; k < count; ++k) bundle.set_direction(k, direction(first + k));
          open += count - std::popcount(accel.occluded_bundle_from(bundle, si.tri));
        }
        bundled = true;
      }
    }
    if (!bundled) {
      for (int i = 0; i < s.ao_samples; ++i) {
        Ray ao;
        ao.org = si.origin;
        ao.dir = direction(i);
        ao.tfar = s.ao_distance;
        open += occluded_leaving(accel, ao, si.tri) ? 0 : 1;
      }
    }
    counts.ao += uint64_t(s.ao_samples);
    unoccluded = float(open) / float(s.ao_samples);
  }
  return direct + si.mat->kd * (s.ambient * unoccluded);
}

// The colour of pixel (x, y) whose primary ray `primary` found `hit` (invalid: nothing).
template <class Accel>
Vec3 shade_hit(const Accel& accel, const RenderContext& ctx, int x, int y, const Ray& primary, const Hit& hit,
               RayCounts& counts, uint32_t sample = 0) {
  if (!hit.valid()) return Vec3{0.0f};
  const SurfaceInteraction si = surface_interaction(ctx, primary, hit);
  const Vec3 direct = add_lamp_light(accel, ctx, si, si.mat->ke, counts);
  return finish_with_ambient(accel, ctx, x, y, si, direct, counts, sample);
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
// light its shadow rays as one packet (add_lamp_light's packet form), then each hit's AO rays.
// Each ray gets the answer it gets alone and every pixel sums its lights in the same order, so
// the image is the one shade_pixel() makes.
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
  SurfaceInteraction sis[kPacketSize];
  uint32_t lit = 0;  // lanes that hit something
  for (uint32_t bits = packet.active; bits; bits &= bits - 1) {
    const int k = __builtin_ctz(bits);
    if (!hits[k].valid()) {
      ctx.framebuffer->add(bx + k % kPacketEdge, by + k / kPacketEdge, Vec3{0.0f});
      continue;
    }
    sis[k] = surface_interaction(ctx, rays[k], hits[k]);
    lit |= 1u << k;
  }
  Vec3 direct[kPacketSize];
  for (uint32_t bits = lit; bits; bits &= bits - 1) direct[__builtin_ctz(bits)] = sis[__builtin_ctz(bits)].mat->ke;
  add_lamp_light(accel, ctx, sis, lit, direct, counts);
  for (uint32_t bits = lit; bits; bits &= bits - 1) {
    const int k = __builtin_ctz(bits);
    const int x = bx + k % kPacketEdge, y = by + k / kPacketEdge;
    ctx.framebuffer->add(x, y, finish_with_ambient(accel, ctx, x, y, sis[k], direct[k], counts));
  }
}

}  // namespace tracer
