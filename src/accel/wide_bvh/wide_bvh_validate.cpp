// The 8-wide BVH's validator: every child box contains its subtree, every non-degenerate
// triangle is in exactly one leaf (with spatial splits: in at least one, its leaves' boxes
// covering its box), empty slots come after the used ones.
#include <cmath>
#include <string>
#include <vector>

#include "accel/wide_bvh/wide_bvh.hpp"

namespace tracer {

std::string WideBvh::validate() const {
  const uint32_t first = range_.first, end = range_.first + range_.count;
  if (nodes_.empty()) {
    for (uint32_t i = first; i < end; ++i) {
      if (!scene_->triangles[i].degenerate()) return "triangles but no nodes";
    }
    return "";
  }
  std::vector<uint32_t> seen(scene_->size(), 0);
  std::vector<Aabb> covered(spatial_splits_ ? scene_->size() : 0);  // by its leaves' boxes
  std::vector<uint32_t> visits(nodes_.size(), 0);
  std::vector<uint32_t> stack{0};
  // Every triangle below a child must lie in that child's box; check leaf by leaf.
  struct Pending {
    uint32_t node;
    Aabb box;
  };
  std::vector<Pending> work{{0, bounds_}};  // the root's children lie in the tree's bounds
  while (!work.empty()) {
    const Pending p = work.back();
    work.pop_back();
    if (p.node >= nodes_.size()) return "node index out of range";
    if (++visits[p.node] > 1) return "node " + std::to_string(p.node) + " reached twice";
    const WideNode& n = nodes_[p.node];
    bool empty_seen = false;  // traversals stop at the first empty slot
    for (int i = 0; i < kWideWidth; ++i) {
      const Aabb box{{n.lo_x[i], n.lo_y[i], n.lo_z[i]}, {n.hi_x[i], n.hi_y[i], n.hi_z[i]}};
      if (box.empty()) {
        if (n.count[i] != 0 || n.child[i] != 0) return "empty slot with contents";
        empty_seen = true;
        continue;
      }
      if (empty_seen) return "used slot after an empty one";
      if (!p.box.contains(box)) return "child box outside its parent's box";
      if (n.count[i] > 0) {
        if (n.child[i] >= packs_.size() || n.count[i] > uint32_t(kWideWidth)) return "leaf pack out of range";
        const TrianglePack& pk = packs_[n.child[i]];
        for (uint32_t lane = 0; lane < uint32_t(kWideWidth); ++lane) {
          if (lane >= n.count[i]) {
            if (pk.id[lane] != kInvalidIndex || !std::isnan(pk.v[0][0][lane])) return "padding lane not empty";
            continue;
          }
          const uint32_t k = pk.id[lane];
          if (k < first || k >= end) return "pack lane's triangle out of range";
          const Triangle& t = scene_->triangles[k];
          if (pk.v[0][0][lane] != t.v0.x || pk.v[2][2][lane] != t.v2.z) return "pack lane differs from its triangle";
          if (spatial_splits_) {
            const Aabb tb = t.bounds();
            const Aabb part{max(box.lo, tb.lo), min(box.hi, tb.hi)};
            if (part.empty()) return "leaf box misses triangle " + std::to_string(k);
            covered[k].extend(part);
          } else if (!box.contains(t.bounds())) {
            return "leaf box does not contain triangle " + std::to_string(k);
          }
          ++seen[k];
        }
      } else {
        work.push_back({n.child[i], box});
      }
    }
  }
  for (size_t i = first; i < end; ++i) {
    const bool degenerate = scene_->triangles[i].degenerate();
    const bool right = spatial_splits_ ? (seen[i] > 0) != degenerate : seen[i] == (degenerate ? 0u : 1u);
    if (!right) return "triangle " + std::to_string(i) + " appears in " + std::to_string(seen[i]) + " leaves";
    if (spatial_splits_ && !degenerate && !covered[i].contains(scene_->triangles[i].bounds()))
      return "the leaves of triangle " + std::to_string(i) + " do not cover it";
  }
  for (size_t i = 0; i < visits.size(); ++i) {
    if (visits[i] != 1) return "node " + std::to_string(i) + " unreachable";
  }
  return "";
}

}  // namespace tracer
