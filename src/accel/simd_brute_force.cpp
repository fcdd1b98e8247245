// SIMD brute force (the study's ISPC column): every ray against every triangle, eight triangles
// per test with the 8-wide BVH's pack kernel, compiled once per SIMD target.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "accel/simd_brute_force.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <algorithm>

#include "accel/brute_force.hpp"
#include "accel/wide_bvh/wide_bvh.hpp"
#include "accel/wide_bvh/wide_bvh_kernels-inl.h"

HWY_BEFORE_NAMESPACE();
namespace tracer {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Brute force over packs: closest hit, ties to the lower scene index as everywhere.
bool IntersectBrute(const SimdBruteForce& bf, const Ray& ray, Hit& hit) {
  hit = Hit{};
  hit.t = ray.tfar;
  const RayShear ray_shear(ray);
  const PackRay shear(ray_shear);
  const Triangle* tris = bf.scene().triangles.data();
  for (const TrianglePack& p : bf.packs()) ClosestInPack(p, shear, tris, ray.tnear, hit);
  return finish_hit(bf.scene(), hit);
}

bool OccludedBrute(const SimdBruteForce& bf, const Ray& ray) {
  const RayShear ray_shear(ray);
  const PackRay shear(ray_shear);
  const Triangle* tris = bf.scene().triangles.data();
  HWY_ALIGN float tt[kWideWidth], uu[kWideWidth], vv[kWideWidth];
  for (const TrianglePack& p : bf.packs()) {
    if (IntersectPack(p, shear, tris, ray.tnear, ray.tfar, tt, uu, vv)) return true;
  }
  return false;
}

}  // namespace HWY_NAMESPACE
}  // namespace tracer
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace tracer {

HWY_EXPORT(IntersectBrute);
HWY_EXPORT(OccludedBrute);

bool SimdBruteForce::intersect(const Ray& ray, Hit& hit) const {
  return SIMD_DISPATCH(simd_, IntersectBrute)(*this, ray, hit);
}
bool SimdBruteForce::occluded(const Ray& ray) const { return SIMD_DISPATCH(simd_, OccludedBrute)(*this, ray); }

SimdBruteForce::SimdBruteForce(const Scene& scene, SimdTarget simd) : scene_(&scene), simd_(SimdDispatch::of(simd)) {
  std::vector<uint32_t> ids;
  for (uint32_t i = 0; i < scene.size(); ++i) {
    if (!scene.triangles[i].degenerate()) ids.push_back(i);
  }
  for (uint32_t first = 0; first < ids.size(); first += kWideWidth) {
    packs_.push_back(
        make_triangle_pack(scene.triangles, ids, first, std::min<uint32_t>(kWideWidth, uint32_t(ids.size()) - first)));
  }
}

}  // namespace tracer
#endif  // HWY_ONCE
