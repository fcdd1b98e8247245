// Packet traversal of the 8-wide BVH: up to 16 coherent rays go down the tree together, one SIMD
// lane per ray (one AVX-512 register, two AVX2 or four SSE4 ones). Each node's children are
// loaded once per packet instead of once per ray, and a per-packet lane mask follows which rays
// are still inside each subtree (per-ray box culling against each ray's own closest hit).
//
// Every lane computes exactly the scalar code's arithmetic (RayBoxTest, the watertight test of
// triangle_test.hpp, closer()), so each ray gets the hit it gets alone, bit for bit. Packets whose
// rays do not share the shear axes of that test (rare for primary rays) are traced ray by ray.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "accel/wide_bvh/wide_bvh_packets.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <bit>

#include "accel/wide_bvh/wide_bvh.hpp"
#include "accel/wide_bvh/wide_bvh_packet_kernels-inl.h"

HWY_BEFORE_NAMESPACE();
namespace tracer {
namespace HWY_NAMESPACE {

template <class Count>
void IntersectPacketWideT(const WideBvh& bvh, const RayPacket& rays, Hit* hits, Count count, TraversalCounts* counts) {
  const uint32_t active = rays.active & ((1u << kPacketSize) - 1u);
  for (uint32_t bits = active; bits; bits &= bits - 1) {
    const int lane = __builtin_ctz(bits);
    hits[lane] = Hit{};
    hits[lane].t = rays.tfar[lane];
  }
  if (active == 0 || bvh.nodes().empty()) return;
  PacketState st;
  if (!InitPacketState(rays, active, st)) {  // rare for primary rays: ray by ray
    for (uint32_t bits = active; bits; bits &= bits - 1) {
      const int lane = __builtin_ctz(bits);
      if (counts)
        bvh.intersect(rays.ray(lane), hits[lane], *counts);
      else
        bvh.intersect(rays.ray(lane), hits[lane]);
    }
    return;
  }
  count.rays(uint32_t(std::popcount(active)));
  ClosestInTreePacket(bvh, st, active, count);
  for (uint32_t bits = active; bits; bits &= bits - 1) {
    const int lane = __builtin_ctz(bits);
    Hit& h = hits[lane];
    h.tri = uint32_t(st.tri[lane]) ^ uint32_t(kFlip);
    h.t = st.t[lane];
    h.u = st.u[lane];
    h.v = st.v[lane];
    finish_hit(bvh.scene(), h);
  }
}

void IntersectPacketWide(const WideBvh& bvh, const RayPacket& rays, Hit* hits) {
  IntersectPacketWideT(bvh, rays, hits, NoCount{}, nullptr);
}
void IntersectPacketWideCounted(const WideBvh& bvh, const RayPacket& rays, Hit* hits, TraversalCounts* counts) {
  IntersectPacketWideT(bvh, rays, hits, CountInto{counts}, counts);
}

}  // namespace HWY_NAMESPACE
}  // namespace tracer
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace tracer {

HWY_EXPORT(IntersectPacketWide);
HWY_EXPORT(IntersectPacketWideCounted);

void WideBvh::intersect_packet(const RayPacket& rays, Hit* hits) const {
  SIMD_DISPATCH(simd_, IntersectPacketWide)(*this, rays, hits);
}
void WideBvh::intersect_packet(const RayPacket& rays, Hit* hits, TraversalCounts& counts) const {
  SIMD_DISPATCH(simd_, IntersectPacketWideCounted)(*this, rays, hits, &counts);
}

}  // namespace tracer
#endif  // HWY_ONCE
