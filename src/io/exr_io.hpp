// OpenEXR output: the framebuffer's linear radiance, no tone mapping, as half or float RGB.
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "base/enum_names.hpp"
#include "film/framebuffer.hpp"
#include "io/image_size.hpp"

namespace tracer {

enum class ExrPixel { Half, Float };
inline constexpr EnumName<ExrPixel> kExrPixelNames[] = {{ExrPixel::Half, "half"}, {ExrPixel::Float, "float"}};

// A further layer of an EXR beside the radiance (an AOV for a denoiser): channels NAME.C for the
// three channel names given.
struct ExrLayer {
  std::string name;
  const Framebuffer* image = nullptr;
  // The channels of the image's x, y, z; a null name leaves that one out (read back as 0).
  std::array<const char*, 3> channels{"R", "G", "B"};
};

// The bytes of an EXR file holding `fb` (channels R, G, B, ZIP compression) and `layers`, all
// of `pixel` type; throws InputError. Values beyond the pixel type's range, or not finite, are
// written as its largest finite value (NaN as 0); `*clamped` (if given) counts them.
std::string encode_exr(const Framebuffer& fb, ExrPixel pixel, const std::vector<ExrLayer>& layers = {},
                       size_t* clamped = nullptr);

// An EXR's size from its header alone (refused past kMaxImagePixels); throws InputError.
ImageSize exr_size(std::string_view bytes, const std::string& path);

// An EXR's R, G, B channels as floats (tests, image comparison), or those of a layer (NAME.R ...
// as encode_exr writes them). Throws InputError: unreadable, too large (kMaxImagePixels), or
// truncated, refused before the pixels are allocated.
Framebuffer decode_exr(std::string_view bytes, const std::string& path, const ExrLayer& layer = {});
// read_exr: the same from a file, which stays writable by this run (read_back()).
Framebuffer read_exr(const std::string& path, const ExrLayer& layer = {});

}  // namespace tracer
