#include "film/tone_map.hpp"

#include <algorithm>
#include <cmath>

#include "math/srgb.hpp"

namespace tracer {

namespace {

uint8_t encode(float linear, float exposure) {
  return static_cast<uint8_t>(std::clamp(std::lround(display_value(linear, exposure) * 255.0f), 0L, 255L));
}

}  // namespace

float display_value(float linear, float exposure) {
  if (!(linear > 0.0f)) return 0.0f;  // also maps NaN to black
  const float mapped = 1.0f - std::exp(-exposure * linear);
  return linear_to_srgb(mapped);
}

Image8 tonemap(const Framebuffer& fb, float exposure) {
  Image8 img;
  img.width = fb.width();
  img.height = fb.height();
  img.rgb.resize(size_t(img.width) * size_t(img.height) * 3);
  size_t k = 0;
  for (int y = 0; y < fb.height(); ++y) {
    for (int x = 0; x < fb.width(); ++x) {
      const Vec3 c = fb.radiance(x, y);
      img.rgb[k++] = encode(c.x, exposure);
      img.rgb[k++] = encode(c.y, exposure);
      img.rgb[k++] = encode(c.z, exposure);
    }
  }
  return img;
}

void tonemap_tile(const Framebuffer& fb, float exposure, const Tile& tile, Image8& image) {
  for (int y = tile.y0; y < tile.y1; ++y) {
    size_t k = (size_t(y) * size_t(image.width) + size_t(tile.x0)) * 3;
    for (int x = tile.x0; x < tile.x1; ++x) {
      const Vec3 c = fb.radiance(x, y);
      image.rgb[k++] = encode(c.x, exposure);
      image.rgb[k++] = encode(c.y, exposure);
      image.rgb[k++] = encode(c.z, exposure);
    }
  }
}

bool looks_black(const Framebuffer& fb, float exposure) {
  for (int y = 0; y < fb.height(); ++y) {
    for (int x = 0; x < fb.width(); ++x) {
      const Vec3 c = fb.radiance(x, y);
      if (encode(c.x, exposure) != 0 || encode(c.y, exposure) != 0 || encode(c.z, exposure) != 0) return false;
    }
  }
  return true;
}

}  // namespace tracer
