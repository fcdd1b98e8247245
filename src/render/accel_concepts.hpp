// What an accelerator can do beyond one ray at a time, as concepts the integrators test at
// compile time (so the per-ray path never asks at run time).
#pragma once

#include <concepts>
#include <cstdint>

#include "math/ray.hpp"
#include "math/ray_packet.hpp"

namespace tracer {

// Accelerators that trace a RayPacket at once (the 8-wide BVH, Embree's packet API).
template <class A>
concept PacketAccelerator = requires(const A& a, const RayPacket& p, Hit* h) {
  a.intersect_packet(p, h);
};

// Accelerators that answer the AO rays of one shading point as one bundle (both BVHs, Embree).
template <class A>
concept BundleAccelerator = requires(const A& a, const RayBundle& b) {
  a.occluded_bundle_from(b, 0u);
};

// An occlusion query for a ray leaving scene triangle `origin`: accelerators that can start the
// search at that triangle's leaf (the binary BVH) do; the others search from the root.
template <class Accel>
bool occluded_leaving(const Accel& accel, const Ray& ray, uint32_t origin) {
  if constexpr (requires { accel.occluded_from(ray, origin); }) {
    return accel.occluded_from(ray, origin);
  } else {
    return accel.occluded(ray);
  }
}

// Accelerators that answer a packet of unrelated occlusion rays at once (Embree's packet API).
template <class A>
concept OcclusionPacketAccelerator = requires(const A& a, const RayPacket& p) {
  { a.occluded_packet(p) } -> std::same_as<uint32_t>;
};

}  // namespace tracer
