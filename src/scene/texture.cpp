#include "scene/texture.hpp"

#include <stb_image.h>
#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <limits>

#include "base/errors.hpp"
#include "base/read_input.hpp"
#include "math/srgb.hpp"

namespace tracer {

namespace fs = std::filesystem;

namespace {

// The sRGB transfer curve inverted, for each 8-bit code; a namespace-scope table, so a lookup
// has no function-local-static guard to check.
const std::array<float, 256> kSrgbToLinear = [] {
  std::array<float, 256> t{};
  for (int i = 0; i < 256; ++i) {
    const float c = float(i) / 255.0f;
    t[size_t(i)] = srgb_to_linear(c);
  }
  return t;
}();

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Linear [0, 1] back to an sRGB byte, through a 4096-entry table (building a mip pyramid calls
// it for a third of the texels again: std::pow each time cost tens of milliseconds a texture).
const std::array<uint8_t, 4097> kLinearToSrgb = [] {
  std::array<uint8_t, 4097> t{};
  for (size_t i = 0; i < t.size(); ++i) {
    const double c = double(i) / 4096.0;
    const double s = linear_to_srgb(c);
    t[i] = uint8_t(std::lround(std::clamp(s, 0.0, 1.0) * 255.0));
  }
  return t;
}();

}  // namespace

Texture::Texture(int width, int height, std::vector<uint8_t> srgb)
    : width_(width), height_(height), srgb_(std::move(srgb)) {
  // The pyramid: each level the linear mean of 2 x 2 texels of the one below (the last row or
  // column of an odd size counted twice), until 1 x 1.
  int w = width_, h = height_;
  const std::vector<uint8_t>* below = &srgb_;
  while (w > 1 || h > 1) {
    const int nw = std::max(1, w / 2), nh = std::max(1, h / 2);
    Level level{nw, nh, std::vector<uint8_t>(size_t(nw) * size_t(nh) * 3)};
    for (int y = 0; y < nh; ++y) {
      for (int x = 0; x < nw; ++x) {
        const int xs[2] = {std::min(2 * x, w - 1), std::min(2 * x + 1, w - 1)};
        const int ys[2] = {std::min(2 * y, h - 1), std::min(2 * y + 1, h - 1)};
        for (int c = 0; c < 3; ++c) {
          float sum = 0.0f;
          for (int j : ys)
            for (int i : xs) sum += kSrgbToLinear[(*below)[(size_t(j) * size_t(w) + size_t(i)) * 3 + size_t(c)]];
          level.srgb[(size_t(y) * size_t(nw) + size_t(x)) * 3 + size_t(c)] =
              kLinearToSrgb[size_t(std::lround(std::min(sum * 0.25f, 1.0f) * 4096.0f))];
        }
      }
    }
    mips_.push_back(std::move(level));
    below = &mips_.back().srgb;
    w = nw;
    h = nh;
  }
}

Vec3 Texture::texel(int x, int y) const {
  const auto& lut = kSrgbToLinear;
  const uint8_t* p = &srgb_[(size_t(y) * size_t(width_) + size_t(x)) * 3];
  return {lut[p[0]], lut[p[1]], lut[p[2]]};
}

namespace {

// The four texels around (u, v) and their weights: texel centres sit at half-integers; v runs up
// the image, rows run down. `nearest`: one texel, the four indices equal and no blend.
struct Footprint {
  int x0, x1, y0, y1;
  float ax, ay;
};

// A coordinate along an axis in [0, 1) of the image's width (u) or its rows from the top (t),
// reduced as the wrap mode reads it: [0, 1) for repeat, [0, 2) for a mirrored repeat (the second
// half read backwards by wrap_index), as given for clamp. Non-finite coordinates read 0.
float reduce(float x, Wrap w) {
  if (!std::isfinite(x)) return 0.0f;
  switch (w) {
    case Wrap::Repeat:
      return x - std::floor(x);
    case Wrap::MirroredRepeat:
      return x - 2.0f * std::floor(0.5f * x);
    case Wrap::ClampToEdge:
      break;
  }
  return std::clamp(x, -1.0f, 2.0f);  // beyond, every index clamps to the same edge
}

// Texel index i of an axis of n texels as the wrap mode reads it: i lies within a texel or two
// of what reduce() bounds it to.
int wrap_index(int i, int n, Wrap w) {
  switch (w) {
    case Wrap::Repeat:
      return i < 0 ? i + n : (i >= n ? i - n : i);
    case Wrap::MirroredRepeat:
      i = i < 0 ? i + 2 * n : (i >= 2 * n ? i - 2 * n : i);
      return i >= n ? 2 * n - 1 - i : i;
    case Wrap::ClampToEdge:
      break;
  }
  return std::clamp(i, 0, n - 1);
}

Footprint footprint(float u, float v, int width, int height, const Sampler& s) {
  // Rows run down from v = 1. Repeat reduces v itself (the images before samplers, bit for bit).
  const float t = s.wrap_t == Wrap::Repeat ? 1.0f - reduce(v, Wrap::Repeat) : reduce(1.0f - v, s.wrap_t);
  const float fx = reduce(u, s.wrap_s) * float(width), fy = t * float(height);
  if (s.nearest) {
    const int x = wrap_index(int(std::floor(fx)), width, s.wrap_s),
              y = wrap_index(int(std::floor(fy)), height, s.wrap_t);
    return {x, x, y, y, 0.0f, 0.0f};
  }
  const float x0f = std::floor(fx - 0.5f), y0f = std::floor(fy - 0.5f);
  return {wrap_index(int(x0f), width, s.wrap_s),
          wrap_index(int(x0f) + 1, width, s.wrap_s),
          wrap_index(int(y0f), height, s.wrap_t),
          wrap_index(int(y0f) + 1, height, s.wrap_t),
          fx - 0.5f - x0f,
          fy - 0.5f - y0f};
}

// The bilinear blend of what `at(x, y)` gives at the footprint's four texels.
template <class At>
auto blend(const Footprint& f, const At& at) {
  return (at(f.x0, f.y0) * (1.0f - f.ax) + at(f.x1, f.y0) * f.ax) * (1.0f - f.ay) +
         (at(f.x0, f.y1) * (1.0f - f.ax) + at(f.x1, f.y1) * f.ax) * f.ay;
}

}  // namespace

float Texture::height(float u, float v, const Sampler& s) const {
  if (width_ == 0 || height_ == 0) return 0.0f;
  const Footprint f = footprint(u, v, width_, height_, s);
  return blend(f, [&](int x, int y) {
    const uint8_t* p = &srgb_[3 * (size_t(y) * size_t(width_) + size_t(x))];
    return float(int(p[0]) + int(p[1]) + int(p[2])) * (1.0f / 765.0f);
  });
}

Texture Texture::tinted(Vec3 factor) const {
  std::vector<uint8_t> out(srgb_.size());
  const float f[3] = {factor.x, factor.y, factor.z};
  for (size_t i = 0; i < out.size(); ++i) {
    const float linear = std::clamp(kSrgbToLinear[srgb_[i]] * f[i % 3], 0.0f, 1.0f);
    out[i] = kLinearToSrgb[size_t(std::lround(linear * 4096.0f))];
  }
  return Texture(width_, height_, std::move(out));
}

Vec3 Texture::data(float u, float v, const Sampler& s) const {
  if (width_ == 0 || height_ == 0) return Vec3{0.0f};
  const Footprint f = footprint(u, v, width_, height_, s);
  return blend(f, [&](int x, int y) {
    const uint8_t* p = &srgb_[3 * (size_t(y) * size_t(width_) + size_t(x))];
    return Vec3{float(p[0]), float(p[1]), float(p[2])} * (1.0f / 255.0f);
  });
}

Vec3 Texture::bilinear_at(const Level& level, float u, float v, const Sampler& s) const {
  const Footprint f = footprint(u, v, level.width, level.height, s);
  const auto& lut = kSrgbToLinear;
  return blend(f, [&](int x, int y) {
    const uint8_t* p = &level.srgb[(size_t(y) * size_t(level.width) + size_t(x)) * 3];
    return Vec3{lut[p[0]], lut[p[1]], lut[p[2]]};
  });
}

Vec3 Texture::filtered(float u, float v, float lod, const Sampler& s) const {
  if (!(lod > 0.0f) || mips_.empty() || !s.mipmaps) return bilinear(u, v, s);
  // Minified: the levels blend linearly (a nearest magnification filter does not apply).
  Sampler linear = s;
  linear.nearest = false;
  const float top = float(mips_.size());
  if (lod >= top) return bilinear_at(mips_.back(), u, v, linear);
  const int l = int(lod);
  const float a = lod - float(l);
  const Vec3 lo = l == 0 ? bilinear(u, v, linear) : bilinear_at(mips_[size_t(l) - 1], u, v, linear);
  const Vec3 hi = bilinear_at(mips_[size_t(l)], u, v, linear);
  return lo * (1.0f - a) + hi * a;
}

Vec3 Texture::bilinear(float u, float v, const Sampler& s) const {
  if (width_ == 0 || height_ == 0) return Vec3{0.0f};
  return blend(footprint(u, v, width_, height_, s), [&](int x, int y) { return texel(x, y); });
}

namespace {

// stb_image's reason for a failure; it gives none for some files that end early (a PNG of only
// its IHDR chunk).
std::string stb_reason() {
  const char* why = stbi_failure_reason();
  return why && *why ? why : "corrupt or truncated (no image data)";
}

}  // namespace

EncodedTexture read_texture(const fs::path& path, const TextureLimits& limits, CancelFlag cancel) {
  const std::string name = path.string();
  struct stat st {};
  if (::stat(name.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
    throw InputError(name + ": not a regular file" + (S_ISFIFO(st.st_mode) ? " (a FIFO)" : ""));
  }
  // The encoded file is far smaller than its texels; a file this large is no texture.
  std::string bytes = read_input(name, cancel, limits.max_texels * 3 + (uint64_t(64) << 20));
  return encoded_texture(name, std::move(bytes), limits);
}

EncodedTexture encoded_texture(std::string name, std::string bytes, const TextureLimits& limits) {
  EncodedTexture t;
  t.name = std::move(name);
  t.bytes = std::move(bytes);
  if (t.bytes.size() > size_t(std::numeric_limits<int>::max())) throw InputError(t.name + ": too large to decode");
  int channels = 0;
  if (!stbi_info_from_memory(reinterpret_cast<const stbi_uc*>(t.bytes.data()), int(t.bytes.size()), &t.width, &t.height,
                             &channels)) {
    throw InputError(t.name + ": cannot read texture: " + stb_reason());
  }
  t.bytes_per_value =
      stbi_is_16_bit_from_memory(reinterpret_cast<const stbi_uc*>(t.bytes.data()), int(t.bytes.size())) ? 2 : 1;
  t.channels = std::clamp(channels, 1, 4);
  if (uint64_t(t.width) * uint64_t(t.height) > limits.max_texels) {
    throw InputError(t.name + ": " + std::to_string(t.width) + "x" + std::to_string(t.height) +
                     " texels, more than the " + std::to_string(limits.max_texels) + " a texture may have");
  }
  return t;
}

Texture decode_texture(const EncodedTexture& t) {
  int w = 0, h = 0, channels = 0;
  unsigned char* texels = stbi_load_from_memory(reinterpret_cast<const stbi_uc*>(t.bytes.data()), int(t.bytes.size()),
                                                &w, &h, &channels, 3);
  if (!texels) throw InputError(t.name + ": cannot read texture: " + stb_reason());
  std::vector<uint8_t> srgb(texels, texels + size_t(w) * size_t(h) * 3);
  stbi_image_free(texels);
  return Texture(w, h, std::move(srgb));
}

Texture load_texture(const fs::path& path, const TextureLimits& limits, CancelFlag cancel) {
  return decode_texture(read_texture(path, limits, cancel));
}

std::optional<fs::path> FileFinder::find(const fs::path& dir, const std::string& name) {
  std::error_code ec;
  std::string normalised = name;
  std::replace(normalised.begin(), normalised.end(), '\\', '/');  // MTL files written on Windows
  const fs::path relative(normalised);
  if (fs::exists(fs::symlink_status(dir / relative, ec))) return dir / relative;
  fs::path at = dir.empty() ? fs::path(".") : dir;
  for (const fs::path& part : relative) {
    if (part == ".") continue;
    if (part == "..") {
      at /= part;
      continue;
    }
    auto [listing, fresh] = listings_.try_emplace(at);
    if (fresh) {
      for (fs::directory_iterator it(at, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string key = lower(it->path().filename().string());
        const auto [entry, inserted] = listing->second.try_emplace(key, it->path());
        if (!inserted && it->path() < entry->second) entry->second = it->path();  // first in byte order
      }
    }
    const auto match = listing->second.find(lower(part.string()));
    if (match == listing->second.end()) return std::nullopt;
    at = match->second;
  }
  return fs::exists(fs::symlink_status(at, ec)) && !fs::is_directory(at, ec) ? std::optional<fs::path>(at)
                                                                             : std::nullopt;
}

std::optional<fs::path> find_file_any_case(const fs::path& dir, const std::string& name) {
  return FileFinder().find(dir, name);
}

}  // namespace tracer
