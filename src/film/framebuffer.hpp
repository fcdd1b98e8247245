// Linear-radiance framebuffer: per pixel the sum of the samples taken so far and their count, so
// passes add up (progressive renders, ranks of an MPI job) and any prefix of them is an image.
// A pass adds each pixel's sum of its samples (summed in sample order from zero), and passes are
// added in order: the floats depend on the pass schedule only, not on who rendered which tile.
#pragma once

#include <cstdint>
#include <vector>

#include "math/vec.hpp"
#include "parallel/tiles.hpp"

namespace tracer {

class Framebuffer {
 public:
  Framebuffer(int width, int height)
      : width_(width), height_(height), sum_(size_t(width) * size_t(height)), samples_(sum_.size(), 0u) {}
  // A framebuffer for one window of a larger image (a tile a rank renders for another): pixels
  // keep the image's coordinates, x in [window.x0, window.x1).
  explicit Framebuffer(const Tile& window) : Framebuffer(window.x1 - window.x0, window.y1 - window.y0) {
    x0_ = window.x0;
    y0_ = window.y0;
  }
  int width() const { return width_; }
  int height() const { return height_; }
  size_t pixel_count() const { return sum_.size(); }

  // Adds to pixel (x, y) the sum of `count` samples (one sample by default).
  void add(int x, int y, Vec3 sum, uint32_t count = 1) {
    const size_t i = index(x, y);
    sum_[i] += sum;
    samples_[i] += count;
  }
  // The same, with the sum of those of the samples in one half of the sample sequence
  // (in_half() of film/convergence.hpp): kept only after keep_halves(), for adaptive sampling's
  // noise estimate.
  void add(int x, int y, Vec3 sum, Vec3 half_sum, uint32_t count) {
    const size_t i = index(x, y);
    sum_[i] += sum;
    samples_[i] += count;
    if (!half_.empty()) half_[i] += half_sum;
  }
  // From now on also sums each pixel's samples of one half apart (zero so far).
  void keep_halves() { half_.assign(sum_.size(), Vec3{0.0f}); }
  bool has_halves() const { return !half_.empty(); }
  Vec3 sum(int x, int y) const { return sum_[index(x, y)]; }
  Vec3 half_sum(int x, int y) const { return half_.empty() ? Vec3{0.0f} : half_[index(x, y)]; }
  uint32_t samples(int x, int y) const { return samples_[index(x, y)]; }
  // Makes (x, y) hold exactly `value`, as one sample (an image read back, a test's pattern).
  void set(int x, int y, Vec3 value) {
    const size_t i = index(x, y);
    sum_[i] = value;
    samples_[i] = 1;
  }
  // The pixel's estimate: the mean of its samples, black before the first.
  Vec3 radiance(int x, int y) const {
    const size_t i = index(x, y);
    return samples_[i] == 0 ? Vec3{0.0f} : sum_[i] / float(samples_[i]);
  }
  // Fewest samples of any pixel: 0 while some pixel has none.
  uint32_t min_samples() const;
  // Most samples of any pixel: 0 while no pixel has one.
  uint32_t max_samples() const;
  // Makes the pixels of `tile` (in this image's coordinates) hold what `from`'s hold: a copy of a
  // render in progress, taken tile by tile as tiles finish (the viewer's display image).
  void copy_tile(const Framebuffer& from, const Tile& tile) {
    for (int y = tile.y0; y < tile.y1; ++y) {
      for (int x = tile.x0; x < tile.x1; ++x) {
        sum_[index(x, y)] = from.sum_[from.index(x, y)];
        samples_[index(x, y)] = from.samples_[from.index(x, y)];
        if (!half_.empty()) half_[index(x, y)] = from.half_sum(x, y);
      }
    }
  }
  // Raw sums by pixel index (row-major), for sending a window's pixels to another rank.
  const Vec3* sums() const { return sum_.data(); }
  const Vec3* half_sums() const { return half_.data(); }  // only with has_halves()

 private:
  size_t index(int x, int y) const { return size_t(y - y0_) * size_t(width_) + size_t(x - x0_); }
  int width_, height_;
  int x0_ = 0, y0_ = 0;
  std::vector<Vec3> sum_;
  std::vector<uint32_t> samples_;
  std::vector<Vec3> half_;  // empty unless keep_halves()
};

}  // namespace tracer
