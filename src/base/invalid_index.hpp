// The one value that means "no index": no hit, no triangle, no parent, an empty SIMD lane.
#pragma once

#include <cstdint>

namespace tracer {

inline constexpr uint32_t kInvalidIndex = 0xffffffffu;

}  // namespace tracer
