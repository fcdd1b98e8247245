// OpenEXR output: the framebuffer's linear radiance, no tone mapping, as half or float RGB.
#pragma once

#include <string>

#include "base/enum_names.hpp"
#include "film/framebuffer.hpp"

namespace tracer {

enum class ExrPixel { Half, Float };
inline constexpr EnumName<ExrPixel> kExrPixelNames[] = {{ExrPixel::Half, "half"}, {ExrPixel::Float, "float"}};

// The bytes of an EXR file holding `fb` (channels R, G, B, ZIP compression); throws InputError.
std::string encode_exr(const Framebuffer& fb, ExrPixel pixel);

// Reads an EXR's R, G, B channels as floats (tests, image comparison); throws InputError.
Framebuffer read_exr(const std::string& path);

}  // namespace tracer
