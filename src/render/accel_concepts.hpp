// What an accelerator can do beyond one ray at a time, as concepts the integrators test at
// compile time (so the per-ray path never asks at run time).
#pragma once

#include <concepts>
#include <cstdint>

#include "accel/kernels/traversal_counts.hpp"
#include "math/ray.hpp"
#include "math/ray_packet.hpp"
#include "math/ray_stream.hpp"

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

// Accelerators that answer a sorted stream of occlusion rays (a tile's AO rays) at once: the
// 8-wide BVH's packets over the stream, Embree's stream API.
template <class A>
concept StreamAccelerator = requires(const A& a, const RayStream& s, StreamMask& m) {
  a.occluded_stream(s, m);
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

// Accelerators that count what their queries visit (the 8-wide BVH).
template <class A>
concept CountingAccelerator = requires(const A& a, const Ray& r, Hit& h, TraversalCounts& c) {
  { a.intersect(r, h, c) } -> std::same_as<bool>;
  { a.occluded(r, c) } -> std::same_as<bool>;
};

// A counting accelerator seen as an ordinary one (--count): each query goes to the counted
// kernels, closest hits into counts->closest and any hits into counts->any. The integrators run
// on it unchanged, so the image is the one the uncounted render makes.
template <CountingAccelerator A>
class Counted {
 public:
  Counted(const A& accel, QueryCounts& counts) : accel_(&accel), counts_(&counts) {}
  bool intersect(const Ray& r, Hit& h) const { return accel_->intersect(r, h, counts_->closest); }
  bool occluded(const Ray& r) const { return accel_->occluded(r, counts_->any); }
  void intersect_packet(const RayPacket& p, Hit* h) const requires PacketAccelerator<A> {
    accel_->intersect_packet(p, h, counts_->closest);
  }
  uint32_t occluded_bundle_from(const RayBundle& b, uint32_t origin) const requires BundleAccelerator<A> {
    return accel_->occluded_bundle_from(b, origin, counts_->any);
  }
  void occluded_stream(const RayStream& s, StreamMask& m) const requires StreamAccelerator<A> {
    accel_->occluded_stream(s, m, counts_->any);
  }

 private:
  const A* accel_;
  QueryCounts* counts_;
};

}  // namespace tracer
