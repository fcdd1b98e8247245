// A stream of occlusion rays (the AO rays a tile's hits spawn), as structure of arrays, with the
// order they are to be traced in: rays next to each other in `order` point the same way from
// nearby points (render/stream_order.hpp sorts them), so a group of consecutive ones traverses a
// tree together as coherently as a primary packet does.
#pragma once

#include <cstdint>

#include "math/ray.hpp"

namespace tracer {

struct alignas(64) RayStream {
  static constexpr uint32_t kCapacity = 4096;  // a 16x16 tile's 16 AO rays per pixel
  // One ray per 32 bytes: a kernel reads the rays in sorted order, so each costs one cache line
  // (eight arrays cost eight misses a ray once the stream outgrows the L1 cache).
  struct Entry {
    Vec3 org;
    float tnear;
    Vec3 dir;
    float tfar;
  };
  Entry rays[kCapacity];
  uint32_t order[kCapacity];   // the rays' indices in trace order, grouped by shear_class():
  uint32_t class_end[6] = {};  // class c's rays are order[class_end[c - 1] .. class_end[c]) (from 0 for c = 0)
  uint16_t owner[kCapacity];   // whose ray it is (the caller's: a pixel of the tile)
  uint32_t size = 0;

  bool full() const { return size == kCapacity; }
  void push(const Ray& r, uint16_t who) {
    rays[size] = {r.org, r.tnear, r.dir, r.tfar};
    owner[size++] = who;
  }
  Ray ray(uint32_t i) const {
    Ray r;
    r.org = rays[i].org;
    r.dir = rays[i].dir;
    r.tnear = rays[i].tnear;
    r.tfar = rays[i].tfar;
    return r;
  }
};
static_assert(sizeof(RayStream::Entry) == 32);

// One bit per ray of a stream, by its index (not its place in `order`).
struct StreamMask {
  uint64_t words[RayStream::kCapacity / 64] = {};
  void set(uint32_t i) { words[i >> 6] |= uint64_t(1) << (i & 63); }
  bool test(uint32_t i) const { return (words[i >> 6] >> (i & 63)) & 1u; }
};

// The triangle test's shear class of a direction (triangle_test.hpp's RayShear): its axis of
// largest magnitude, twice, plus one where that component is negative. Rays of one class share
// the shear axes, which a packet's triangle test needs.
inline uint32_t shear_class(Vec3 d) {
  const int kz = max_dimension(abs(d));
  return uint32_t(kz) * 2u + (d[kz] < 0.0f ? 1u : 0u);
}

}  // namespace tracer
