#include "render/render_image.hpp"

namespace tracer {

bool render_image(const Accelerator& accel, const RenderContext& ctx, const SchedOptions& options,
                  RenderControl& control) {
  return parallel_for_tiles(
      ctx.framebuffer->width(), ctx.framebuffer->height(), options, control.cancel, [&](const Tile& tile) {
        // The one place the accelerator variant is dispatched: once per tile.
        const RayCounts counts = accel.visit([&](const auto& a) { return render_tile(a, ctx, tile); });
        control.counts.add(counts);
        control.rays_done.fetch_add(counts.total(), std::memory_order_relaxed);
        control.pixels_done.fetch_add(uint64_t(tile.pixel_count()), std::memory_order_relaxed);
        if (control.on_tile) control.on_tile(tile);
      });
}

}  // namespace tracer
