// The 8-wide BVH's AO bundles: up to 16 rays leaving one point searched top-down together while
// many of them enter the same nodes (docs/RENDERING.md, "Packets"), compiled once per SIMD target.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "accel/wide_bvh/wide_bvh_bundles.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <bit>

#include "accel/wide_bvh/wide_bvh.hpp"
#include "accel/wide_bvh/wide_bvh_bundle_kernels-inl.h"

HWY_BEFORE_NAMESPACE();
namespace tracer {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

template <class Count>
uint32_t OccludedBundleWideT(const WideBvh& bvh, const RayBundle& rays, Count count) {
  count.rays(uint32_t(std::popcount(rays.active)));
  if (bvh.nodes().empty() || rays.active == 0) return 0;
  return OccludedBundleInTree(bvh, BundleState(rays), rays.active, count);
}

uint32_t OccludedBundleWide(const WideBvh& bvh, const RayBundle& rays, uint32_t /*origin*/) {
  return OccludedBundleWideT(bvh, rays, NoCount{});
}
uint32_t OccludedBundleWideCounted(const WideBvh& bvh, const RayBundle& rays, TraversalCounts* counts) {
  return OccludedBundleWideT(bvh, rays, CountInto{counts});
}

}  // namespace HWY_NAMESPACE
}  // namespace tracer
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace tracer {

HWY_EXPORT(OccludedBundleWide);
HWY_EXPORT(OccludedBundleWideCounted);

uint32_t WideBvh::occluded_bundle_from(const RayBundle& rays, uint32_t origin) const {
  return SIMD_DISPATCH(simd_, OccludedBundleWide)(*this, rays, origin);
}
uint32_t WideBvh::occluded_bundle_from(const RayBundle& rays, uint32_t /*origin*/, TraversalCounts& counts) const {
  return SIMD_DISPATCH(simd_, OccludedBundleWideCounted)(*this, rays, &counts);
}

}  // namespace tracer
#endif  // HWY_ONCE
