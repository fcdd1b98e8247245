// The size of an image read as input (tracer compare, tests), checked from its header before any
// pixel is decoded: at most what tracer writes (16384 x 16384).
#pragma once

#include <cstdint>
#include <string>

#include "base/errors.hpp"

namespace tracer {

struct ImageSize {
  int width = 0, height = 0;
  bool operator==(const ImageSize&) const = default;
};

inline constexpr long long kMaxImageSide = 16384;

// Throws InputError("PATH: W x H pixels ...") for an empty image or one larger than tracer writes.
inline void check_image_size(const std::string& path, long long w, long long h) {
  if (w < 1 || h < 1 || w > kMaxImageSide || h > kMaxImageSide) {
    throw InputError(path + ": " + std::to_string(w) + " x " + std::to_string(h) +
                     " pixels, outside the 1 to 16384 a side tracer reads");
  }
}

}  // namespace tracer
