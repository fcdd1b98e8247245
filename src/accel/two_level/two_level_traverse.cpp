// The two-level tree's kernels, compiled once per SIMD target: closest hit and any hit for one ray,
// primary packets and AO bundles. The top level is walked with the 8-wide BVH's node tests, and
// each instance reached is traced in its mesh's tree by the kernels the flat tree runs.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "accel/two_level/two_level_traverse.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <bit>

#include "accel/two_level/two_level_bvh.hpp"
#include "accel/wide_bvh/wide_bvh_bundle_kernels-inl.h"
#include "accel/wide_bvh/wide_bvh_kernels-inl.h"
#include "accel/wide_bvh/wide_bvh_packet_kernels-inl.h"

HWY_BEFORE_NAMESPACE();
namespace tracer {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// The ray in instance `in`'s mesh space, up to `tfar`: origin and direction moved by the inverse
// transform, the direction not renormalised, so t measures the same points in both spaces.
HWY_INLINE Ray ToObject(const Instance& in, const Ray& ray, float tfar) {
  Ray local;
  local.org = in.to_object.point(ray.org);
  local.dir = in.to_object.vector(ray.dir);
  local.tnear = ray.tnear;
  local.tfar = tfar;
  return local;
}

template <class Count>
bool IntersectTwoLevelT(const TwoLevelBvh& tl, const Ray& ray, Hit& hit, Count count) {
  count.rays(1);
  hit = Hit{};
  hit.t = ray.tfar;
  if (tl.top_nodes().empty()) return false;
  const std::span<const Instance> instances = tl.instances();
  ClosestWalk(tl.top_nodes().data(), ray, hit, count, [&](const StackEntry& e) TRACER_INLINE_LAMBDA {
    const Instance& in = instances[e.child];
    const float t_before = hit.t;
    const uint32_t tri_before = hit.tri;
    ClosestInTree(tl.mesh_tree(in.mesh), ToObject(in, ray, hit.t), hit, count);
    if (hit.t != t_before || hit.tri != tri_before) hit.inst = e.child;
  });
  return finish_hit(tl.scene(), hit);
}

template <class Count>
bool OccludedTwoLevelT(const TwoLevelBvh& tl, const Ray& ray, Count count) {
  count.rays(1);
  if (tl.top_nodes().empty()) return false;
  const std::span<const Instance> instances = tl.instances();
  return AnyHitWalk(tl.top_nodes().data(), NodeRay(WideRay(ray)), ray.tnear, ray.tfar, StackEntry{0, 0, ray.tnear},
                    count, [&](const StackEntry& e) TRACER_INLINE_LAMBDA {
                      const Instance& in = instances[e.child];
                      const WideBvh& mesh = tl.mesh_tree(in.mesh);
                      if (mesh.nodes().empty()) return false;
                      const Ray local = ToObject(in, ray, ray.tfar);
                      return OccludedBelow(mesh, WideRay(local), RayShear(local), local.tnear, local.tfar,
                                           StackEntry{0, 0, local.tnear}, count);
                    });
}

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
      local.set(lane, ToObject(in, rays.ray(lane), world.t[lane]));
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

// The AO rays of one point (a bundle): the top level's boxes tested against all of its rays still
// open, and at each instance the bundle moved into the mesh's space (its origin and each
// direction) and searched there by the flat tree's bundle kernel.
template <class Count>
uint32_t OccludedBundleTwoLevelT(const TwoLevelBvh& tl, const RayBundle& rays, Count count) {
  count.rays(uint32_t(std::popcount(rays.active)));
  const WideNodeArray& nodes = tl.top_nodes();
  if (nodes.empty() || rays.active == 0) return 0;
  const std::span<const Instance> instances = tl.instances();
  return BundleWalk(nodes.data(), BundleState(rays), rays.active, count,
                    [&](const BundleEntry& e, uint32_t lanes, uint32_t& found) TRACER_INLINE_LAMBDA {
                      if (e.count == 0) return false;
                      const Instance& in = instances[e.child];
                      RayBundle local;
                      local.org = in.to_object.point(rays.org);
                      local.tnear = rays.tnear;
                      local.tfar = rays.tfar;
                      for (uint32_t bits = lanes; bits; bits &= bits - 1) {
                        const int k = __builtin_ctz(bits);
                        local.set_direction(k, in.to_object.vector({rays.dx[k], rays.dy[k], rays.dz[k]}));
                      }
                      found = OccludedBundleInTree(tl.mesh_tree(in.mesh), BundleState(local), lanes, count);
                      return true;
                    });
}

uint32_t OccludedBundleTwoLevel(const TwoLevelBvh& tl, const RayBundle& rays) {
  return OccludedBundleTwoLevelT(tl, rays, NoCount{});
}
uint32_t OccludedBundleTwoLevelCounted(const TwoLevelBvh& tl, const RayBundle& rays, TraversalCounts* counts) {
  return OccludedBundleTwoLevelT(tl, rays, CountInto{counts});
}

bool IntersectTwoLevel(const TwoLevelBvh& tl, const Ray& ray, Hit& hit) {
  return IntersectTwoLevelT(tl, ray, hit, NoCount{});
}
bool IntersectTwoLevelCounted(const TwoLevelBvh& tl, const Ray& ray, Hit& hit, TraversalCounts* counts) {
  return IntersectTwoLevelT(tl, ray, hit, CountInto{counts});
}
bool OccludedTwoLevel(const TwoLevelBvh& tl, const Ray& ray) { return OccludedTwoLevelT(tl, ray, NoCount{}); }
bool OccludedTwoLevelCounted(const TwoLevelBvh& tl, const Ray& ray, TraversalCounts* counts) {
  return OccludedTwoLevelT(tl, ray, CountInto{counts});
}

}  // namespace HWY_NAMESPACE
}  // namespace tracer
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace tracer {

HWY_EXPORT(IntersectTwoLevel);
HWY_EXPORT(IntersectTwoLevelCounted);
HWY_EXPORT(OccludedTwoLevel);
HWY_EXPORT(OccludedTwoLevelCounted);
HWY_EXPORT(OccludedBundleTwoLevel);
HWY_EXPORT(OccludedBundleTwoLevelCounted);
HWY_EXPORT(IntersectPacketTwoLevel);
HWY_EXPORT(IntersectPacketTwoLevelCounted);

void TwoLevelBvh::intersect_packet(const RayPacket& rays, Hit* hits) const {
  SIMD_DISPATCH(simd_, IntersectPacketTwoLevel)(*this, rays, hits);
}
void TwoLevelBvh::intersect_packet(const RayPacket& rays, Hit* hits, TraversalCounts& counts) const {
  SIMD_DISPATCH(simd_, IntersectPacketTwoLevelCounted)(*this, rays, hits, &counts);
}

bool TwoLevelBvh::intersect(const Ray& ray, Hit& hit) const {
  return SIMD_DISPATCH(simd_, IntersectTwoLevel)(*this, ray, hit);
}
bool TwoLevelBvh::occluded(const Ray& ray) const { return SIMD_DISPATCH(simd_, OccludedTwoLevel)(*this, ray); }
bool TwoLevelBvh::intersect(const Ray& ray, Hit& hit, TraversalCounts& counts) const {
  return SIMD_DISPATCH(simd_, IntersectTwoLevelCounted)(*this, ray, hit, &counts);
}
bool TwoLevelBvh::occluded(const Ray& ray, TraversalCounts& counts) const {
  return SIMD_DISPATCH(simd_, OccludedTwoLevelCounted)(*this, ray, &counts);
}

uint32_t TwoLevelBvh::occluded_bundle_from(const RayBundle& rays, uint32_t /*origin*/) const {
  return SIMD_DISPATCH(simd_, OccludedBundleTwoLevel)(*this, rays);
}
uint32_t TwoLevelBvh::occluded_bundle_from(const RayBundle& rays, uint32_t /*origin*/, TraversalCounts& counts) const {
  return SIMD_DISPATCH(simd_, OccludedBundleTwoLevelCounted)(*this, rays, &counts);
}

}  // namespace tracer
#endif  // HWY_ONCE
