// Binary BVH: 32-byte nodes in one array, siblings adjacent, triangles reordered so each leaf is a
// contiguous run. Traversal is iterative, nearest child first, with a conservative slab test.
#pragma once

#include <cstdint>
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

  const std::vector<BvhNode>& nodes() const { return nodes_; }
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
  std::vector<BvhNode> nodes_;
  std::vector<Triangle> tris_;
  std::vector<uint32_t> ids_;
};

// Slab test against a box with a per-ray reciprocal direction. Zero direction components get a
// huge finite reciprocal, so no 0*inf NaN arises for origins on a slab plane; the far distance is
// scaled up by 1 + 2*gamma(3) (Ize 2013) so rounding can never cull a box the ray touches.
struct RayBoxTest {
  Vec3 org, inv;
  explicit RayBoxTest(const Ray& r) : org(r.org) {
    const auto rcp = [](float d) { return std::fabs(d) < 1e-20f ? std::copysign(1e20f, d) : 1.0f / d; };
    inv = {rcp(r.dir.x), rcp(r.dir.y), rcp(r.dir.z)};
  }
  // Entry distance, or +inf on a miss.
  float enter(const Vec3& lo, const Vec3& hi, float tnear, float tfar) const {
    constexpr float kGuard = 1.0f + 2.0f * 3.0f * 0x1p-24f / (1.0f - 3.0f * 0x1p-24f);
    const float tx0 = (lo.x - org.x) * inv.x, tx1 = (hi.x - org.x) * inv.x;
    const float ty0 = (lo.y - org.y) * inv.y, ty1 = (hi.y - org.y) * inv.y;
    const float tz0 = (lo.z - org.z) * inv.z, tz1 = (hi.z - org.z) * inv.z;
    const float tmin = std::max(std::max(std::min(tx0, tx1), std::min(ty0, ty1)), std::max(std::min(tz0, tz1), tnear));
    const float tmax = std::min(std::min(std::max(tx0, tx1), std::max(ty0, ty1)), std::max(tz0, tz1)) * kGuard;
    return (tmin <= tmax && tmin <= tfar) ? tmin : kInfinity;
  }
};

}  // namespace tracer
