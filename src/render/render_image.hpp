// Rendering a whole image: the workload of shading.hpp over every tile, handed out by one of the
// parallel_for_tiles() strategies. Every strategy renders disjoint tiles with the same per-pixel
// work, so the image is the same from each.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>

#include "accel/accelerator.hpp"
#include "base/errors.hpp"
#include "parallel/parallel_for_tiles.hpp"
#include "render/render_tile.hpp"

namespace tracer {

// Shared between the render, the caller (progress, cancellation) and tests.
struct RenderControl {
  CancelFlag cancel = nullptr;  // set (e.g. by SIGINT) to stop at the next tile
  std::atomic<uint64_t> pixels_done{0};
  std::atomic<uint64_t> rays_done{0};
  AtomicRayCounts counts;
  std::function<void(const Tile&)> on_tile;  // test hook, called once per rendered tile
  bool cancelled() const { return is_cancelled(cancel); }
};

// Renders ctx.framebuffer with `accel`. Returns false if cancelled before finishing (tiles not
// reached are left untouched).
bool render_image(const Accelerator& accel, const RenderContext& ctx, const SchedOptions& options,
                  RenderControl& control);

}  // namespace tracer
