// The one pixel-sample loop, as pbrt-v4's RayIntegrator owns it: for each pixel of a tile, the
// samples of this pass, each with its pixel id, its sample streams and its camera ray (through a
// point of the pixel and of the lens); the integrator gives the radiance along that ray, and the
// loop adds the pixel's sum to the films. Every sample is a function of (pixel, sample index,
// seed), so passes, tiles, threads and schedulers add up to the same image.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <concepts>
#include <cstdint>

#include "film/convergence.hpp"
#include "math/rng.hpp"
#include "math/sobol.hpp"
#include "parallel/tiles.hpp"
#include "render/accel_concepts.hpp"
#include "render/pass_context.hpp"
#include "render/ray_counts.hpp"

namespace tracer {

// One sample of one pixel.
struct PixelSample {
  int x = 0, y = 0;
  uint32_t pixel = 0;  // y * width + x: the id every sample stream of the pixel starts from
  uint32_t index = 0;  // the sample's number in the pixel: sample k of pass after pass
  Ray ray;             // the camera ray
};

// What the camera ray hits first, for the --aov layers: its albedo (the diffuse colour, plus the
// specular colour of glossy materials, 1 for mirrors and glass, as Intel's denoiser takes it) and
// its shading normal; both zero where the ray escapes.
struct FirstHit {
  Vec3 albedo{0.0f}, normal{0.0f};
};

// The denoiser's guides: the albedo and shading normal of the first vertex that is not a mirror
// or glass (seen through them, as Intel's denoiser and NFOR take them), and the distance along the
// path to it. Zero where the path escapes first.
struct GuideFeatures {
  Vec3 albedo{0.0f}, normal{0.0f};
  float distance = 0.0f;  // along the path, camera to the vertex
};

// Path tracing's sample streams: one stratified sampler per sample (math/sobol.hpp); the point
// in the pixel is set 0, the lens point a set of its own beyond every bounce's (--max-depth is at
// most 64), drawn only when the camera has a lens, so a pinhole's samples are unchanged.
inline constexpr uint32_t kPixelSet = 0;
inline constexpr uint32_t kLensSet = 1u << 16;
#ifdef TRACER_INDEPENDENT_SAMPLES
using PathSampler = SampleRng;  // the baseline scripts/benchmarks-sampler.sh measures against
#else
using PathSampler = PixelSampler;
#endif
struct PathStreams {
  using Sampler = PathSampler;
  static constexpr bool kCentredSingleSample = false;
  static Sampler sampler(uint32_t pixel, uint32_t index, uint32_t seed) { return Sampler(pixel, index, seed); }
  static std::array<float, 4> camera_numbers(const Sampler& s, bool lens) {
    const std::array<float, 2> p = s.template get<2>(kPixelSet);
    if (!lens) return {p[0], p[1], 0.0f, 0.0f};
    const std::array<float, 2> l = s.template get<2>(kLensSet);
    return {p[0], p[1], l[0], l[1]};
  }
};

// ao's and whitted's: one sample through the pixel centre (the study's) unless there are more or
// a lens, then a jittered point of the pixel and of the lens from a stream apart from the AO rays'.
struct JitterStreams {
  using Sampler = SampleRng;
  static constexpr bool kCentredSingleSample = true;
  static constexpr uint32_t kJitterStream = 0x2545f491u;
  static Sampler sampler(uint32_t pixel, uint32_t index, uint32_t seed) {
    return Sampler(pixel, index, seed ^ kJitterStream);
  }
  static std::array<float, 4> camera_numbers(const Sampler& s, bool lens) {
    return {s.draw(0), s.draw(1), lens ? s.draw(2) : 0.0f, lens ? s.draw(3) : 0.0f};
  }
};

// A 4x4 block of pixels at (x0, y0) whose camera rays go as one packet (lanes off the tile are
// inactive): the centred single sample of every pixel.
struct PixelBlock {
  int x0 = 0, y0 = 0;
  Ray rays[kPacketSize];
  RayPacket packet;
  int x(int lane) const { return x0 + lane % kPacketEdge; }
  int y(int lane) const { return y0 + lane / kPacketEdge; }
};

// Builds the block at (bx, by) with the camera rays of its pixels left of x1 and above y1.
inline PixelBlock primary_block(const PassContext& ctx, int bx, int by, int x1, int y1) {
  PixelBlock block;
  block.x0 = bx;
  block.y0 = by;
  for (int k = 0; k < kPacketSize; ++k) {
    if (block.x(k) >= x1 || block.y(k) >= y1) continue;
    block.rays[k] = ctx.camera.primary_ray(block.x(k), block.y(k));
    block.packet.set(k, block.rays[k]);
  }
  return block;
}

// Up to 16x16 pixels of a tile whose centred samples' AO rays are traced as one stream: 16 AO
// rays per pixel fill a RayStream. Pixel p of the chunk is (x0 + p % 16, y0 + p / 16).
inline constexpr int kChunkEdge = 16;
inline constexpr int kChunkPixels = kChunkEdge * kChunkEdge;
struct PixelChunk {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // x1, y1 exclusive, at most kChunkEdge past x0, y0
  int index(int x, int y) const { return (y - y0) * kChunkEdge + (x - x0); }
  int x(int p) const { return x0 + p % kChunkEdge; }
  int y(int p) const { return y0 + p / kChunkEdge; }
  bool contains(int p) const { return x(p) < x1 && y(p) < y1; }
};

// An integrator: its sample streams and the radiance along a sample's camera ray. `first` and
// `guide`, when not null, take what the --aov layers and the denoiser read of the sample.
template <class I, class Accel>
concept PixelIntegrator = requires(const I& i, const Accel& accel, const PassContext& ctx, const PixelSample& ps,
                                   const typename I::Streams::Sampler& sampler, RayCounts& counts) {
  { i.radiance(accel, ctx, ps, sampler, counts, (FirstHit*)nullptr, (GuideFeatures*)nullptr) } -> std::same_as<Vec3>;
};
// One that also shades a block's centred samples together (the study's ao with packets): the
// radiance of each active lane into radiance[lane], each what radiance() gives its pixel.
template <class I, class Accel>
concept BlockIntegrator = PixelIntegrator<I, Accel> &&
    requires(const I& i, const Accel& accel, const PassContext& ctx, const PixelBlock& block, Vec3* radiance,
             RayCounts& counts) {
  i.block_radiance(accel, ctx, block, radiance, counts);
};

// One that also shades a chunk's centred samples with their AO rays as one stream (--streams):
// radiance[p] of each pixel p of the chunk, each what radiance() gives that pixel.
template <class I, class Accel>
concept ChunkIntegrator = BlockIntegrator<I, Accel> &&
    requires(const I& i, const Accel& accel, const PassContext& ctx, const PixelChunk& chunk, Vec3* radiance,
             RayCounts& counts) {
  i.chunk_radiance(accel, ctx, chunk, radiance, counts);
};

// Adds this pass's samples (ctx.samples) of every pixel of `tile` (those ctx.active keeps) to the
// films: each pixel's sum taken in sample order from zero (see Framebuffer). A sample that comes
// out non-finite (a float overflow on a degenerate path) adds black rather than poisoning it.
template <class Integrator, class Accel>
requires PixelIntegrator<Integrator, Accel>
void render_pixels(const Integrator& integrator, const Accel& accel, const PassContext& ctx, const Tile& tile,
                   RayCounts& counts) {
  using Streams = typename Integrator::Streams;
  const RenderSettings& s = ctx.settings;
  const bool lens = ctx.camera.thin_lens();
  const bool centred = Streams::kCentredSingleSample && s.spp == 1 && !lens;
  if constexpr (BlockIntegrator<Integrator, Accel>) {
    if (centred && s.packets) {
      if constexpr (ChunkIntegrator<Integrator, Accel>) {
        if (s.streams) {
          for (int cy = tile.y0; cy < tile.y1; cy += kChunkEdge) {
            for (int cx = tile.x0; cx < tile.x1; cx += kChunkEdge) {
              const PixelChunk chunk{cx, cy, std::min(cx + kChunkEdge, tile.x1), std::min(cy + kChunkEdge, tile.y1)};
              Vec3 radiance[kChunkPixels];
              integrator.chunk_radiance(accel, ctx, chunk, radiance, counts);
              for (int p = 0; p < kChunkPixels; ++p)
                if (chunk.contains(p)) ctx.framebuffer->add(chunk.x(p), chunk.y(p), radiance[p]);
            }
          }
          return;
        }
      }
      for (int by = tile.y0; by < tile.y1; by += kPacketEdge) {
        for (int bx = tile.x0; bx < tile.x1; bx += kPacketEdge) {
          const PixelBlock block = primary_block(ctx, bx, by, tile.x1, tile.y1);
          counts.primary += uint64_t(std::popcount(block.packet.active));
          Vec3 radiance[kPacketSize];
          integrator.block_radiance(accel, ctx, block, radiance, counts);
          for (uint32_t bits = block.packet.active; bits; bits &= bits - 1) {
            const int k = std::countr_zero(bits);
            ctx.framebuffer->add(block.x(k), block.y(k), radiance[k]);
          }
        }
      }
      return;
    }
  }
  const bool want_first = ctx.albedo || ctx.normal;
  for (int y = tile.y0; y < tile.y1; ++y) {
    for (int x = tile.x0; x < tile.x1; ++x) {
      if (ctx.active && !ctx.active->active(x, y)) continue;
      PixelSample ps;
      ps.x = x;
      ps.y = y;
      ps.pixel = uint32_t(y) * uint32_t(s.width) + uint32_t(x);
      Vec3 sum{0.0f}, half{0.0f}, albedo{0.0f}, normal{0.0f};
      FeatureFilm::PixelSums features;
      for (uint32_t k = ctx.samples.first, end = ctx.samples.first + ctx.samples.count; k < end; ++k) {
        const typename Streams::Sampler sampler = Streams::sampler(ps.pixel, k, s.seed);
        ps.index = k;
        if (centred) {
          ps.ray = ctx.camera.primary_ray(x, y);
        } else {
          const std::array<float, 4> u = Streams::camera_numbers(sampler, lens);
          ps.ray = lens ? ctx.camera.ray_through(float(x) + u[0], float(y) + u[1], u[2], u[3])
                        : ctx.camera.ray_through(float(x) + u[0], float(y) + u[1]);
        }
        ++counts.primary;
        FirstHit first;
        GuideFeatures guide;
        Vec3 l = integrator.radiance(accel, ctx, ps, sampler, counts, want_first ? &first : nullptr,
                                     ctx.features ? &guide : nullptr);
        if (!is_finite(l)) l = Vec3{0.0f};
        sum += l;
        if (in_half(k)) half += l;
        albedo += first.albedo;
        normal += first.normal;
        if (ctx.features) features.add({l, guide.albedo, guide.normal, guide.distance}, in_half(k));
      }
      ctx.framebuffer->add(x, y, sum, half, ctx.samples.count);
      if (ctx.albedo) ctx.albedo->add(x, y, albedo, ctx.samples.count);
      if (ctx.normal) ctx.normal->add(x, y, normal, ctx.samples.count);
      if (ctx.features) ctx.features->add(x, y, features);
    }
  }
}

}  // namespace tracer
