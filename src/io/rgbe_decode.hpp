// Radiance HDR (.hdr, RGBE) images, decoded as their bytes arrive in scanlines: a truncated file
// is an error, not a zero-filled image; the texels grow with the data actually decoded, never
// with what the header claims; Ctrl-C is seen between scanlines. stb_image decodes the same format
// but zero-fills what is missing, allocates the claimed size first and cannot be interrupted
// (docs/RELIABILITY.md), which is why tracer reads its environment maps with this.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "base/errors.hpp"
#include "math/vec.hpp"

namespace tracer {

struct RgbeImage {
  int width = 0, height = 0;
  std::vector<Vec3> texels;  // rows from the top, linear RGB
};

// Decodes `bytes` (the whole file); `check_size(w, h)` runs once the header is read, before any
// texel. Throws InputError("PATH: ...") for anything but a complete -Y H +X W image of format
// 32-bit_rle_rgbe (flat or run-length scanlines, as the format and stb_image allow).
RgbeImage decode_rgbe(std::string_view bytes, const std::string& path,
                      void (*check_size)(const std::string&, long long, long long), CancelFlag cancel);

}  // namespace tracer
