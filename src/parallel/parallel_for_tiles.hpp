// Parallel loops over the tiles of an image, in the five ways the study compares (the executor's
// strategies), knowing nothing of rays or colours (pbrt-v4's ParallelFor2D is the model). The render
// loop, the tests and any distributed driver hand their per-tile work to parallel_for_tiles().
#pragma once

#include <functional>

#include "base/errors.hpp"
#include "parallel/executor.hpp"
#include "parallel/thread_count.hpp"
#include "parallel/tiles.hpp"

namespace tracer {

// The tile schedulers are the executor's strategies: seq and async hand out image rows, queue
// row blocks of `block` pixels, atomic and tbb `tile`-edged squares.

struct SchedOptions {
  Strategy strategy = Strategy::Tbb;
  int threads = 0;  // 0: every hardware thread the process may use
  int tile = 16;    // square tile edge for atomic and tbb
  int block = 64;   // pixels per row block for queue
};

// The tiles `options.strategy` hands out for a width x height image: rows (seq, async), row blocks of
// `block` pixels (queue) or `tile`-edged squares (atomic, tbb). The one place tiles are made.
std::vector<Tile> tiles_for(int width, int height, const SchedOptions& options);

// Calls fn(tile) once for every tile of tiles_for(width, height, options), concurrently as the
// strategy decides; once `cancel` is set no further tile starts. Returns false if cancelled. fn
// must be safe to call concurrently for different tiles.
bool parallel_for_tiles(int width, int height, const SchedOptions& options, CancelFlag cancel,
                        const std::function<void(const Tile&)>& fn);

// How many threads `options` runs (1 for seq).
inline int thread_count(const SchedOptions& options) {
  return options.strategy == Strategy::Seq ? 1 : resolve_thread_count(options.threads);
}

}  // namespace tracer
