// The 8-wide BVH's single-ray kernels, closest hit and any hit, compiled once per SIMD target.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "accel/wide_bvh/wide_bvh_traverse.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "accel/wide_bvh/wide_bvh.hpp"
#include "accel/wide_bvh/wide_bvh_kernels-inl.h"

HWY_BEFORE_NAMESPACE();
namespace tracer {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

template <class Count>
bool IntersectWideT(const WideBvh& bvh, const Ray& ray, Hit& hit, Count count) {
  count.rays(1);
  hit = Hit{};
  hit.t = ray.tfar;
  ClosestInTree(bvh, ray, hit, count);
  return finish_hit(bvh.scene(), hit);
}

bool IntersectWide(const WideBvh& bvh, const Ray& ray, Hit& hit) { return IntersectWideT(bvh, ray, hit, NoCount{}); }
bool IntersectWideCounted(const WideBvh& bvh, const Ray& ray, Hit& hit, TraversalCounts* counts) {
  return IntersectWideT(bvh, ray, hit, CountInto{counts});
}
bool OccludedWide(const WideBvh& bvh, const Ray& ray) { return OccludedFromRoot(bvh, ray, NoCount{}); }
bool OccludedWideCounted(const WideBvh& bvh, const Ray& ray, TraversalCounts* counts) {
  return OccludedFromRoot(bvh, ray, CountInto{counts});
}

}  // namespace HWY_NAMESPACE
}  // namespace tracer
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace tracer {

HWY_EXPORT(IntersectWide);
HWY_EXPORT(IntersectWideCounted);
HWY_EXPORT(OccludedWide);
HWY_EXPORT(OccludedWideCounted);

// One table-indexed call per ray (Highway's dynamic dispatch), never per node: the kernels above
// inline the whole traversal.
bool WideBvh::intersect(const Ray& ray, Hit& hit) const { return SIMD_DISPATCH(simd_, IntersectWide)(*this, ray, hit); }
bool WideBvh::occluded(const Ray& ray) const { return SIMD_DISPATCH(simd_, OccludedWide)(*this, ray); }
bool WideBvh::intersect(const Ray& ray, Hit& hit, TraversalCounts& counts) const {
  return SIMD_DISPATCH(simd_, IntersectWideCounted)(*this, ray, hit, &counts);
}
bool WideBvh::occluded(const Ray& ray, TraversalCounts& counts) const {
  return SIMD_DISPATCH(simd_, OccludedWideCounted)(*this, ray, &counts);
}

}  // namespace tracer
#endif  // HWY_ONCE
