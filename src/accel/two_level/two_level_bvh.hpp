// The two-level tree of an instanced scene: an 8-wide BVH per mesh over its own triangles (the
// bottom level, built once however many instances place it) and an 8-wide tree over the
// instances' world boxes (the top level, one instance per leaf). A ray reaching an instance is
// moved into its mesh's space by the inverse transform (direction unnormalised, so distances
// along it are the world ray's) and traced there with the 8-wide BVH's own kernels: single rays,
// primary packets and AO bundles alike.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "accel/wide_bvh/wide_bvh.hpp"

namespace tracer {

class TwoLevelBvh {
 public:
  // Builds a tree per mesh of scene.meshes (meshes in parallel, and each in parallel where the
  // executor is data-parallel) and the tree over scene.instances.
  TwoLevelBvh(const Scene& scene, const BvhBuildOptions& options);
  TwoLevelBvh(const Scene& scene, const BvhBuildOptions& options, const Executor& exec);

  bool intersect(const Ray& ray, Hit& hit) const;
  bool occluded(const Ray& ray) const;
  // The same queries, counting both levels' nodes (and the meshes' packs) into `counts`.
  bool intersect(const Ray& ray, Hit& hit, TraversalCounts& counts) const;
  bool occluded(const Ray& ray, TraversalCounts& counts) const;
  // Closest hits of the rays of a packet (up to 16 coherent rays, e.g. a 4x4 pixel block): each
  // lane's hit is the one intersect() gives its ray; lanes not in rays.active are left alone.
  void intersect_packet(const RayPacket& rays, Hit* hits) const;
  void intersect_packet(const RayPacket& rays, Hit* hits, TraversalCounts& counts) const;
  // The lanes of rays.active whose rays (up to 16 leaving one point) are occluded, each the answer
  // occluded() gives its ray: the top level searched with the bundle's open rays, each instance's
  // mesh by the 8-wide BVH's bundle kernel with the bundle moved into its space. `origin` unused.
  uint32_t occluded_bundle_from(const RayBundle& rays, uint32_t origin) const;
  uint32_t occluded_bundle_from(const RayBundle& rays, uint32_t origin, TraversalCounts& counts) const;

  const Scene& scene() const { return *scene_; }
  const WideNodeArray& top_nodes() const { return top_; }  // a leaf child's `child`: its instance
  const WideBvh& mesh_tree(uint32_t mesh) const { return *meshes_[mesh]; }
  std::span<const Instance> instances() const { return scene_->instances; }
  size_t memory_bytes() const;
  // Every top-level child box contains its instance's box or subtree, every instance with a
  // non-empty box is in exactly one leaf, and each mesh's tree is valid.
  std::string validate() const;
  const SimdDispatch& simd() const { return simd_; }

 private:
  const Scene* scene_;
  std::vector<std::unique_ptr<WideBvh>> meshes_;
  WideNodeArray top_;
  SimdDispatch simd_;
};

// The ray in instance `in`'s mesh space, up to `tfar`: origin and direction moved by the inverse
// transform, the direction not renormalised, so t measures the same points in both spaces.
inline Ray to_object(const Instance& in, const Ray& ray, float tfar) {
  Ray local;
  local.org = in.to_object.point(ray.org);
  local.dir = in.to_object.vector(ray.dir);
  local.tnear = ray.tnear;
  local.tfar = tfar;
  return local;
}

}  // namespace tracer
