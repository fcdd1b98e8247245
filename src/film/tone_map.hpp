// Tone mapping: a framebuffer's linear radiance to the 8-bit sRGB image PNG and PPM files hold.
#pragma once

#include <cstdint>
#include <vector>

#include "film/framebuffer.hpp"

namespace tracer {

// 8-bit RGB, rows top to bottom.
struct Image8 {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
};

// One channel of linear radiance as displayed, in [0, 1]: the exponential tone map
// 1 - exp(-exposure * L), then the sRGB transfer curve (NaN and negatives: 0).
float display_value(float linear, float exposure);

// display_value() of each channel of each pixel's radiance, rounded to 8 bits.
Image8 tonemap(const Framebuffer& fb, float exposure);

// Tone-maps the pixels of `tile` into `image` (of fb's size), as tonemap() maps them.
void tonemap_tile(const Framebuffer& fb, float exposure, const Tile& tile, Image8& image);

// Whether tonemap(fb, exposure) is black in every pixel: a render a user must be told about.
bool looks_black(const Framebuffer& fb, float exposure);

}  // namespace tracer
