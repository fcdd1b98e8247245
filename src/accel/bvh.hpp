// Binary BVH: 32-byte nodes in one array, siblings adjacent, triangles reordered so each leaf is a
// contiguous run. Traversal is iterative, nearest child first, with a conservative slab test.
#pragma once

#include <cstdint>
#include <new>
#include <string>
#include <vector>

#include "accel/triangle_test.hpp"
#include "math/aabb.hpp"
#include "scene/scene.hpp"

namespace tracer {

enum class BvhSplit { Median, Sah };
enum class BuildMode { Seq, Async, Queue, Tasks };

struct BvhBuildOptions {
  BvhSplit split = BvhSplit::Sah;
  BuildMode mode = BuildMode::Seq;
  int threads = 0;       // 0: all hardware threads (parallel modes only)
  int max_leaf = 4;      // SAH: largest leaf; the median split always makes leaves of 1-2
  int bins = 16;         // SAH bins per axis
  float traversal_cost = 1.0f;
  float intersection_cost = 1.0f;
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

// Cache-line aligned storage: with sibling pairs at even indices, each pair is one 64-byte line.
template <class T>
struct CacheAlignedAllocator {
  using value_type = T;
  CacheAlignedAllocator() = default;
  template <class U>
  CacheAlignedAllocator(const CacheAlignedAllocator<U>&) {}
  T* allocate(size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t{64})); }
  void deallocate(T* p, size_t) { ::operator delete(p, std::align_val_t{64}); }
  template <class U>
  bool operator==(const CacheAlignedAllocator<U>&) const { return true; }
};

using BvhNodeArray = std::vector<BvhNode, CacheAlignedAllocator<BvhNode>>;

struct BvhStats {
  size_t nodes = 0, leaves = 0, max_depth = 0, max_leaf_size = 0;
  double sah_cost = 0.0;  // expected cost per ray, in the builder's cost units
  double avg_leaf_size = 0.0;
};

class Bvh {
 public:
  static constexpr int kMaxDepth = 96;  // the builder guarantees it; traversal stacks rely on it

  Bvh(const Scene& scene, const BvhBuildOptions& options);

  bool intersect(const Ray& ray, Hit& hit) const;
  bool occluded(const Ray& ray) const;

  // nodes()[0] is the root; nodes()[1] is padding so sibling pairs start at even indices.
  const BvhNodeArray& nodes() const { return nodes_; }
  const std::vector<Triangle>& triangles() const { return tris_; }
  const std::vector<uint32_t>& triangle_ids() const { return ids_; }  // scene index per slot
  const BvhBuildOptions& options() const { return options_; }
  const Scene& scene() const { return *scene_; }
  BvhStats stats() const;
  size_t memory_bytes() const {
    return nodes_.size() * sizeof(BvhNode) + tris_.size() * sizeof(Triangle) + ids_.size() * sizeof(uint32_t);
  }
  // Checks the tree's invariants; returns an empty string when they hold, else the first violation.
  std::string validate() const;

 private:
  const Scene* scene_;
  BvhBuildOptions options_;
  BvhNodeArray nodes_;
  std::vector<Triangle> tris_;
  std::vector<uint32_t> ids_;
};

// Slab test with a per-ray reciprocal direction (Williams et al. 2005, as pbrt does it): a zero
// direction component gives an infinite reciprocal, and an origin exactly on that slab's plane
// gives 0*inf = NaN, which the comparisons below drop, so such a slab never culls. The far
// distance is scaled by 1 + 2*gamma(3) (Ize 2013) so rounding never culls a box the ray touches.
struct RayBoxTest {
  // Boxes are also kept when entered up to ~16 ulps beyond tfar: a box's entry distance and a
  // triangle's t round differently, and a triangle hit at exactly the current closest t must
  // still be reached so ties resolve the same way as in brute force.
  static constexpr float kTieGuard = 1.0f + 0x1p-20f;
  Vec3 org, inv;
  bool neg_x, neg_y, neg_z;
  explicit RayBoxTest(const Ray& r) : org(r.org) {
    inv = {1.0f / r.dir.x, 1.0f / r.dir.y, 1.0f / r.dir.z};
    neg_x = std::signbit(inv.x);
    neg_y = std::signbit(inv.y);
    neg_z = std::signbit(inv.z);
  }
  // Entry distance, or +inf on a miss. tnear and tfar must not be NaN.
  float enter(const Vec3& lo, const Vec3& hi, float tnear, float tfar) const {
    float t0;
    return hit(lo, hi, tnear, tfar, t0) ? t0 : kInfinity;
  }
  // Whether the ray enters the box within [tnear, tfar]; t0 receives the entry distance. No
  // branch: traversal turns the two children's answers into its next step with plain arithmetic.
  bool hit(const Vec3& lo, const Vec3& hi, float tnear, float tfar, float& t0_out) const {
    constexpr float kGuard = 1.0f + 2.0f * 3.0f * 0x1p-24f / (1.0f - 3.0f * 0x1p-24f);
    float t0 = tnear, t1 = tfar * kTieGuard;
    const auto slab = [&](float l, float h, float o, float i, bool neg) {
      const float n = ((neg ? h : l) - o) * i;
      const float f = ((neg ? l : h) - o) * i * kGuard;
      t0 = n > t0 ? n : t0;  // NaN n leaves t0 alone
      t1 = f < t1 ? f : t1;  // NaN f leaves t1 alone
    };
    slab(lo.x, hi.x, org.x, inv.x, neg_x);
    slab(lo.y, hi.y, org.y, inv.y, neg_y);
    slab(lo.z, hi.z, org.z, inv.z, neg_z);
    t0_out = t0;
    return t0 <= t1;
  }
};

}  // namespace tracer
