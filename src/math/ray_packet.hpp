// A packet of up to 16 coherent rays (e.g. the primary rays of a 4x4 pixel block), stored as
// structure-of-arrays so a SIMD register holds one component of many rays. Lanes not in
// `active` hold no ray and are never touched by the traversal.
#pragma once

#include <cstdint>

#include "math/ray.hpp"

namespace tracer {

inline constexpr int kPacketSize = 16;
inline constexpr int kPacketEdge = 4;  // primary-ray packets cover 4x4 pixels

struct alignas(64) RayPacket {
  float ox[kPacketSize], oy[kPacketSize], oz[kPacketSize];
  float dx[kPacketSize], dy[kPacketSize], dz[kPacketSize];
  float tnear[kPacketSize], tfar[kPacketSize];
  uint32_t active = 0;  // bit k: lane k holds a ray

  void set(int lane, const Ray& r) {
    ox[lane] = r.org.x;
    oy[lane] = r.org.y;
    oz[lane] = r.org.z;
    dx[lane] = r.dir.x;
    dy[lane] = r.dir.y;
    dz[lane] = r.dir.z;
    tnear[lane] = r.tnear;
    tfar[lane] = r.tfar;
    active |= 1u << lane;
  }
  Ray ray(int lane) const {
    Ray r;
    r.org = {ox[lane], oy[lane], oz[lane]};
    r.dir = {dx[lane], dy[lane], dz[lane]};
    r.tnear = tnear[lane];
    r.tfar = tfar[lane];
    return r;
  }
};

// Up to 16 rays that share their origin and interval but not their direction: the ambient-
// occlusion rays of one shading point. Directions in structure-of-arrays form, one lane per ray.
struct alignas(64) RayBundle {
  float dx[kPacketSize]{}, dy[kPacketSize]{}, dz[kPacketSize]{};  // zeros in lanes without a ray
  Vec3 org;
  float tnear = 0.0f, tfar = kInfinity;
  uint32_t active = 0;  // bit k: lane k holds a ray

  void set_direction(int lane, Vec3 d) {
    dx[lane] = d.x;
    dy[lane] = d.y;
    dz[lane] = d.z;
    active |= 1u << lane;
  }
  Ray ray(int lane) const {
    Ray r;
    r.org = org;
    r.dir = {dx[lane], dy[lane], dz[lane]};
    r.tnear = tnear;
    r.tfar = tfar;
    return r;
  }
};

}  // namespace tracer
