// The two-level tree's single-ray kernels, compiled once per SIMD target: closest hit and any hit.
// The top level is walked with the 8-wide BVH's node tests, and each instance reached is traced
// in its mesh's tree by the kernels the flat tree runs. Packets and bundles have their own files
// (two_level_packets.cpp, two_level_bundles.cpp), so the three compile in parallel.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "accel/two_level/two_level_traverse.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <bit>

#include "accel/two_level/two_level_bvh.hpp"
#include "accel/wide_bvh/wide_bvh_kernels-inl.h"

HWY_BEFORE_NAMESPACE();
namespace tracer {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

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
    ClosestInTree(tl.mesh_tree(in.mesh), to_object(in, ray, hit.t), hit, count);
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
                      const Ray local = to_object(in, ray, ray.tfar);
                      return OccludedBelow(mesh, WideRay(local), RayShear(local), local.tnear, local.tfar,
                                           StackEntry{0, 0, local.tnear}, count);
                    });
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

}  // namespace tracer
#endif  // HWY_ONCE
