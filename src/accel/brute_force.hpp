// The study's O(N) baselines: every ray against every triangle, one at a time (BruteForce) or
// eight at a time (SimdBruteForce).
#pragma once

#include <vector>

#include "accel/kernels/triangle_pack.hpp"
#include "accel/kernels/triangle_test.hpp"
#include "base/simd_dispatch.hpp"
#include "scene/scene.hpp"

namespace tracer {

class BruteForce {
 public:
  explicit BruteForce(const Scene& scene) : scene_(&scene) {
    for (uint32_t i = 0; i < scene.size(); ++i) {
      if (scene.triangles[i].degenerate()) continue;
      tris_.push_back(scene.triangles[i]);
      ids_.push_back(i);
    }
  }

  bool intersect(const Ray& ray, Hit& hit) const {
    const RayShear shear(ray);
    hit = Hit{};
    hit.t = ray.tfar;
    intersect_range(shear, tris_.data(), ids_.data(), 0, static_cast<uint32_t>(tris_.size()), ray.tnear, hit);
    return finish_hit(*scene_, hit);
  }

  bool occluded(const Ray& ray) const {
    const RayShear shear(ray);
    TriangleHit th;
    for (const Triangle& t : tris_) {
      if (intersect_triangle(shear, t, ray.tnear, ray.tfar, th)) return true;
    }
    return false;
  }

  size_t memory_bytes() const { return tris_.size() * sizeof(Triangle) + ids_.size() * sizeof(uint32_t); }

 private:
  const Scene* scene_;
  std::vector<Triangle> tris_;
  std::vector<uint32_t> ids_;
};

// The study's brute-force SIMD variant (its ISPC kernel): every ray against every triangle, eight
// at a time, through the same pack kernel as the wide BVH's leaves.
class SimdBruteForce {
 public:
  explicit SimdBruteForce(const Scene& scene, SimdTarget simd = SimdTarget::Auto);
  bool intersect(const Ray& ray, Hit& hit) const;
  bool occluded(const Ray& ray) const;
  const std::vector<TrianglePack>& packs() const { return packs_; }
  const Scene& scene() const { return *scene_; }
  size_t memory_bytes() const { return packs_.size() * sizeof(TrianglePack); }
  const SimdDispatch& simd() const { return simd_; }

 private:
  const Scene* scene_;
  std::vector<TrianglePack> packs_;
  SimdDispatch simd_;
};

}  // namespace tracer
