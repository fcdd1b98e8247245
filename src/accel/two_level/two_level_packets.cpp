// The two-level tree's primary packets, compiled once per SIMD target.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "accel/two_level/two_level_packets.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <bit>

#include "accel/two_level/two_level_bvh.hpp"
#include "accel/wide_bvh/wide_bvh_kernels-inl.h"
#include "accel/wide_bvh/wide_bvh_packet_kernels-inl.h"

HWY_BEFORE_NAMESPACE();
namespace tracer {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// A packet of primary rays (up to 16): the top level walked by the packet in world space; at each
// instance, the lanes that reach it moved into its mesh's space (each ray as ToObject moves it,
// up to its closest hit so far) and searched together by the flat tree's packet kernel, or one by
// one where the moved rays do not share the triangle test's shear axes. Each lane's hit is the
// one IntersectTwoLevelT gives its ray.
template <class Count>
void IntersectPacketTwoLevelT(const TwoLevelBvh& tl, const RayPacket& rays, Hit* hits, Count count) {
  const uint32_t active = rays.active & ((1u << kPacketSize) - 1u);
  for (uint32_t bits = active; bits; bits &= bits - 1) {
    const int lane = __builtin_ctz(bits);
    hits[lane] = Hit{};
    hits[lane].t = rays.tfar[lane];
  }
  if (active == 0 || tl.top_nodes().empty()) return;
  count.rays(uint32_t(std::popcount(active)));
  PacketState world;  // the box tests' constants, and each lane's closest hit so far
  InitPacketState(rays, active, world);
  HWY_ALIGN uint32_t inst[kPacketSize];
  const std::span<const Instance> instances = tl.instances();
  PacketWalk(tl.top_nodes().data(), world, active, count, [&](const PacketEntry& e) TRACER_INLINE_LAMBDA {
    const Instance& in = instances[e.child];
    const WideBvh& mesh = tl.mesh_tree(in.mesh);
    if (mesh.nodes().empty()) return;
    RayPacket local;
    for (uint32_t bits = e.lanes; bits; bits &= bits - 1) {
      const int lane = __builtin_ctz(bits);
      local.set(lane, to_object(in, rays.ray(lane), world.t[lane]));
    }
    PacketState st;
    const bool shared_axes = InitPacketState(local, e.lanes, st);
    for (uint32_t bits = e.lanes; bits; bits &= bits - 1) {  // the closest hit so far, for ties
      const int lane = __builtin_ctz(bits);
      st.tri[lane] = world.tri[lane];
      st.u[lane] = world.u[lane];
      st.v[lane] = world.v[lane];
    }
    if (shared_axes) {
      ClosestInTreePacket(mesh, st, e.lanes, count);
    } else {
      for (uint32_t bits = e.lanes; bits; bits &= bits - 1) {
        const int lane = __builtin_ctz(bits);
        Hit h;
        h.t = st.t[lane];
        h.u = st.u[lane];
        h.v = st.v[lane];
        h.tri = uint32_t(st.tri[lane]) ^ uint32_t(kFlip);
        ClosestInTree(mesh, local.ray(lane), h, count);
        st.t[lane] = h.t;
        st.u[lane] = h.u;
        st.v[lane] = h.v;
        st.tri[lane] = int32_t(h.tri ^ uint32_t(kFlip));
      }
    }
    for (uint32_t bits = e.lanes; bits; bits &= bits - 1) {
      const int lane = __builtin_ctz(bits);
      if (st.t[lane] == world.t[lane] && st.tri[lane] == world.tri[lane]) continue;
      world.t[lane] = st.t[lane];
      world.u[lane] = st.u[lane];
      world.v[lane] = st.v[lane];
      world.tri[lane] = st.tri[lane];
      inst[lane] = e.child;
    }
  });
  for (uint32_t bits = active; bits; bits &= bits - 1) {
    const int lane = __builtin_ctz(bits);
    Hit& h = hits[lane];
    h.tri = uint32_t(world.tri[lane]) ^ uint32_t(kFlip);
    h.t = world.t[lane];
    h.u = world.u[lane];
    h.v = world.v[lane];
    if (h.tri != kInvalidIndex) h.inst = inst[lane];
    finish_hit(tl.scene(), h);
  }
}

void IntersectPacketTwoLevel(const TwoLevelBvh& tl, const RayPacket& rays, Hit* hits) {
  IntersectPacketTwoLevelT(tl, rays, hits, NoCount{});
}
void IntersectPacketTwoLevelCounted(const TwoLevelBvh& tl, const RayPacket& rays, Hit* hits, TraversalCounts* counts) {
  IntersectPacketTwoLevelT(tl, rays, hits, CountInto{counts});
}

}  // namespace HWY_NAMESPACE
}  // namespace tracer
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace tracer {

HWY_EXPORT(IntersectPacketTwoLevel);
HWY_EXPORT(IntersectPacketTwoLevelCounted);

void TwoLevelBvh::intersect_packet(const RayPacket& rays, Hit* hits) const {
  SIMD_DISPATCH(simd_, IntersectPacketTwoLevel)(*this, rays, hits);
}
void TwoLevelBvh::intersect_packet(const RayPacket& rays, Hit* hits, TraversalCounts& counts) const {
  SIMD_DISPATCH(simd_, IntersectPacketTwoLevelCounted)(*this, rays, hits, &counts);
}

}  // namespace tracer
#endif  // HWY_ONCE
