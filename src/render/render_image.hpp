// Rendering a whole image: the workload of render_tile.hpp over every tile, handed out by one of
// the parallel_for_tiles() strategies, in one or more passes of samples. Every strategy renders
// disjoint tiles with the same per-pixel work, so the image is the same from each.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <vector>

#include "accel/accelerator.hpp"
#include "base/errors.hpp"
#include "parallel/parallel_for_tiles.hpp"
#include "render/render_tile.hpp"

namespace tracer {

// What the caller watches and stops a render by, shared with the render and tests: the cancel
// flag, progress and ray counters, a per-tile hook, adaptive sampling's active pixels.
struct RenderMonitor {
  CancelFlag cancel = nullptr;           // set (e.g. by SIGINT) to stop at the next tile
  std::atomic<uint64_t> pixels_done{0};  // pixel samples, over all passes
  std::atomic<uint64_t> rays_done{0};
  AtomicRayCounts counts;
  AtomicQueryCounts traversal;               // with settings.count_traversal, where the accelerator counts
  std::function<void(const Tile&)> on_tile;  // test hook, called once per rendered tile
  // Adaptive sampling: the pixels the current pass samples, decided before it from the film, and
  // their count (for the progress line).
  ActivePixels active;
  std::atomic<uint64_t> active_pixels{0};
  bool cancelled() const { return is_cancelled(cancel); }
};

// What one tile's render traced: its rays, the pixels it reached (all of them unless cancelled)
// and, with settings.count_traversal on an accelerator that counts, what its queries visited.
struct TileResult {
  RayCounts rays;
  uint64_t pixels = 0;
  QueryCounts traversal;
};
// ctx.samples of the pixels of `tile` into ctx's films: the accelerator's variant dispatched once
// for the tile, which is walked in pieces with `cancel` checked between them. What render_image
// does for each tile, and tracer-mpi's ranks for each tile they are handed.
TileResult render_tile_of(const Accelerator& accel, const PassContext& ctx, const Tile& tile,
                          CancelFlag cancel = nullptr);

// Renders ctx.samples of every pixel into ctx.framebuffer with `accel`. Returns false if
// cancelled before finishing (tiles not reached are left untouched).
bool render_image(const Accelerator& accel, const PassContext& ctx, const SchedOptions& options,
                  RenderMonitor& control);

// The passes of a render: settings.spp samples per pixel (ao and whitted: 1 by default) in
// passes that double (1, 1, 2, 4, ... at most kMaxPassSamples), so a checkpoint or a stop finds
// a complete image early and later passes keep the tile overhead small. With adaptive sampling
// passes are the samples between two decisions of which pixels go on: kAdaptivePassSamples, or
// an eighth of those taken so far once that is more, up to kMaxPassSamples.
inline constexpr uint32_t kMaxPassSamples = 64;
inline constexpr uint32_t kAdaptivePassSamples = 8;
std::vector<SampleRange> sample_passes(const RenderSettings& settings);

// Adaptive sampling's target for these settings: threshold 0 (off) but for path tracing.
NoiseTarget noise_target(const RenderSettings& settings);
inline bool adaptive(const RenderSettings& settings) { return noise_target(settings).threshold > 0.0f; }

// Before a pass of ctx.samples with adaptive sampling: decides from ctx.framebuffer (kept with
// halves) which pixels the pass samples, into `control`, and points ctx.active at them. Does
// nothing without adaptive sampling or before the minimum samples.
void choose_active_pixels(PassContext& ctx, RenderMonitor& control);

// The passes of `round` (some of sample_passes(), in order) of every pixel into ctx.framebuffer,
// each by render_image(): what tracer render does with each round of the render driver. Returns
// false if cancelled (the framebuffer then holds the finished passes plus whatever tiles of the
// stopped one completed).
bool render_round(const Accelerator& accel, PassContext ctx, const std::vector<SampleRange>& round,
                  const SchedOptions& options, RenderMonitor& control);

}  // namespace tracer
