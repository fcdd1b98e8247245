// Binary BVH: 32-byte nodes in one array, siblings adjacent, triangles reordered so each leaf is a
// contiguous run. Traversal is iterative, nearest child first, with a conservative slab test.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <new>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "accel/kernels/lane_kernels.hpp"
#include "accel/kernels/triangle_test.hpp"
#include "base/enum_names.hpp"
#include "base/errors.hpp"
#include "base/huge_pages.hpp"
#include "base/simd_dispatch.hpp"
#include "math/aabb.hpp"
#include "math/ray_packet.hpp"
#include "parallel/executor.hpp"
#include "scene/scene.hpp"

namespace tracer {

enum class BvhSplit { Median, Sah };
inline constexpr EnumName<BvhSplit> kBvhSplitNames[] = {{BvhSplit::Sah, "sah"}, {BvhSplit::Median, "median"}};

struct BvhBuildOptions {
  BvhSplit split = BvhSplit::Sah;
  Strategy strategy = Strategy::Tbb;   // how the build forks (Executor); Atomic forks nothing
  int threads = 0;                     // 0: all hardware threads (parallel modes only)
  SimdTarget simd = SimdTarget::Auto;  // the widest target the built tree's SIMD kernels may use
  int max_leaf = 4;                    // SAH: largest leaf; the median split always makes leaves of 1-2
  int bins = 16;                       // SAH bins per axis
  // Spatial splits may add up to this fraction of references (0: none). The 8-wide BVH only: the
  // binary tree keeps one leaf per triangle.
  float split_budget = 0.0f;
  // Relative costs for the SAH. 1.5 rather than 1 for a node step: traversal measured the same
  // on every scene, with fewer nodes to build and store (docs/BENCHMARKS.md section 4).
  float traversal_cost = 1.5f;
  float intersection_cost = 1.0f;
  // Polled once per node split: when set, the build stops splitting and the constructor throws
  // Cancelled (a Ctrl-C during a long build).
  CancelFlag cancel = nullptr;
};

// 32 bytes: count == 0 marks an interior node whose children are nodes[index] and nodes[index+1];
// otherwise a leaf of `count` triangles starting at triangles()[index].
struct BvhNode {
  Vec3 lo;
  uint32_t index;
  Vec3 hi;
  uint32_t count;
  bool leaf() const { return count != 0; }
};
static_assert(sizeof(BvhNode) == 32);

// Requests what visiting child `c` reads first (its children pair, or its first triangle), the
// address chosen with masks rather than a branch: whether a child is a leaf is as unpredictable
// as the ray. Integer arithmetic, since the index is valid for only one of the two arrays.
inline void prefetch_child(const BvhNode& c, const BvhNode* nodes, const Triangle* tris) {
  const uintptr_t node_line = reinterpret_cast<uintptr_t>(nodes) + uintptr_t(c.index) * sizeof(BvhNode);
  const uintptr_t tri_line = reinterpret_cast<uintptr_t>(tris) + uintptr_t(c.index) * sizeof(Triangle);
  const uintptr_t leaf = uintptr_t(0) - uintptr_t(c.leaf());
  __builtin_prefetch(reinterpret_cast<const void*>((tri_line & leaf) | (node_line & ~leaf)));
}

// Cache-line aligned (sibling pairs at even indices are one 64-byte line), on huge pages when large.
using BvhNodeArray = std::vector<BvhNode, LargeArrayAllocator<BvhNode>>;
using TriangleArray = std::vector<Triangle, LargeArrayAllocator<Triangle>>;

struct BvhStats {
  size_t nodes = 0, leaves = 0, max_depth = 0, max_leaf_size = 0;
  double sah_cost = 0.0;  // expected cost per ray, in the builder's cost units
  double avg_leaf_size = 0.0;
};

struct RayBoxTest;

class Bvh {
 public:
  static constexpr int kMaxDepth = 96;  // the builder guarantees it; traversal stacks rely on it

  // Builds with the executor `options.strategy` names, or the one it is handed.
  Bvh(const Scene& scene, const BvhBuildOptions& options);
  Bvh(const Scene& scene, const BvhBuildOptions& options, const Executor& exec);

  bool intersect(const Ray& ray, Hit& hit) const;
  bool occluded(const Ray& ray) const;
  // occluded() for a ray leaving scene triangle `origin` (a shadow or AO ray): the same answer,
  // found bottom-up from the leaf holding `origin`, testing only the sibling subtree at each
  // level, so the boxes on the path down to the ray's own surface (which it starts inside) are
  // neither tested nor stacked. Any `origin` gives the right answer; the right one is fastest.
  bool occluded_from(const Ray& ray, uint32_t origin) const;
  // occluded_from() for all the rays of a bundle (the AO rays of one shading point), which leave
  // `origin` from one point: returns the bits of rays.active whose rays are occluded, each the
  // answer its ray gets alone. The walk up from the origin's leaf, which the rays share, is made
  // once for all of them, one SIMD lane per ray (bvh_bundles.cpp).
  uint32_t occluded_bundle_from(const RayBundle& rays, uint32_t origin) const;

  // nodes()[0] is the root; nodes()[1] is padding so sibling pairs start at even indices.
  const BvhNodeArray& nodes() const { return nodes_; }
  const TriangleArray& triangles() const { return tris_; }
  const std::vector<uint32_t>& triangle_ids() const { return ids_; }  // scene index per slot
  const BvhBuildOptions& options() const { return options_; }
  const Scene& scene() const { return *scene_; }
  const std::vector<uint32_t>& pair_parents() const {
    return pair_parent_;
  }  // parent of pair nodes[2k], nodes[2k+1], at k
  const std::vector<uint32_t>& leaf_of() const {
    return leaf_of_;
  }  // leaf of each scene triangle (kInvalidIndex: degenerate)
  BvhStats stats() const;
  size_t memory_bytes() const {
    return nodes_.size() * sizeof(BvhNode) + tris_.size() * sizeof(Triangle) +
           (ids_.size() + pair_parent_.size() + leaf_of_.size()) * sizeof(uint32_t);
  }
  // Checks the tree's invariants; returns an empty string when they hold, else the first violation.
  std::string validate() const;

  // Any hit below `node`, whose box the caller has found the ray entering (shear and box are
  // the ray's own constants).
  bool occluded_subtree(uint32_t node, const Ray& ray, const RayShear& shear, const RayBoxTest& box) const;

 private:
  bool occluded_below(uint32_t node, const Ray& ray, const RayShear& shear, const RayBoxTest& box) const;

  const Scene* scene_;
  BvhBuildOptions options_;
  BvhNodeArray nodes_;
  TriangleArray tris_;
  std::vector<uint32_t> ids_;
  std::vector<uint32_t> pair_parent_;  // parent of the sibling pair nodes_[2k], nodes_[2k+1], at k
  std::vector<uint32_t> leaf_of_;      // leaf holding each scene triangle (kInvalidIndex: degenerate)
  SimdDispatch simd_;                  // the AO bundles' kernel target
};

// Slab test of one ray against one binary node's box, with a per-ray reciprocal direction
// (Williams et al. 2005, as pbrt does it); the arithmetic is slab_test's (lane_kernels.hpp).
// The guards: far distances are scaled by 1 + 2*gamma(3) (Ize 2013) so rounding never culls a box
// the ray touches, folded into a second reciprocal, which rounds once as the separate multiply
// did; boxes are kept up to kTieGuard beyond tfar so ties resolve as in brute force. That guard is
// relative: a triangle t whose rounding is larger (t small beside its vertices' distances, hit near
// an edge) can still fall below its box's entry; docs/RENDERING.md states what then differs.
struct RayBoxTest : SlabGuards {
  float org[3], inv[3], inv_far[3];
  // Byte offsets, within a BvhNode, of the plane each slab enters and leaves by: the ray's
  // direction signs are resolved once here, so the per-node test is loads and arithmetic only.
  uint32_t near_off[3], far_off[3];
  explicit RayBoxTest(const Ray& r) : org{r.org.x, r.org.y, r.org.z} {
    for (int a = 0; a < 3; ++a) {
      inv[a] = 1.0f / r.dir[a];
      inv_far[a] = inv[a] * kFarGuard;
      const bool neg = std::signbit(inv[a]);
      near_off[a] = uint32_t((neg ? offsetof(BvhNode, hi) : offsetof(BvhNode, lo)) + sizeof(float) * size_t(a));
      far_off[a] = uint32_t((neg ? offsetof(BvhNode, lo) : offsetof(BvhNode, hi)) + sizeof(float) * size_t(a));
    }
  }
  // Entry distance, or +inf on a miss. tnear and tfar must not be NaN.
  float enter(const BvhNode& n, float tnear, float tfar) const {
    float t0;
    return hit(n, tnear, tfar, t0) ? t0 : kInfinity;
  }
  // Whether the ray enters the node's box within [tnear, tfar]; t0 receives the entry distance.
  // No branch: traversal turns the two children's answers into its next step with arithmetic.
  bool hit(const BvhNode& n, float tnear, float tfar, float& t0_out) const {
    const auto* base = reinterpret_cast<const unsigned char*>(&n);
    const auto plane = [base, this](uint32_t off, int a) {
      float v;
      std::memcpy(&v, base + off, sizeof v);
      return v - org[a];
    };
    const Lanes3<float> near{plane(near_off[0], 0), plane(near_off[1], 1), plane(near_off[2], 2)};
    const Lanes3<float> far{plane(far_off[0], 0), plane(far_off[1], 1), plane(far_off[2], 2)};
    return slab_test<ScalarLanes>(near, far, {inv[0], inv[1], inv[2]}, {inv_far[0], inv_far[1], inv_far[2]}, tnear,
                                  tfar, t0_out);
  }
};

}  // namespace tracer
