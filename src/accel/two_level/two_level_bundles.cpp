// The two-level tree's AO bundles, compiled once per SIMD target.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "accel/two_level/two_level_bundles.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <bit>

#include "accel/two_level/two_level_bvh.hpp"
#include "accel/wide_bvh/wide_bvh_bundle_kernels-inl.h"
#include "accel/wide_bvh/wide_bvh_kernels-inl.h"

HWY_BEFORE_NAMESPACE();
namespace tracer {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

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

}  // namespace HWY_NAMESPACE
}  // namespace tracer
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace tracer {

HWY_EXPORT(OccludedBundleTwoLevel);
HWY_EXPORT(OccludedBundleTwoLevelCounted);

uint32_t TwoLevelBvh::occluded_bundle_from(const RayBundle& rays, uint32_t /*origin*/) const {
  return SIMD_DISPATCH(simd_, OccludedBundleTwoLevel)(*this, rays);
}
uint32_t TwoLevelBvh::occluded_bundle_from(const RayBundle& rays, uint32_t /*origin*/, TraversalCounts& counts) const {
  return SIMD_DISPATCH(simd_, OccludedBundleTwoLevelCounted)(*this, rays, &counts);
}

}  // namespace tracer
#endif  // HWY_ONCE
