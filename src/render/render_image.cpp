#include "render/render_image.hpp"

#include <algorithm>
#include <type_traits>

namespace tracer {

NoiseTarget noise_target(const RenderSettings& s) {
  if (s.integrator != Integrator::Path) return {};
  return {s.noise_threshold, uint32_t(std::max(s.min_spp, 2)), s.exposure};
}

void choose_active_pixels(PassContext& ctx, RenderMonitor& control) {
  const NoiseTarget target = noise_target(ctx.settings);
  if (target.threshold <= 0.0f) return;
  if (ctx.samples.first < target.min_samples) {
    control.active_pixels.store(ctx.framebuffer->pixel_count(), std::memory_order_relaxed);
    return;
  }
  control.active.update(*ctx.framebuffer, target, ctx.samples.first);
  control.active_pixels.store(control.active.active_pixels(), std::memory_order_relaxed);
  ctx.active = &control.active;
}

TileResult render_tile_of(const Accelerator& accel, const PassContext& ctx, const Tile& tile, CancelFlag cancel) {
  // The tile is walked in pieces of kPieceWidth x kChunkEdge pixels (aligned to the tile, so
  // packet blocks and stream chunks are the same) with the cancel flag checked between them: a
  // whole-row tile of the async and seq schedulers or a --tile 4096 stops within moments of a
  // Ctrl-C.
  constexpr int kPieceWidth = 64;
  TileResult result;
  const auto pieces = [&](const auto& a) {
    for (int y = tile.y0; y < tile.y1 && !is_cancelled(cancel); y += kChunkEdge) {
      for (int x = tile.x0; x < tile.x1 && !is_cancelled(cancel); x += kPieceWidth) {
        const Tile piece{x, y, std::min(x + kPieceWidth, tile.x1), std::min(y + kChunkEdge, tile.y1)};
        result.rays += render_tile(a, ctx, piece);
        result.pixels += uint64_t(piece.pixel_count());
      }
    }
  };
  accel.visit([&](const auto& a) {
    using A = std::decay_t<decltype(a)>;
    if constexpr (CountingAccelerator<A>) {
      if (ctx.settings.count_traversal) {
        pieces(Counted<A>(a, result.traversal));
        return;
      }
    }
    pieces(a);
  });
  return result;
}

bool render_image(const Accelerator& accel, const PassContext& image, const SchedOptions& options,
                  RenderMonitor& control) {
  PassContext ctx = image;
  choose_active_pixels(ctx, control);
  return parallel_for_tiles(ctx.framebuffer->width(), ctx.framebuffer->height(), options, control.cancel,
                            [&](const Tile& tile) {
                              const TileResult r = render_tile_of(accel, ctx, tile, control.cancel);
                              control.pixels_done.fetch_add(r.pixels * ctx.samples.count, std::memory_order_relaxed);
                              if (ctx.settings.count_traversal) control.traversal.add(r.traversal);
                              control.counts.add(r.rays);
                              control.rays_done.fetch_add(r.rays.total(), std::memory_order_relaxed);
                              if (control.on_tile) control.on_tile(tile);
                            });
}

std::vector<SampleRange> sample_passes(const RenderSettings& settings) {
  std::vector<SampleRange> passes;
  const uint32_t total = uint32_t(std::max(settings.spp, 1));
  for (uint32_t done = 0; done < total;) {
    // Adaptive: at least kAdaptivePassSamples, then an eighth of the samples so far (a pixel
    // takes at most 1/8 more than it needed, and the decisions' cost stays small), up to 64.
    const uint32_t most =
        adaptive(settings) ? std::clamp(done / 8, kAdaptivePassSamples, kMaxPassSamples) : kMaxPassSamples;
    const uint32_t count = std::min({total - done, std::max(done, 1u), most});
    passes.push_back({done, count});
    done += count;
  }
  return passes;
}

bool render_round(const Accelerator& accel, PassContext ctx, const std::vector<SampleRange>& round,
                  const SchedOptions& options, RenderMonitor& control) {
  for (const SampleRange& pass : round) {
    ctx.samples = pass;
    if (!render_image(accel, ctx, options, control)) return false;
  }
  return true;
}

}  // namespace tracer
