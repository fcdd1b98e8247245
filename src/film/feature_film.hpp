// What a feature-guided denoiser needs of each pixel (denoise/nfor.hpp): for each half of the
// pixel's samples (film/convergence.hpp's in_half(): A, the other B) the sums of the radiance and
// of its square (each half's sample variance), and of the features of the path's first
// non-specular vertex -- albedo, shading normal and the distance the path travelled to it -- with
// the half's sample count. Summed as the radiance film is (each pass adds each pixel's sums, in
// order), so it is the same whoever rendered which tile.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "math/vec.hpp"
#include "parallel/tiles.hpp"

namespace tracer {

// One sample's contribution: its radiance and the features of the vertex it was guided by.
struct FeatureSample {
  Vec3 radiance{0.0f};
  Vec3 albedo{0.0f};
  Vec3 normal{0.0f};
  float depth = 0.0f;
};

class FeatureFilm {
 public:
  // Channels of one half, in this order.
  enum Channel : int {
    kRadiance = 0,   // 3: sum of radiance
    kRadiance2 = 3,  // 3: sum of radiance squared
    kAlbedo = 6,     // 3
    kNormal = 9,     // 3
    kDepth = 12,     // 1
    kCount = 13,     // 1: samples in this half
    kHalfChannels = 14
  };
  static constexpr int kPixelFloats = 2 * kHalfChannels;

  // A pixel's two halves, summed sample by sample before being added to the film.
  struct PixelSums {
    std::array<float, kPixelFloats> v{};
    void add(const FeatureSample& s, bool half_a) {
      float* h = v.data() + (half_a ? 0 : kHalfChannels);
      for (int c = 0; c < 3; ++c) {
        h[kRadiance + c] += s.radiance[c];
        h[kRadiance2 + c] += s.radiance[c] * s.radiance[c];
        h[kAlbedo + c] += s.albedo[c];
        h[kNormal + c] += s.normal[c];
      }
      h[kDepth] += s.depth;
      h[kCount] += 1.0f;
    }
  };

  FeatureFilm(int width, int height)
      : width_(width), height_(height), v_(size_t(width) * size_t(height) * kPixelFloats) {}
  // A film for one window of a larger image (a tile a rank renders for another), in the image's
  // coordinates.
  explicit FeatureFilm(const Tile& window) : FeatureFilm(window.x1 - window.x0, window.y1 - window.y0) {
    x0_ = window.x0;
    y0_ = window.y0;
  }
  int width() const { return width_; }
  int height() const { return height_; }

  void add(int x, int y, const PixelSums& sums) {
    float* p = pixel(x, y);
    for (int i = 0; i < kPixelFloats; ++i) p[i] += sums.v[size_t(i)];
  }
  // Channel `c` of half `h` (0: A, 1: B) of pixel (x, y).
  float get(int x, int y, int h, int c) const { return v_[offset(x, y) + size_t(h * kHalfChannels + c)]; }
  // The variance of the pixel's mean radiance, from all its samples (0 below two).
  Vec3 variance_of_mean(int x, int y) const {
    const float n = get(x, y, 0, kCount) + get(x, y, 1, kCount);
    Vec3 v{0.0f};
    if (n < 2.0f) return v;
    for (int c = 0; c < 3; ++c) {
      const float s = get(x, y, 0, kRadiance + c) + get(x, y, 1, kRadiance + c);
      const float s2 = get(x, y, 0, kRadiance2 + c) + get(x, y, 1, kRadiance2 + c);
      v[c] = std::max(0.0f, (s2 - s * s / n) / (n * (n - 1.0f)));
    }
    return v;
  }
  // Adds to the pixels of `tile` what `from`'s hold (a window another rank rendered: its sums
  // of this pass, added as path_tile adds them).
  void add_tile(const FeatureFilm& from, const Tile& tile) {
    for (int y = tile.y0; y < tile.y1; ++y) {
      for (int x = tile.x0; x < tile.x1; ++x) {
        const float* src = from.v_.data() + from.offset(x, y);
        float* dst = pixel(x, y);
        for (int i = 0; i < kPixelFloats; ++i) dst[i] += src[i];
      }
    }
  }
  // Raw floats, kPixelFloats per pixel, row-major: for sending a window to another rank.
  const float* data() const { return v_.data(); }
  float* data() { return v_.data(); }
  size_t float_count() const { return v_.size(); }

 private:
  size_t offset(int x, int y) const {
    return (size_t(y - y0_) * size_t(width_) + size_t(x - x0_)) * size_t(kPixelFloats);
  }
  float* pixel(int x, int y) { return v_.data() + offset(x, y); }
  int width_, height_;
  int x0_ = 0, y0_ = 0;
  std::vector<float> v_;
};

}  // namespace tracer
