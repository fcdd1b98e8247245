// The study's O(N) baseline: every ray against every triangle.
#pragma once

#include <vector>

#include "accel/kernels/triangle_test.hpp"
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

}  // namespace tracer
