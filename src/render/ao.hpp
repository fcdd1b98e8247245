// The study's workload, defined once so every accelerator and scheduler traces the same rays:
// per pixel one primary ray through the pixel centre; at a hit one shadow ray per light (its
// centroid) and N ambient-occlusion rays; every surface diffuse. Its images are the golden ones.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "math/rng.hpp"
#include "render/direct_light.hpp"
#include "render/pixel_samples.hpp"
#include "render/stream_order.hpp"
#include "scene/emission.hpp"

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

// AO ray i of sample `sample` of pixel (x, y), leaving `si`. Sample k of the pixel takes AO rays
// k * ao_samples ... of its stream: distinct per sample, and sample 0's are the one-sample image's.
inline Ray ao_ray(const RenderSettings& s, int x, int y, const SurfaceInteraction& si, uint32_t sample, int i) {
  const uint32_t pixel = uint32_t(y) * uint32_t(s.width) + uint32_t(x);
  const SampleRng rng(pixel, sample * uint32_t(s.ao_samples) + uint32_t(i), s.seed);
  Ray ao;
  ao.org = si.origin;
  ao.dir = ao_direction(si.n, rng.draw(0), rng.draw(1));
  ao.tfar = s.ao_distance;
  return ao;
}

// `direct` plus the ambient term scaled by the fraction of si's AO rays that escape (`open` of
// ao_samples; all of them without AO).
inline Vec3 with_ambient(const RenderSettings& s, const SurfaceInteraction& si, Vec3 direct, int open) {
  const float unoccluded = s.ao_samples > 0 ? float(open) / float(s.ao_samples) : 1.0f;
  return direct + si.mat->kd * (s.ambient * unoccluded);
}

// How many of `si`'s AO rays (sample `sample` of pixel (x, y)) escape: by bundles of 16 with
// packets, else one by one.
template <class Accel>
int open_ao_rays(const Accel& accel, const RenderSettings& s, int x, int y, const SurfaceInteraction& si,
                 RayCounts& counts, uint32_t sample = 0) {
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
        for (int k = 0; k < count; ++k) bundle.set_direction(k, ao_ray(s, x, y, si, sample, first + k).dir);
        open += count - std::popcount(accel.occluded_bundle_from(bundle, si.tri));
      }
      bundled = true;
    }
  }
  if (!bundled) {
    for (int i = 0; i < s.ao_samples; ++i)
      open += occluded_leaving(accel, ao_ray(s, x, y, si, sample, i), si.tri) ? 0 : 1;
  }
  counts.ao += uint64_t(s.ao_samples);
  return open;
}

// `direct` (the hit's emission and lamp light) plus the ambient term, scaled by the fraction of
// `si`'s AO rays that escape: the pixel's colour.
template <class Accel>
Vec3 finish_with_ambient(const Accel& accel, const PassContext& ctx, int x, int y, const SurfaceInteraction& si,
                         Vec3 direct, RayCounts& counts, uint32_t sample = 0) {
  const RenderSettings& s = ctx.settings;
  const int open = s.ao_samples > 0 ? open_ao_rays(accel, s, x, y, si, counts, sample) : 0;
  return with_ambient(s, si, direct, open);
}

// The colour of pixel (x, y) whose primary ray `primary` found `hit` (invalid: nothing).
template <class Accel>
Vec3 shade_hit(const Accel& accel, const PassContext& ctx, int x, int y, const Ray& primary, const Hit& hit,
               RayCounts& counts, uint32_t sample = 0) {
  if (!hit.valid()) return Vec3{0.0f};
  const SurfaceInteraction si = surface_interaction(ctx, primary, hit);
  const Vec3 direct = add_lamp_light(accel, ctx, si, emitted_radiance(*ctx.scene, hit.tri, hit.u, hit.v), counts);
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

  // The primary rays of `block` as one packet and the direct light at their hits: radiance[k] of
  // each active lane (black where it escapes), sis[k] and bit k of the returned mask where it hit.
  template <class Accel>
  requires PacketAccelerator<Accel>
  static uint32_t block_direct(const Accel& accel, const PassContext& ctx, const PixelBlock& block, Vec3* radiance,
                               SurfaceInteraction* sis, RayCounts& counts) {
    Hit hits[kPacketSize];
    accel.intersect_packet(block.packet, hits);
    uint32_t lit = 0;  // lanes that hit something
    for (uint32_t bits = block.packet.active; bits; bits &= bits - 1) {
      const int k = std::countr_zero(bits);
      radiance[k] = Vec3{0.0f};
      if (!hits[k].valid()) continue;
      sis[k] = surface_interaction(ctx, block.rays[k], hits[k]);
      radiance[k] = emitted_radiance(*ctx.scene, hits[k].tri, hits[k].u, hits[k].v);
      lit |= 1u << k;
    }
    add_lamp_light(accel, ctx, sis, lit, radiance, counts);
    return lit;
  }

  template <class Accel>
  requires PacketAccelerator<Accel>
  void block_radiance(const Accel& accel, const PassContext& ctx, const PixelBlock& block, Vec3* radiance,
                      RayCounts& counts) const {
    SurfaceInteraction sis[kPacketSize];
    const uint32_t lit = block_direct(accel, ctx, block, radiance, sis, counts);
    for (uint32_t bits = lit; bits; bits &= bits - 1) {
      const int k = std::countr_zero(bits);
      radiance[k] = finish_with_ambient(accel, ctx, block.x(k), block.y(k), sis[k], radiance[k], counts);
    }
  }

  // A chunk of up to 16x16 pixels' centred samples as a stream (render/stream_order.hpp): the
  // primary rays and shadow rays by 4x4 blocks as block_radiance() traces them, then every hit's
  // AO rays gathered into one stream, sorted, traced by the accelerator's stream kernel and
  // counted back per pixel. Each ray gets the answer it gets alone and a pixel's colour depends
  // only on how many of its rays escape, so the colours are those radiance() gives.
  template <class Accel>
  requires PacketAccelerator<Accel> && StreamAccelerator<Accel>
  void chunk_radiance(const Accel& accel, const PassContext& ctx, const PixelChunk& chunk, Vec3* radiance,
                      RayCounts& counts) const {
    const RenderSettings& s = ctx.settings;
    SurfaceInteraction sis[kChunkPixels];
    int open[kChunkPixels] = {};
    std::array<uint32_t, kChunkPixels / 32> lit{};
    const auto is_lit = [&lit](int p) { return (lit[size_t(p) / 32] >> (p % 32) & 1u) != 0; };
    for (int by = chunk.y0; by < chunk.y1; by += kPacketEdge) {
      for (int bx = chunk.x0; bx < chunk.x1; bx += kPacketEdge) {
        const PixelBlock block = primary_block(ctx, bx, by, chunk.x1, chunk.y1);
        counts.primary += uint64_t(std::popcount(block.packet.active));
        Vec3 direct[kPacketSize];
        SurfaceInteraction block_sis[kPacketSize];
        const uint32_t block_lit = block_direct(accel, ctx, block, direct, block_sis, counts);
        for (uint32_t bits = block.packet.active; bits; bits &= bits - 1) {
          const int k = std::countr_zero(bits);
          const int p = chunk.index(block.x(k), block.y(k));
          radiance[p] = direct[k];
          if (!(block_lit >> k & 1u)) continue;
          sis[p] = block_sis[k];
          lit[size_t(p) / 32] |= 1u << (p % 32);
        }
      }
    }
    if (s.ao_samples > 0) {
      // The probe: the corner pixel of each 4x4 block (where lit) traces its AO rays by bundles.
      // Where a quarter or more of them escape (or no corner is lit), the chunk's other pixels do
      // too: escaping rays cross the tree, where a stream's packets of rays from scattered origins
      // cost more than a bundle from one point (the Bunny). Else the rest go as one stream, which
      // the occluder cache makes cheap where nearly every ray is blocked (Sponza). The counts per
      // ray, with their commands: docs/BENCHMARKS.md section 23 and docs/bench/LOG.md, session 31.
      const auto is_probe = [](int p) { return p % kPacketEdge == 0 && p / kChunkEdge % kPacketEdge == 0; };
      int probe_rays = 0, probe_open = 0;
      for (int p = 0; p < kChunkPixels; ++p) {
        if (!is_probe(p) || !is_lit(p)) continue;
        open[p] = open_ao_rays(accel, s, chunk.x(p), chunk.y(p), sis[p], counts);
        probe_rays += s.ao_samples;
        probe_open += open[p];
      }
      const bool stream_rest = 4 * probe_open < probe_rays;
      static thread_local RayStream stream;  // 160 KB: kept per thread, not on the stack
      stream.size = 0;
      const auto flush = [&] {
        sort_stream(stream);
        StreamMask occluded;
        accel.occluded_stream(stream, occluded);
        for (uint32_t i = 0; i < stream.size; ++i) open[stream.owner[i]] += occluded.test(i) ? 0 : 1;
        stream.size = 0;
      };
      for (int p = 0; p < kChunkPixels; ++p) {
        if (!is_lit(p) || is_probe(p)) continue;
        if (!stream_rest) {
          open[p] = open_ao_rays(accel, s, chunk.x(p), chunk.y(p), sis[p], counts);
          continue;
        }
        for (int i = 0; i < s.ao_samples; ++i) {
          if (stream.full()) flush();
          stream.push(ao_ray(s, chunk.x(p), chunk.y(p), sis[p], 0, i), uint16_t(p));
        }
        counts.ao += uint64_t(s.ao_samples);
      }
      if (stream.size > 0) flush();
    }
    for (int p = 0; p < kChunkPixels; ++p)
      if (is_lit(p)) radiance[p] = with_ambient(s, sis[p], radiance[p], open[p]);
  }
};

}  // namespace tracer
