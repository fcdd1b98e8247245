// Image textures (the MTL's maps, glTF's images): 8-bit sRGB texels as stored in the file, decoded
// to linear at lookup through a table, filtered and wrapped as a Sampler says (bilinear and
// repeating by default).
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "base/errors.hpp"
#include "math/vec.hpp"
#include "scene/texture_slot.hpp"

namespace tracer {

class Texture {
 public:
  Texture() = default;
  Texture(int width, int height, std::vector<uint8_t> srgb);  // rows top to bottom, RGB
  int width() const { return width_; }
  int height() const { return height_; }
  // Linear colour at texture coordinates (u, v) as OBJ gives them: v = 0 is the image's bottom
  // row. Bilinear between the four nearest texel centres (the nearest texel where the sampler
  // says so); coordinates wrap as the sampler says.
  Vec3 bilinear(float u, float v, const Sampler& s = {}) const;
  // The same filtered to level of detail `lod` (0: the texels; each level halves the resolution,
  // its texels the mean of 2 x 2 of the level below, averaged in linear light): trilinear, between
  // the two levels around lod; lod <= 0, or a sampler without mip-maps, is bilinear().
  Vec3 filtered(float u, float v, float lod, const Sampler& s = {}) const;
  int levels() const { return 1 + int(mips_.size()); }
  // The linear colour of texel (x, y), rows from the top.
  Vec3 texel(int x, int y) const;
  // A bump map's height in [0, 1] at (u, v): the stored bytes as data (no sRGB decoding), the
  // mean of the channels, filtered and wrapped as bilinear() is.
  float height(float u, float v, const Sampler& s = {}) const;
  // The texture with each texel's linear colour times `factor` (clamped to 1): glTF's
  // baseColorFactor folded into its baseColorTexture.
  Texture tinted(Vec3 factor) const;
  // The stored bytes as data in [0, 1] (a normal map's), filtered and wrapped as bilinear() is.
  Vec3 data(float u, float v, const Sampler& s = {}) const;
  // The texels as stored: 8-bit sRGB, RGB, rows from the top.
  const std::vector<uint8_t>& srgb() const { return srgb_; }

 private:
  struct Level {
    int width, height;
    std::vector<uint8_t> srgb;
  };
  Vec3 bilinear_at(const Level& level, float u, float v, const Sampler& s) const;
  int width_ = 0, height_ = 0;
  std::vector<uint8_t> srgb_;
  std::vector<Level> mips_;  // levels 1, 2, ... down to 1 x 1 (level 0 is srgb_)
};

// What a scene's textures may take: a texture larger than max_texels is refused (a decompression
// bomb: a 5 KB JPEG header can claim 26000 x 26000), and so is any texture past the total.
struct TextureLimits {
  uint64_t max_texels = uint64_t(8192) * 8192;  // 192 MiB as 8-bit RGB
  uint64_t max_total_bytes = uint64_t(2048) << 20;
};

// A texture file read but not decoded: its bytes and the size its header gives.
struct EncodedTexture {
  std::string name;
  std::string bytes;
  int width = 0, height = 0;
  int channels = 3;         // in the file (with alpha, or a palette's 1)
  int bytes_per_value = 1;  // 2 for a 16-bit PNG
  // Its texels and mip levels (a third more) once decoded.
  uint64_t decoded_bytes() const { return uint64_t(width) * uint64_t(height) * 4; }
  // The most memory its decode holds at once, per texel: stb_image's inflated data and image in
  // the file's layout, its conversion to RGB and to 8 bits, tracer's copy and the mip levels.
  uint64_t decode_peak_bytes() const {
    const uint64_t b = uint64_t(bytes_per_value);
    return uint64_t(width) * uint64_t(height) * (uint64_t(channels) * b + 4 * b + 3 * b + 3 + 4);
  }
};

// Reads any image stb_image reads (PNG, JPEG, ...) and its header: throws InputError naming the
// file when it cannot be read, is not a regular file, or is larger than `limits.max_texels`.
// Cancelled when `cancel` is set while reading.
EncodedTexture read_texture(const std::filesystem::path& path, const TextureLimits& limits = {},
                            CancelFlag cancel = nullptr);
// The same for bytes already in memory (an image inside a glTF buffer); `name` names it in errors.
EncodedTexture encoded_texture(std::string name, std::string bytes, const TextureLimits& limits = {});
// Decodes what read_texture() read; throws InputError naming the file.
Texture decode_texture(const EncodedTexture& encoded);
// Both.
Texture load_texture(const std::filesystem::path& path, const TextureLimits& limits = {}, CancelFlag cancel = nullptr);

// The file `name` (relative, as an MTL writes it) under `dir`: the exact path if it exists (of
// any type: reading it says what is wrong with it), or else the one whose every component
// matches ignoring letter case (files written on Windows name "KAMEN.JPG" for kamen.jpg);
// nothing if neither exists. Each directory is listed once, however many names are looked up.
class FileFinder {
 public:
  std::optional<std::filesystem::path> find(const std::filesystem::path& dir, const std::string& name);

 private:
  // Per directory: lower-cased file name to the first such entry in byte order.
  std::map<std::filesystem::path, std::map<std::string, std::filesystem::path>> listings_;
};

// One look-up with a finder of its own.
std::optional<std::filesystem::path> find_file_any_case(const std::filesystem::path& dir, const std::string& name);

}  // namespace tracer
