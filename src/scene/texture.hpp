// Image textures (the MTL's map_Kd): 8-bit sRGB texels as stored in the file, decoded to linear
// at lookup through a table, filtered bilinearly, repeating outside [0, 1).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "math/vec.hpp"

namespace tracer {

class Texture {
 public:
  Texture() = default;
  Texture(int width, int height, std::vector<uint8_t> srgb);  // rows top to bottom, RGB
  int width() const { return width_; }
  int height() const { return height_; }
  // Linear colour at texture coordinates (u, v) as OBJ gives them: v = 0 is the image's bottom
  // row. Bilinear between the four nearest texel centres; coordinates wrap.
  Vec3 bilinear(float u, float v) const;
  // The linear colour of texel (x, y), rows from the top.
  Vec3 texel(int x, int y) const;
  // The texels as stored: 8-bit sRGB, RGB, rows from the top.
  const std::vector<uint8_t>& srgb() const { return srgb_; }

 private:
  int width_ = 0, height_ = 0;
  std::vector<uint8_t> srgb_;
};

// Decodes any image stb_image reads (PNG, JPEG, ...). Throws InputError naming the file.
Texture load_texture(const std::filesystem::path& path);

// The file `name` (relative, as an MTL writes it) under `dir`: the exact path if it exists, or
// else the one whose every component matches ignoring letter case (files written on Windows name
// "KAMEN.JPG" for kamen.jpg); nothing if neither exists.
std::optional<std::filesystem::path> find_file_any_case(const std::filesystem::path& dir, const std::string& name);

}  // namespace tracer
