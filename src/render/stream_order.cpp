#include "render/stream_order.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace tracer {
namespace {

// Bit i of a 4-bit value moved to bit 2i.
constexpr std::array<uint32_t, 16> kSpread2 = {0x00, 0x01, 0x04, 0x05, 0x10, 0x11, 0x14, 0x15,
                                               0x40, 0x41, 0x44, 0x45, 0x50, 0x51, 0x54, 0x55};

}  // namespace

uint32_t stream_key(float dx, float dy, float dz) {
  const float c[3] = {dx, dy, dz};
  const uint32_t cls = shear_class({dx, dy, dz});
  const int kz = int(cls / 2);
  const int kx = kz == 2 ? 0 : kz + 1, ky = kx == 2 ? 0 : kx + 1;
  // The two minor components over the major one, in [-1, 1], quantised to 4 bits each.
  const float scale = 8.0f / std::abs(c[kz]);
  const auto q = [&](float v) {
    const float f = v * scale + 8.0f;
    return f > 0.0f ? uint32_t(std::min(f, 15.0f)) : 0u;  // NaN (a zero direction): 0; inf: 15
  };
  return (cls << 8) | (kSpread2[q(c[kx])] << 1) | kSpread2[q(c[ky])];
}

void sort_stream(RayStream& s) {
  const uint32_t n = s.size;
  static thread_local std::array<uint16_t, RayStream::kCapacity> keys;
  uint32_t count[kStreamKeys + 1] = {};
  for (uint32_t i = 0; i < n; ++i) {
    const Vec3 d = s.rays[i].dir;
    keys[i] = uint16_t(stream_key(d.x, d.y, d.z));
    ++count[keys[i] + 1];
  }
  for (uint32_t k = 0; k < kStreamKeys; ++k) count[k + 1] += count[k];
  for (uint32_t c = 0; c < 6; ++c) s.class_end[c] = count[(c + 1) << 8];
  for (uint32_t i = 0; i < n; ++i) s.order[count[keys[i]]++] = i;  // stable: pixel order within a key
}

}  // namespace tracer
