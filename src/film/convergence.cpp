#include "film/convergence.hpp"

#include <algorithm>
#include <cmath>

#include "film/tone_map.hpp"

namespace tracer {

float pixel_noise(const Framebuffer& fb, int x, int y, float exposure) {
  const uint32_t n = fb.samples(x, y), half = half_count(n);
  if (n < 2 || half == 0) return 0.0f;
  const Vec3 i = fb.sum(x, y) / float(n);
  const Vec3 a = fb.half_sum(x, y) / float(half);
  float difference = 0.0f;
  for (int c = 0; c < 3; ++c) difference += std::fabs(display_value(i[c], exposure) - display_value(a[c], exposure));
  return difference / 3.0f;
}

void ActivePixels::update(const Framebuffer& fb, const NoiseTarget& target, uint32_t taken) {
  const int w = fb.width(), h = fb.height();
  width_ = w;
  height_ = h;
  columns_ = (w + kBlock - 1) / kBlock;
  const int rows = (h + kBlock - 1) / kBlock;
  blocks_.assign(size_t(columns_) * size_t(rows), 1);
  for (int by = 0; by < rows; ++by) {
    for (int bx = 0; bx < columns_; ++bx) {
      bool done = true;
      if (fb.samples(bx * kBlock, by * kBlock) < taken) {
        blocks_[size_t(by) * size_t(columns_) + size_t(bx)] = 0;
        continue;
      }
      for (int y = by * kBlock; done && y < std::min(h, (by + 1) * kBlock); ++y) {
        for (int x = bx * kBlock; done && x < std::min(w, (bx + 1) * kBlock); ++x) {
          done = fb.samples(x, y) >= target.min_samples && pixel_noise(fb, x, y, target.exposure) < target.threshold;
        }
      }
      blocks_[size_t(by) * size_t(columns_) + size_t(bx)] = done ? 0 : 1;
    }
  }
  count_active(w, h);
}

size_t ActivePixels::window_block_count(const Tile& tile) {
  return size_t((tile.x1 - 1) / kBlock - tile.x0 / kBlock + 1) * size_t((tile.y1 - 1) / kBlock - tile.y0 / kBlock + 1);
}

std::vector<uint8_t> ActivePixels::window_blocks(const Tile& tile) const {
  std::vector<uint8_t> out;
  out.reserve(window_block_count(tile));
  if (blocks_.empty()) {
    out.assign(window_block_count(tile), 1);
  } else {
    for_window(tile, [&](size_t b) { out.push_back(blocks_[b]); });
  }
  return out;
}

void ActivePixels::set_window_blocks(int width, int height, const Tile& tile, const uint8_t* blocks) {
  if (blocks_.empty() || width != width_ || height != height_) {
    width_ = width;
    height_ = height;
    columns_ = (width + kBlock - 1) / kBlock;
    blocks_.assign(size_t(columns_) * size_t((height + kBlock - 1) / kBlock), 1);
  }
  size_t i = 0;
  for_window(tile, [&](size_t b) { blocks_[b] = blocks[i++]; });
}

void ActivePixels::count_active(int width, int height) {
  active_pixels_ = 0;
  const int rows = (height + kBlock - 1) / kBlock;
  for (int by = 0; by < rows; ++by) {
    for (int bx = 0; bx < columns_; ++bx) {
      if (!blocks_[size_t(by) * size_t(columns_) + size_t(bx)]) continue;
      active_pixels_ += uint64_t(std::min(width, (bx + 1) * kBlock) - bx * kBlock) *
                        uint64_t(std::min(height, (by + 1) * kBlock) - by * kBlock);
    }
  }
}

}  // namespace tracer
