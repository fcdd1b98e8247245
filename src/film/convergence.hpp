// Adaptive sampling's stopping rule: which pixels still need samples, decided from the film alone.
//
// A pixel's noise is estimated as Dammertz et al. ("A hierarchical automatic stopping condition
// for Monte Carlo global illumination", 2010, section 2.1) and Cycles estimate it: from the
// distance between the mean of all its samples, I, and the mean of one half of them, A. As
// I - A = (B - A) / 2 with B the other half's mean, it is distributed as the error of I itself.
// Unlike Cycles (linear radiance, divided by the square root of the brightness), e is measured
// in the values the image is shown in -- tone-mapped with the exposure and sRGB-encoded, in
// [0, 1], as display_value() -- and averaged over the three channels:
//     e = (|d(I.r) - d(A.r)| + |d(I.g) - d(A.g)| + |d(I.b) - d(A.b)|) / 3,
// so the threshold reads as the error a viewer sees in a pixel, the measure the benchmarks' RMSE
// takes, and a lamp that the tone map saturates stops as soon as it is white (docs/BENCHMARKS.md
// has the measurements behind the choice).
//
// The half is one sample of each pair 2m, 2m+1, chosen by a hash of m: not the even-numbered
// samples, which of a Sobol sequence all lie in one half of the pixel (the radical inverse's top
// bit is the index's lowest), so I - A would measure the pixel's gradient, not its noise; nor
// Christensen et al.'s split by the parity of the index's odd bits ("Progressive Multi-Jittered
// Sample Sequences", 2018, 10.2.1), which tracer's per-set index shuffle turns into a split along
// a diagonal of the pixel (tests/test_adaptive.cpp).
//
// One pixel's e is a single draw of a noisy difference, so a pixel stops only with its block: the
// 4x4 pixels of an aligned grid over the image stop together, once every one of them has at
// least the minimum samples and e below the threshold. The decision reads the film between
// passes, never the clock or the tiling, so every scheduler, thread count and rank stops the same
// pixels.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <vector>

#include "film/framebuffer.hpp"
#include "math/rng.hpp"
#include "parallel/tiles.hpp"

namespace tracer {

// Made from the render's settings by noise_target() (render/render_image.hpp), which holds the
// defaults; the film only applies it.
struct NoiseTarget {
  float threshold = 0.0f;    // e at which a block stops; 0: adaptive sampling off
  uint32_t min_samples = 2;  // no pixel stops before it has this many (e needs two)
  float exposure = 1.0f;     // e is measured on radiance times this
};

// Whether sample `k` of a pixel belongs to the half A is the mean of: one of each pair 2m, 2m+1,
// which one by a hash of m.
constexpr bool in_half(uint32_t k) { return ((pcg_hash(k >> 1) ^ k) & 1u) != 0; }
// How many of samples 0 .. n-1 do.
constexpr uint32_t half_count(uint32_t n) { return n / 2 + ((n & 1u) && in_half(n - 1) ? 1u : 0u); }

// The noise estimate e of pixel (x, y) of a film kept with halves; 0 before two samples.
float pixel_noise(const Framebuffer& fb, int x, int y, float exposure);

class ActivePixels {
 public:
  static constexpr int kBlock = 4;  // edge of the blocks that stop together
  // Every pixel active: the state before the first decision.
  ActivePixels() = default;
  // Decides from `fb` (kept with halves) which blocks go on: those with a pixel short of
  // target.min_samples or at or above target.threshold. `taken`: the samples every pixel still
  // going on has at this pass boundary; a block with fewer stopped at an earlier one and stays
  // stopped without being measured again (its film has not changed since), so the cost of a
  // decision falls with the pixels left.
  void update(const Framebuffer& fb, const NoiseTarget& target, uint32_t taken);
  bool active(int x, int y) const {
    return blocks_.empty() || blocks_[size_t(y / kBlock) * size_t(columns_) + size_t(x / kBlock)] != 0;
  }
  // Pixels still active after the last update().
  uint64_t active_pixels() const { return active_pixels_; }
  // The blocks a tile of the image touches, one byte each (1: active), row-major: what another
  // rank needs to render the tile. window_blocks() gives them, set_window_blocks() takes them
  // into a mask of a `width` x `height` image (all active but for the windows set).
  static size_t window_block_count(const Tile& tile);
  std::vector<uint8_t> window_blocks(const Tile& tile) const;
  void set_window_blocks(int width, int height, const Tile& tile, const uint8_t* blocks);

 private:
  void count_active(int width, int height);
  // Calls f(block index) for each block tile touches, row-major.
  template <class F>
  void for_window(const Tile& tile, F&& f) const {
    for (int by = tile.y0 / kBlock; by <= (tile.y1 - 1) / kBlock; ++by)
      for (int bx = tile.x0 / kBlock; bx <= (tile.x1 - 1) / kBlock; ++bx) f(size_t(by) * size_t(columns_) + size_t(bx));
  }
  int width_ = 0, height_ = 0;
  int columns_ = 0;
  std::vector<uint8_t> blocks_;  // empty: all active
  uint64_t active_pixels_ = 0;
};

}  // namespace tracer
