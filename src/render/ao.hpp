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
#include "render/direct_light.hpp"
#include "render/pixel_samples.hpp"

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
Vec3 finish_with_ambient(const Accel& accel, const PassContext& ctx, int x, int y, const SurfaceInteraction& si,
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
Vec3 shade_hit(const Accel& accel, const PassContext& ctx, int x, int y, const Ray& primary, const Hit& hit,
               RayCounts& counts, uint32_t sample = 0) {
  if (!hit.valid()) return Vec3{0.0f};
  const SurfaceInteraction si = surface_interaction(ctx, primary, hit);
  const Vec3 direct = add_lamp_light(accel, ctx, si, si.mat->ke, counts);
  return finish_with_ambient(accel, ctx, x, y, si, direct, counts, sample);
}

// The study's workload as the pixel-sample loop (render/pixel_samples.hpp) takes it: a sample's
// colour, and a 4x4 block's centred samples together -- the primary rays as one packet, then per
// light the shadow rays as one packet (add_lamp_light's packet form), then each hit's AO rays.
// Each ray gets the answer it gets alone and every pixel sums its lights in the same order, so a
// block's colours are those radiance() gives.
struct AoIntegrator {
  using Streams = JitterStreams;
  template <class Accel>
  Vec3 radiance(const Accel& accel, const PassContext& ctx, const PixelSample& ps, const SampleRng&, RayCounts& counts,
                FirstHit*, GuideFeatures*) const {
    Hit hit;
    accel.intersect(ps.ray, hit);
    return shade_hit(accel, ctx, ps.x, ps.y, ps.ray, hit, counts, ps.index);
  }

  template <class Accel>
  requires PacketAccelerator<Accel>
  void block_radiance(const Accel& accel, const PassContext& ctx, const PixelBlock& block, Vec3* radiance,
                      RayCounts& counts) const {
    Hit hits[kPacketSize];
    accel.intersect_packet(block.packet, hits);
    SurfaceInteraction sis[kPacketSize];
    uint32_t lit = 0;  // lanes that hit something
    for (uint32_t bits = block.packet.active; bits; bits &= bits - 1) {
      const int k = std::countr_zero(bits);
      radiance[k] = Vec3{0.0f};
      if (!hits[k].valid()) continue;
      sis[k] = surface_interaction(ctx, block.rays[k], hits[k]);
      radiance[k] = sis[k].mat->ke;
      lit |= 1u << k;
    }
    add_lamp_light(accel, ctx, sis, lit, radiance, counts);
    for (uint32_t bits = lit; bits; bits &= bits - 1) {
      const int k = std::countr_zero(bits);
      radiance[k] = finish_with_ambient(accel, ctx, block.x(k), block.y(k), sis[k], radiance[k], counts);
    }
  }
};

}  // namespace tracer
