// Building the 8-wide BVH directly: each node takes its primitives, splits the child with the
// largest box (by the same binned SAH as the binary tree, PrimSplitter) until it has eight
// children or every child fits one pack, then builds its inner children, in parallel where they
// are large. This is the tree the binary SAH tree collapsed greedily would give, without building
// the binary tree's lower levels, its flat array, or the collapse.
//
// Determinism: splits do not depend on scheduling, and the nodes, written into a scratch array in
// whatever order threads reach them, are copied depth-first into their final places.
#include <algorithm>
#include <atomic>
#include <stdexcept>
#include <vector>

#include "accel/builders/prim_split.hpp"
#include "accel/builders/wide_tree_build.hpp"
#include "accel/wide_bvh/wide_bvh.hpp"

namespace tracer {

namespace {

constexpr uint32_t kParallelSubtree = 4096;  // below this a subtree is built by one thread
constexpr size_t kPackBlock = 1024;          // packs filled per parallel item

class WideBuilder {
 public:
  WideBuilder(PrimSplitter& splitter, const BvhBuildOptions& options, const Executor& exec, uint32_t leaf_size)
      : options_(options), exec_(exec), splitter_(splitter), leaf_size_(leaf_size) {
    // Every inner node holds more than one leaf's primitives and at least two children, and one
    // with fewer than eight has only leaves below it, so n references make fewer than n/2 + 2.
    // Left uninitialised: only the nodes taken are touched.
    scratch_ = LargeBuffer<WideNode>(splitter_.capacity() / 2 + 2);
  }

  // Builds the tree into `nodes` and `runs`; returns the bounds of everything in it.
  Aabb build(WideNodeArray& nodes, std::vector<LeafRun>& runs) {
    if (splitter_.count() == 0) return Aabb{};
    PrimRange root = splitter_.root();
    splitter_.bound(root, parallel_split(root));
    used_ = 1;
    build_node(root, 0);
    throw_if_cancelled(options_.cancel);
    if (failed_) throw std::logic_error("8-wide BVH build: a node of more than one pack could not be split");
    nodes.clear();
    nodes.reserve(used_);
    runs.clear();
    place(0, nodes, runs);
    return root.box;
  }

 private:
  // A subtree of at most leaf_size_ primitives becomes one leaf: for triangles, one pack's worth
  // (testing eight lanes costs about what one more level of boxes would, and saves its loads).
  bool packable(const PrimRange& r) const { return r.size() <= leaf_size_; }
  bool parallel_split(const PrimRange& r) const {
    return exec_.data_parallel() && r.size() >= PrimSplitter::kParallelSplit;
  }

  // Builds the node for `range` into scratch_[self] and, below it, its inner children.
  void build_node(PrimRange range, uint32_t self) {
    // Open the largest child until eight children (or only packs) remain: keeps the children's
    // total surface area, and so the expected cost, as low as greedy can.
    PrimRange kids[kWideWidth];
    int count = 1;
    kids[0] = range;
    if (!packable(range) && !open(kids, count, 0)) return;
    while (count < kWideWidth) {
      int best = -1;
      float best_area = -1.0f;
      for (int i = 0; i < count; ++i) {
        const float area = kids[i].box.half_area();
        if (!packable(kids[i]) && area > best_area) {
          best = i;
          best_area = area;
        }
      }
      if (best < 0) break;
      if (!open(kids, count, best)) return;
    }
    // Largest subtree (in triangles) first. Any-hit traversal enters the last slot first, so it
    // tries the smallest subtrees first: few triangles spanning a box as large as their siblings'
    // are large triangles (walls, floors), the likeliest occluders. Embree's builder orders its
    // children the same way; docs/bench/LOG.md measures what it saves on Sponza's AO rays.
    std::stable_sort(kids, kids + count, [](const PrimRange& a, const PrimRange& b) { return a.size() > b.size(); });
    WideNode& w = scratch_[self];
    PrimRange inner[kWideWidth];
    uint32_t inner_slot[kWideWidth];
    int inner_count = 0;
    for (int i = 0; i < kWideWidth; ++i) {
      const bool used = i < count;
      const Aabb& b = kids[i].box;
      w.lo_x[i] = used ? b.lo.x : kInfinity;
      w.lo_y[i] = used ? b.lo.y : kInfinity;
      w.lo_z[i] = used ? b.lo.z : kInfinity;
      w.hi_x[i] = used ? b.hi.x : -kInfinity;
      w.hi_y[i] = used ? b.hi.y : -kInfinity;
      w.hi_z[i] = used ? b.hi.z : -kInfinity;
      w.child[i] = used ? 0 : kInvalidIndex;  // in scratch, an empty slot; 0 once placed
      w.count[i] = 0;
      if (!used) continue;
      if (packable(kids[i])) {
        w.child[i] = kids[i].begin;  // in scratch, a leaf's first primitive
        w.count[i] = kids[i].size();
      } else {
        w.child[i] = used_.fetch_add(1, std::memory_order_relaxed);
        inner[inner_count] = kids[i];
        inner_slot[inner_count++] = w.child[i];
      }
    }
    build_nodes(inner, inner_slot, inner_count);
  }

  // Builds nodes for ranges[0, n) into their slots: large groups as two forked halves.
  void build_nodes(const PrimRange* ranges, const uint32_t* slots, int n) {
    if (n == 0) return;
    if (n == 1) return build_node(ranges[0], slots[0]);
    uint64_t total = 0;
    for (int i = 0; i < n; ++i) total += ranges[i].size();
    if (!exec_.forks() || total < kParallelSubtree) {
      for (int i = 0; i < n; ++i) build_node(ranges[i], slots[i]);
      return;
    }
    const int half = n / 2;
    exec_.fork_join([&] { build_nodes(ranges, slots, half); },
                    [&] { build_nodes(ranges + half, slots + half, n - half); });
  }

  // Replaces kids[i] by its two halves (kids[i], kids[i + 1]); false if it could not be split
  // (the build was cancelled).
  bool open(PrimRange* kids, int& count, int i) {
    PrimRange halves[2];
    if (!splitter_.split(kids[i], halves, parallel_split(kids[i]))) {
      if (!is_cancelled(options_.cancel)) failed_ = true;
      return false;
    }
    std::copy_backward(kids + i + 1, kids + count, kids + count + 1);
    kids[i] = halves[0];
    kids[i + 1] = halves[1];
    ++count;
    return true;
  }

  // Copies scratch node `s` and its subtree, depth first, to the end of `out`, numbering leaf
  // runs in the same order; returns its index there.
  uint32_t place(uint32_t s, WideNodeArray& out, std::vector<LeafRun>& runs) {
    const auto self = static_cast<uint32_t>(out.size());
    out.push_back(scratch_[s]);
    for (int i = 0; i < kWideWidth; ++i) {
      const uint32_t child = out[self].child[i], count = out[self].count[i];
      if (count == 0 && child == kInvalidIndex) {
        out[self].child[i] = 0;
      } else if (count != 0) {
        out[self].child[i] = static_cast<uint32_t>(runs.size());
        runs.push_back({child, count});
      } else {
        const uint32_t placed = place(child, out, runs);  // may reallocate out: index, not reference
        out[self].child[i] = placed;
      }
    }
    return self;
  }

  const BvhBuildOptions& options_;
  const Executor& exec_;
  PrimSplitter& splitter_;
  uint32_t leaf_size_;
  LargeBuffer<WideNode> scratch_;
  std::atomic<uint32_t> used_{0};
  std::atomic<bool> failed_{false};
};

// Fills the packs from the leaf runs, in parallel: each gathers its triangles from the scene, a
// cache miss per triangle on large scenes.
void fill_packs(const Scene& scene, const PrimSplitter& splitter, const std::vector<LeafRun>& runs,
                const Executor& exec, PackArray& packs) {
  packs.resize(runs.size());
  const auto fill = [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k) {
      const LeafRun& r = runs[k];
      uint32_t ids[kWideWidth];
      for (uint32_t j = 0; j < r.count; ++j) ids[j] = splitter.refs()[r.first + j].id();
      // By triangle: the partitions' order is not the same on every executor. At most eight.
      for (uint32_t j = 1; j < r.count; ++j) {
        for (uint32_t m = j; m > 0 && ids[m - 1] > ids[m]; --m) std::swap(ids[m - 1], ids[m]);
      }
      packs[k] = make_triangle_pack(scene.triangles, ids, 0, r.count);
    }
  };
  const auto blocks = uint32_t((runs.size() + kPackBlock - 1) / kPackBlock);
  if (!exec.data_parallel() || blocks < 2) return fill(0, runs.size());
  exec.for_each(blocks, [&](size_t b) { fill(b * kPackBlock, std::min(runs.size(), (b + 1) * kPackBlock)); });
}

}  // namespace

Aabb build_wide_tree(PrimSplitter& splitter, const BvhBuildOptions& options, const Executor& exec, uint32_t leaf_size,
                     WideNodeArray& nodes, std::vector<LeafRun>& runs) {
  return WideBuilder(splitter, options, exec, leaf_size).build(nodes, runs);
}

WideBvh::WideBvh(const Scene& scene, const BvhBuildOptions& options)
    : WideBvh(scene, options, Executor(options.strategy, options.threads)) {}

WideBvh::WideBvh(const Scene& scene, const BvhBuildOptions& options, const Executor& exec)
    : WideBvh(scene, TriangleRange::all(scene), options, exec) {}

WideBvh::WideBvh(const Scene& scene, TriangleRange range, const BvhBuildOptions& options_in, const Executor& exec)
    : scene_(&scene),
      range_(range),
      spatial_splits_(options_in.split_budget > 0.0f),
      simd_(SimdDispatch::of(options_in.simd)) {
  BvhBuildOptions options = options_in;
  // Nodes of more than one pack are always split, so the SAH never weighs a leaf larger than one.
  options.max_leaf = std::min(options.max_leaf, kWideWidth);
  exec.run([&] {
    PrimSplitter splitter(scene, range, options, exec);
    std::vector<LeafRun> runs;
    bounds_ = build_wide_tree(splitter, options, exec, kWideWidth, nodes_, runs);
    fill_packs(scene, splitter, runs, exec, packs_);
  });
}

}  // namespace tracer
