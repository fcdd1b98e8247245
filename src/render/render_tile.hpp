// One tile of an image: the integrator the settings name, chosen once per tile, over the tile's
// pixels. Templated on the accelerator so the per-ray path has no virtual call.
#pragma once

#include "render/ao.hpp"
#include "render/path.hpp"
#include "render/whitted.hpp"

namespace tracer {

// ao and whitted with more than one sample per pixel, or through a lens: each sample a ray through
// a point of the pixel (and of the lens) drawn from its own stream (pixel, sample), as path
// tracing's camera rays are, so passes, tiles and threads add up to the same image.
template <class Accel>
void antialiased_tile(const Accel& accel, const RenderContext& ctx, const Tile& tile, RayCounts& counts) {
  const RenderSettings& s = ctx.settings;
  constexpr uint32_t kJitterStream = 0x2545f491u;  // apart from the AO rays' streams
  for (int y = tile.y0; y < tile.y1; ++y) {
    for (int x = tile.x0; x < tile.x1; ++x) {
      const uint32_t pixel = uint32_t(y) * uint32_t(s.width) + uint32_t(x);
      Vec3 sum{0.0f};
      for (uint32_t k = ctx.samples.first, end = ctx.samples.first + ctx.samples.count; k < end; ++k) {
        const SampleRng rng(pixel, k, s.seed ^ kJitterStream);
        const Ray ray = ctx.camera.thin_lens() ? ctx.camera.ray_through(float(x) + rng.draw(0), float(y) + rng.draw(1),
                                                                        rng.draw(2), rng.draw(3))
                                               : ctx.camera.ray_through(float(x) + rng.draw(0), float(y) + rng.draw(1));
        ++counts.primary;
        if (s.integrator == Integrator::Whitted) {
          sum += whitted_radiance(accel, ctx, ray, 0, counts);
        } else {
          Hit hit;
          accel.intersect(ray, hit);
          sum += shade_hit(accel, ctx, x, y, ray, hit, counts, k);
        }
      }
      ctx.framebuffer->add(x, y, sum, ctx.samples.count);
    }
  }
}

template <class Accel>
RayCounts render_tile(const Accel& accel, const RenderContext& ctx, const Tile& tile) {
  RayCounts counts;
  if (ctx.settings.integrator == Integrator::Path) {
    path_tile(accel, ctx, tile, counts);
    return counts;
  }
  if (ctx.settings.spp > 1 || ctx.camera.thin_lens()) {
    antialiased_tile(accel, ctx, tile, counts);
    return counts;
  }
  if (ctx.settings.integrator == Integrator::Whitted) {
    for (int y = tile.y0; y < tile.y1; ++y) {
      for (int x = tile.x0; x < tile.x1; ++x) {
        ++counts.primary;
        ctx.framebuffer->add(x, y, whitted_radiance(accel, ctx, ctx.camera.primary_ray(x, y), 0, counts));
      }
    }
    return counts;
  }
  if constexpr (PacketAccelerator<Accel>) {
    if (ctx.settings.packets) {
      for (int by = tile.y0; by < tile.y1; by += kPacketEdge) {
        for (int bx = tile.x0; bx < tile.x1; bx += kPacketEdge) shade_block(accel, ctx, tile, bx, by, counts);
      }
      return counts;
    }
  }
  for (int y = tile.y0; y < tile.y1; ++y) {
    for (int x = tile.x0; x < tile.x1; ++x) ctx.framebuffer->add(x, y, shade_pixel(accel, ctx, x, y, counts));
  }
  return counts;
}

}  // namespace tracer
