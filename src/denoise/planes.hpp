// A stack of float planes of one image with a border around them, so that the denoiser's loops
// read a pixel's neighbours and their patches with plain strided loads, never a bounds check:
// the border reads as zero, and the `valid` plane says which pixels are the image's.
#pragma once

#include <cstddef>
#include <cstdint>

#include "base/huge_pages.hpp"

namespace tracer::denoise {

// The denoiser's tiles: kTileWidth x kTileHeight pixels, a row of a tile a whole number of SIMD
// vectors on every target (4, 8 or 16 floats). Wide, so that the patch margin a row of distances
// needs on either side is a small part of it.
inline constexpr int kTileWidth = 64;
inline constexpr int kTileHeight = 16;
// Widest window and patch radii any filter uses; the border covers them.
inline constexpr int kMaxRadius = 10;
inline constexpr int kMaxPatch = 3;
// Columns a tile's patch distances are computed over: kTileWidth + 2 * kMaxPatch, rounded up to
// a whole number of the widest vectors.
inline constexpr int kPatchColumns = 80;

class Planes {
 public:
  Planes() = default;
  Planes(int width, int height, int channels)
      : width_(width),
        height_(height),
        channels_(channels),
        stride_(ptrdiff_t(round_up(width, kTileWidth) + 2 * kBorder + kPatchColumns)),
        rows_(round_up(height, kTileHeight) + 2 * kBorder),
        size_(size_t(channels) * size_t(stride_) * size_t(rows_)),
        data_(size_, kZeroFilled) {}
  Planes(Planes&&) noexcept = default;
  Planes& operator=(Planes&&) noexcept = default;
  Planes(const Planes&) = delete;  // hundreds of MB: moved, never copied
  Planes& operator=(const Planes&) = delete;

  // The floats one channel of a width x height image holds, its border and padding included: a
  // thin image pads every row to a whole tile and a border (a 1-pixel column holds 170 floats a row).
  static uint64_t floats_per_channel(int width, int height) {
    return uint64_t(round_up(width, kTileWidth) + 2 * kBorder + kPatchColumns) *
           uint64_t(round_up(height, kTileHeight) + 2 * kBorder);
  }

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  ptrdiff_t stride() const { return stride_; }
  // Pixel (x, y) of channel c; x and y may lie up to the border outside the image.
  float* at(int c, int x, int y) { return data_.get() + offset(c, x, y); }
  const float* at(int c, int x, int y) const { return data_.get() + offset(c, x, y); }
  float& operator()(int c, int x, int y) { return *at(c, x, y); }
  float operator()(int c, int x, int y) const { return *at(c, x, y); }

 private:
  static constexpr int kBorder = kMaxRadius + kMaxPatch;
  static int round_up(int n, int m) { return (n + m - 1) / m * m; }
  size_t offset(int c, int x, int y) const {
    return (size_t(c) * size_t(rows_) + size_t(y + kBorder)) * size_t(stride_) + size_t(x + kBorder);
  }
  int width_ = 0, height_ = 0, channels_ = 0;
  ptrdiff_t stride_ = 0;
  int rows_ = 0;
  size_t size_ = 0;
  // Zero-filled by the kernel as its pages are first touched, by the threads that write them: a
  // megapixel's planes are 660 MB, whose zeroing and page faults on the calling thread took a
  // tenth of the denoiser's time.
  LargeBuffer<float> data_;
};

}  // namespace tracer::denoise
