// The order a stream's rays are traced in (math/ray_stream.hpp): by the triangle test's shear
// class first (a packet needs its rays to share it), then by a Morton code of the quantised
// direction, keeping the order rays were gathered in (pixel by pixel) among equal keys, so rays
// next to each other point the same way from nearby points. One counting-sort pass: a 5-D Morton
// code of direction and origin (as Moon et al. 2010) by a 32-bit radix sort cost 323 instructions
// a ray against this key and sort's 70, and the trace no fewer (docs/bench/LOG.md, session 30).
#pragma once

#include <cstdint>

#include "math/ray_stream.hpp"

namespace tracer {

// The sort key of a direction: shear_class() above 8 bits of Morton code of its two minor
// components over the major one (4 bits each).
inline constexpr uint32_t kStreamKeys = 6u << 8;
uint32_t stream_key(float dx, float dy, float dz);

// Fills s.order with 0 .. s.size - 1 sorted by stream_key (ties in index order).
void sort_stream(RayStream& s);

}  // namespace tracer
