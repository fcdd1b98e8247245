// Reading an environment map: an equirectangular image in linear radiance, OpenEXR (R, G, B) or
// Radiance HDR (.hdr, RGBE), by its extension.
#pragma once

#include <string>

#include "base/errors.hpp"
#include "scene/environment_map.hpp"

namespace tracer {

// The most texels an environment map may have (16384 x 8192): a header claiming more is refused
// before anything is allocated.
inline constexpr uint64_t kMaxEnvironmentTexels = uint64_t(16384) * 8192;

// Throws InputError naming the file: unreadable, not EXR or HDR, too large, truncated, or too
// narrow for an equirectangular map (at least 2 x 1 texels). `rotation_degrees` turns it about
// +y. Memory follows the pixels the file holds, not the size its header claims; `cancel` is seen
// while it decodes and while its sampling distribution is built.
EnvironmentMap load_environment_map(const std::string& path, double rotation_degrees, CancelFlag cancel = nullptr);

}  // namespace tracer
