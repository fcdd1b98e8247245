// One tile of an image: the integrator the settings name, chosen once per tile, over the tile's
// pixels. Templated on the accelerator so the per-ray path has no virtual call.
#pragma once

#include "render/ao.hpp"
#include "render/path.hpp"
#include "render/whitted.hpp"

namespace tracer {

template <class Accel>
RayCounts render_tile(const Accel& accel, const RenderContext& ctx, const Tile& tile) {
  RayCounts counts;
  if (ctx.settings.integrator == Integrator::Path) {
    path_tile(accel, ctx, tile, counts);
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
