// Linear-radiance framebuffer and the conversion to display-ready 8-bit sRGB.
#pragma once

#include <cstdint>
#include <vector>

#include "math/vec.hpp"

namespace tracer {

class Framebuffer {
 public:
  Framebuffer(int width, int height) : width_(width), height_(height), pixels_(size_t(width) * size_t(height)) {}
  int width() const { return width_; }
  int height() const { return height_; }
  Vec3& at(int x, int y) { return pixels_[size_t(y) * size_t(width_) + size_t(x)]; }
  const Vec3& at(int x, int y) const { return pixels_[size_t(y) * size_t(width_) + size_t(x)]; }

 private:
  int width_, height_;
  std::vector<Vec3> pixels_;
};

// 8-bit RGB, rows top to bottom.
struct Image8 {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
};

// Exponential tone map 1 - exp(-exposure * L), then the sRGB transfer curve, rounded to 8 bits.
Image8 tonemap(const Framebuffer& fb, float exposure);

}  // namespace tracer
