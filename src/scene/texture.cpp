#include "scene/texture.hpp"

#include <stb_image.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>

#include "base/errors.hpp"

namespace tracer {

namespace fs = std::filesystem;

namespace {

// The sRGB transfer curve inverted, for each 8-bit code; a namespace-scope table, so a lookup
// has no function-local-static guard to check.
const std::array<float, 256> kSrgbToLinear = [] {
  std::array<float, 256> t{};
  for (int i = 0; i < 256; ++i) {
    const float c = float(i) / 255.0f;
    t[size_t(i)] = c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
  }
  return t;
}();

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

Texture::Texture(int width, int height, std::vector<uint8_t> srgb)
    : width_(width), height_(height), srgb_(std::move(srgb)) {}

Vec3 Texture::texel(int x, int y) const {
  const auto& lut = kSrgbToLinear;
  const uint8_t* p = &srgb_[(size_t(y) * size_t(width_) + size_t(x)) * 3];
  return {lut[p[0]], lut[p[1]], lut[p[2]]};
}

Vec3 Texture::bilinear(float u, float v) const {
  if (width_ == 0 || height_ == 0) return Vec3{0.0f};
  // Texel centres sit at half-integers; v runs up the image, rows run down.
  const float fx = (u - std::floor(u)) * float(width_) - 0.5f;
  const float fy = (1.0f - (v - std::floor(v))) * float(height_) - 0.5f;
  const float x0f = std::floor(fx), y0f = std::floor(fy);
  const float ax = fx - x0f, ay = fy - y0f;
  // fx lies in [-0.5, width - 0.5), so x0 in [-1, width - 1]: one compare wraps each side.
  const auto wrap = [](int i, int n) { return i < 0 ? i + n : (i >= n ? i - n : i); };
  const int x0 = wrap(int(x0f), width_), x1 = wrap(int(x0f) + 1, width_);
  const int y0 = wrap(int(y0f), height_), y1 = wrap(int(y0f) + 1, height_);
  return (texel(x0, y0) * (1.0f - ax) + texel(x1, y0) * ax) * (1.0f - ay) +
         (texel(x0, y1) * (1.0f - ax) + texel(x1, y1) * ax) * ay;
}

Texture load_texture(const fs::path& path) {
  int w = 0, h = 0, channels = 0;
  unsigned char* data = stbi_load(path.c_str(), &w, &h, &channels, 3);
  if (!data) throw InputError(path.string() + ": cannot read texture: " + stbi_failure_reason());
  std::vector<uint8_t> texels(data, data + size_t(w) * size_t(h) * 3);
  stbi_image_free(data);
  return Texture(w, h, std::move(texels));
}

std::optional<fs::path> find_file_any_case(const fs::path& dir, const std::string& name) {
  std::error_code ec;
  std::string normalised = name;
  std::replace(normalised.begin(), normalised.end(), '\\', '/');  // MTL files written on Windows
  const fs::path relative(normalised);
  if (fs::is_regular_file(dir / relative, ec)) return dir / relative;
  fs::path at = dir.empty() ? fs::path(".") : dir;
  for (const fs::path& part : relative) {
    if (part == ".") continue;
    if (part == "..") {
      at /= part;
      continue;
    }
    const std::string want = lower(part.string());
    std::optional<fs::path> match;  // the first in byte order, if several differ only in case
    for (fs::directory_iterator it(at, ec), end; !ec && it != end; it.increment(ec)) {
      if (lower(it->path().filename().string()) == want && (!match || it->path() < *match)) match = it->path();
    }
    if (!match) return std::nullopt;
    at = *match;
  }
  return fs::is_regular_file(at, ec) ? std::optional<fs::path>(at) : std::nullopt;
}

}  // namespace tracer
