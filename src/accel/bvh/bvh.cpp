// BVH traversal, statistics and validation. The build is in bvh_builder.cpp.
#include "accel/bvh/bvh.hpp"

#include <sstream>

namespace tracer {

namespace {
struct ChildHits {
  bool a, b;     // whether the first and second child's boxes are entered within [tnear, tfar]
  float ta, tb;  // their entry distances
};

// The step both traversals take at an interior node: its two children's boxes tested from the
// parent, and what each child's visit will read requested now, so the loads of the near and the
// far path overlap (trees larger than L2 wait on dependent node loads).
inline ChildHits test_children(const BvhNode& parent, const BvhNode* nodes, const Triangle* tris, const RayBoxTest& box,
                               float tnear, float tfar) {
  const BvhNode& a = nodes[parent.index];
  const BvhNode& b = nodes[parent.index + 1];
  prefetch_child(a, nodes, tris);
  prefetch_child(b, nodes, tris);
  ChildHits h;
  h.a = box.hit(a, tnear, tfar, h.ta);
  h.b = box.hit(b, tnear, tfar, h.tb);
  return h;
}
}  // namespace

bool Bvh::intersect(const Ray& ray, Hit& hit) const {
  hit = Hit{};
  hit.t = ray.tfar;
  if (nodes_.empty()) return false;
  const RayShear shear(ray);
  const RayBoxTest box(ray);
  if (box.enter(nodes_[0], ray.tnear, hit.t) == kInfinity) return false;

  struct Entry {
    uint32_t node;
    float t;
  };
  Entry stack[kMaxDepth + 2];
  int sp = 0;
  uint32_t current = 0;
  for (;;) {
    const BvhNode& node = nodes_[current];
    if (node.leaf()) {
      intersect_range(shear, tris_.data(), ids_.data(), node.index, node.index + node.count, ray.tnear, hit);
    } else {
      const ChildHits c = test_children(node, nodes_.data(), tris_.data(), box, ray.tnear, hit.t);
      // Branches, not selects, decide the order: a predicted branch lets the next node's load
      // start before the box tests finish, where a select would make it wait for them
      // (selects here were measured slower: docs/bench/LOG.md).
      if (c.a) {
        if (!c.b) {
          current = node.index;
        } else if (c.tb < c.ta) {
          stack[sp++] = {node.index, c.ta};
          current = node.index + 1;
        } else {
          stack[sp++] = {node.index + 1, c.tb};
          current = node.index;
        }
        continue;
      }
      if (c.b) {
        current = node.index + 1;
        continue;
      }
    }
    // Pop, skipping nodes whose entry is now beyond the closest hit (<=: ties still count).
    for (;;) {
      if (sp == 0) goto done;
      const Entry e = stack[--sp];
      if (e.t <= hit.t * SlabGuards::kTieGuard) {
        current = e.node;
        break;
      }
    }
  }
done:
  return finish_hit(*scene_, hit);
}

// Any hit below `node`, whose own box the caller has already found the ray entering.
inline bool Bvh::occluded_below(uint32_t node, const Ray& ray, const RayShear& shear, const RayBoxTest& box) const {
  uint32_t stack[kMaxDepth + 2];
  int sp = 0;
  uint32_t current = node;
  for (;;) {
    const BvhNode& n = nodes_[current];
    if (n.leaf()) {
      TriangleHit th;
      for (uint32_t i = n.index, end = n.index + n.count; i < end; ++i) {
        if (intersect_triangle(shear, tris_[i], ray.tnear, ray.tfar, th)) return true;
      }
    } else {
      // Children are tested from the parent. Any hit ends the query, so no order is needed:
      // the left child goes first, the right one is pushed when both are entered. Branches
      // choose the next node, as in intersect().
      const ChildHits c = test_children(n, nodes_.data(), tris_.data(), box, ray.tnear, ray.tfar);
      if (c.a) {
        stack[sp] = n.index + 1;
        sp += int(c.b);
        current = n.index;
        continue;
      }
      if (c.b) {
        current = n.index + 1;
        continue;
      }
    }
    if (sp == 0) return false;
    current = stack[--sp];
  }
}

bool Bvh::occluded_subtree(uint32_t node, const Ray& ray, const RayShear& shear, const RayBoxTest& box) const {
  return occluded_below(node, ray, shear, box);
}

bool Bvh::occluded(const Ray& ray) const {
  if (nodes_.empty()) return false;
  const RayShear shear(ray);
  const RayBoxTest box(ray);
  if (box.enter(nodes_[0], ray.tnear, ray.tfar) == kInfinity) return false;
  return occluded_below(0, ray, shear, box);
}

bool Bvh::occluded_from(const Ray& ray, uint32_t origin) const {
  if (origin >= leaf_of_.size() || leaf_of_[origin] == kInvalidIndex) return occluded(ray);
  const RayShear shear(ray);
  const RayBoxTest box(ray);
  // A ray that misses the scene's box (leaving an outer surface outwards) is answered at once,
  // as top-down traversal would.
  if (box.enter(nodes_[0], ray.tnear, ray.tfar) == kInfinity) return false;
  // Every node off the path from the root to `origin`'s leaf lies below exactly one sibling of
  // that path, so the leaf plus those siblings' subtrees cover the whole tree.
  uint32_t node = leaf_of_[origin];
  if (occluded_below(node, ray, shear, box)) return true;
  while (node != 0) {
    const uint32_t sibling = node ^ 1u;
    node = pair_parent_[node >> 1];
    float t0;
    if (box.hit(nodes_[sibling], ray.tnear, ray.tfar, t0) && occluded_below(sibling, ray, shear, box)) return true;
  }
  return false;
}

BvhStats Bvh::stats() const {
  BvhStats s;
  s.nodes = nodes_.size();
  if (nodes_.empty()) return s;
  const double root_area = std::max(1e-30f, Aabb{nodes_[0].lo, nodes_[0].hi}.half_area());
  struct Item {
    uint32_t node;
    size_t depth;
  };
  std::vector<Item> stack{{0, 1}};
  size_t leaf_tris = 0;
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    const BvhNode& n = nodes_[it.node];
    s.max_depth = std::max(s.max_depth, it.depth);
    const double rel_area = Aabb{n.lo, n.hi}.half_area() / root_area;
    if (n.leaf()) {
      ++s.leaves;
      leaf_tris += n.count;
      s.max_leaf_size = std::max<size_t>(s.max_leaf_size, n.count);
      s.sah_cost += rel_area * n.count * options_.intersection_cost;
    } else {
      s.sah_cost += rel_area * options_.traversal_cost;
      stack.push_back({n.index, it.depth + 1});
      stack.push_back({n.index + 1, it.depth + 1});
    }
  }
  s.avg_leaf_size = s.leaves ? double(leaf_tris) / double(s.leaves) : 0.0;
  return s;
}

std::string Bvh::validate() const {
  std::ostringstream err;
  if (nodes_.empty()) return tris_.empty() ? "" : "triangles but no nodes";
  std::vector<uint32_t> seen(scene_->size(), 0);
  struct Item {
    uint32_t node;
    size_t depth;
  };
  std::vector<Item> stack{{0, 1}};
  std::vector<uint32_t> visits(nodes_.size(), 0);
  const size_t leaf_limit = options_.split == BvhSplit::Median ? 2 : size_t(options_.max_leaf);
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    if (it.node >= nodes_.size()) return "node index out of range";
    if (++visits[it.node] > 1) return "node " + std::to_string(it.node) + " reached twice";
    if (it.depth > size_t(kMaxDepth)) return "depth exceeds kMaxDepth";
    const BvhNode& n = nodes_[it.node];
    const Aabb box{n.lo, n.hi};
    if (n.leaf()) {
      if (n.count > leaf_limit)
        return "leaf " + std::to_string(it.node) + " holds " + std::to_string(n.count) + " triangles";
      if (size_t(n.index) + n.count > tris_.size()) return "leaf range out of bounds";
      for (uint32_t i = n.index; i < n.index + n.count; ++i) {
        if (!box.contains(tris_[i].bounds()))
          return "leaf " + std::to_string(it.node) + " box does not contain triangle " + std::to_string(ids_[i]);
        if (ids_[i] >= seen.size()) return "triangle id out of range";
        ++seen[ids_[i]];
        if (leaf_of_.size() != seen.size() || leaf_of_[ids_[i]] != it.node)
          return "leaf_of does not name the leaf of triangle " + std::to_string(ids_[i]);
        if (!(scene_->triangles[ids_[i]].v0 == tris_[i].v0)) return "reordered triangle differs from scene";
      }
    } else {
      if (size_t(n.index) + 1 >= nodes_.size()) return "child index out of range";
      if (n.index % 2 != 0 || pair_parent_.size() <= n.index / 2 || pair_parent_[n.index / 2] != it.node) {
        return "node " + std::to_string(it.node) + " is not its children's recorded parent";
      }
      for (uint32_t c = n.index; c <= n.index + 1; ++c) {
        if (!box.contains(Aabb{nodes_[c].lo, nodes_[c].hi}))
          return "node " + std::to_string(it.node) + " does not contain child " + std::to_string(c);
        stack.push_back({c, it.depth + 1});
      }
    }
  }
  for (size_t i = 0; i < seen.size(); ++i) {
    const uint32_t expected = scene_->triangles[i].degenerate() ? 0 : 1;
    if (expected == 0 && leaf_of_.size() == seen.size() && leaf_of_[i] != kInvalidIndex)
      return "degenerate triangle " + std::to_string(i) + " has a leaf";
    if (seen[i] != expected) {
      err << "triangle " << i << " appears in " << seen[i] << " leaves, expected " << expected;
      return err.str();
    }
  }
  for (size_t i = 0; i < visits.size(); ++i) {
    if (i != 1 && visits[i] != 1) return "node " + std::to_string(i) + " unreachable";
  }
  return "";
}

}  // namespace tracer
