// 8-wide BVH built directly by the binned SAH: each node holds its children's boxes as SoA
// arrays so one SIMD pass tests a ray against all eight, and children are visited nearest first.
// The box kernel is compiled for SSE4, AVX2 and AVX-512 with Google Highway and chosen at run
// time for the CPU it runs on; leaves use the same watertight triangle test as everything else,
// so hits are identical to the binary BVH's and brute force's.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "accel/bvh/bvh.hpp"
#include "accel/kernels/traversal_counts.hpp"
#include "accel/kernels/triangle_pack.hpp"
#include "math/ray_packet.hpp"
#include "math/ray_stream.hpp"

namespace tracer {

struct alignas(64) WideNode {
  // Children's boxes, one lane per child; an empty slot has lo = +inf, hi = -inf and never hits.
  float lo_x[kWideWidth], lo_y[kWideWidth], lo_z[kWideWidth];
  float hi_x[kWideWidth], hi_y[kWideWidth], hi_z[kWideWidth];
  uint32_t child[kWideWidth];  // inner child: node index; leaf child: first triangle
  uint32_t count[kWideWidth];  // 0: inner child; > 0: leaf of `count` triangles in pack `child`
};
static_assert(sizeof(WideNode) == 256);

// Packs and nodes, 64-byte aligned, on huge pages when large; packs are left uninitialised by
// resize() (the build fills them in parallel).
using PackArray = std::vector<TrianglePack, LargeArrayAllocator<TrianglePack>>;
using WideNodeArray = std::vector<WideNode, LargeArrayAllocator<WideNode>>;

class WideBvh {
 public:
  // Builds the tree with `options` (split and executor; leaves are packs of up to eight
  // triangles) directly, 8-wide: wide_bvh_build.cpp.
  WideBvh(const Scene& scene, const BvhBuildOptions& options);
  WideBvh(const Scene& scene, const BvhBuildOptions& options, const Executor& exec);
  // The tree over `range` of the scene's triangles only (a mesh of an instanced scene); its hits
  // name scene triangles as the whole scene's tree does.
  WideBvh(const Scene& scene, TriangleRange range, const BvhBuildOptions& options, const Executor& exec);

  bool intersect(const Ray& ray, Hit& hit) const;
  bool occluded(const Ray& ray) const;
  // The same queries, counting what they visit into `counts` (--count).
  bool intersect(const Ray& ray, Hit& hit, TraversalCounts& counts) const;
  bool occluded(const Ray& ray, TraversalCounts& counts) const;
  void intersect_packet(const RayPacket& rays, Hit* hits, TraversalCounts& counts) const;
  uint32_t occluded_bundle_from(const RayBundle& rays, uint32_t origin, TraversalCounts& counts) const;
  // Closest hits of the packet's active lanes, traversed together; hits[k] is exactly what
  // intersect(rays.ray(k), hits[k]) gives. Inactive lanes' hits are left untouched.
  void intersect_packet(const RayPacket& rays, Hit* hits) const;
  // The lanes of rays.active whose rays (up to 16 leaving one point: the AO rays of one shading
  // point) are occluded; each the answer occluded() gives its ray. Top-down: while many rays
  // enter a node, its children's boxes are tested against all of them at once (one SIMD lane per
  // ray); where few do, each goes on alone from there. `origin` (the triangle they leave) is not
  // needed by this tree; the binary BVH starts from it.
  uint32_t occluded_bundle_from(const RayBundle& rays, uint32_t origin) const;
  // Sets in `occluded` the rays of `rays` that are occluded, each the answer occluded() gives it:
  // the rays taken in rays.order by groups of up to 16 of one shear class, each group traversed
  // as a packet (wide_bvh_streams.cpp).
  void occluded_stream(const RayStream& rays, StreamMask& occluded) const;
  void occluded_stream(const RayStream& rays, StreamMask& occluded, TraversalCounts& counts) const;

  const WideNodeArray& nodes() const { return nodes_; }
  const PackArray& packs() const { return packs_; }
  const Aabb& bounds() const { return bounds_; }  // of every triangle in the tree
  size_t memory_bytes() const { return nodes_.size() * sizeof(WideNode) + packs_.size() * sizeof(TrianglePack); }
  // Every child box contains its subtree, every non-degenerate triangle is in exactly one leaf
  // (with spatial splits: in at least one, and its leaves' boxes together cover its box, each
  // meeting it), empty slots come last.
  std::string validate() const;
  // Built with spatial splits (BvhBuildOptions::split_budget): a triangle may be in several leaves.
  bool spatial_splits() const { return spatial_splits_; }
  const Scene& scene() const { return *scene_; }

  // The SIMD target its kernels run on: options.simd, or the CPU's best narrower than that.
  const SimdDispatch& simd() const { return simd_; }

 private:
  const Scene* scene_;
  TriangleRange range_;  // the scene's triangles it holds
  WideNodeArray nodes_;
  PackArray packs_;
  Aabb bounds_;
  bool spatial_splits_ = false;
  SimdDispatch simd_;
};

}  // namespace tracer
