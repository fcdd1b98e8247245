// The binary BVH's builder: the study's median split and a binned SAH (both in PrimSplitter),
// each built sequentially or in parallel (std::async fork-join, a mutex-guarded job queue, or
// oneTBB tasks).
//
// Determinism: every split is a pure function of the primitive range it is given (PrimSplitter),
// so all builders produce the same tree. Nodes are first written into a scratch array in
// whatever order threads reach them, then flattened depth-first, which fixes the final layout
// independently of scheduling.
#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <memory>
#include <utility>

#include "accel/builders/prim_split.hpp"
#include "accel/bvh/bvh.hpp"

namespace tracer {
namespace {

constexpr uint32_t kParallelSubtree = 4096;  // below this a subtree is built by one thread
constexpr uint32_t kCopyBlock = 16384;       // block size of the parallel triangle copy

struct BuildNode {
  PrimRange range;
  uint32_t left = kInvalidIndex;  // children at left and left+1, or kInvalidIndex for a leaf
  uint32_t subtree = 0;           // nodes in this subtree, itself included; 0 until its build ends
};

class BvhBuilder {
 public:
  BvhBuilder(const Scene& scene, const BvhBuildOptions& options, const Executor& exec)
      : splitter_(scene, options, exec), exec_(exec) {
    const uint32_t n = splitter_.count();
    // Left uninitialised (implicit-lifetime BuildNodes from malloc): every slot is written before
    // it is read, and zeroing 2N nodes cost more than the top-level splits.
    nodes_.reset(static_cast<BuildNode*>(std::malloc(std::max<size_t>(1, 2 * size_t(n)) * sizeof(BuildNode))));
    if (!nodes_) throw std::bad_alloc();
  }

  void build() {
    if (splitter_.count() == 0) return;
    nodes_[0] = BuildNode{splitter_.root()};
    node_count_ = 1;
    build_node(0);
  }

  // Depth-first flattening into the final layout, children adjacent; `ids` receives the scene
  // triangle index of every leaf slot. Each subtree's place follows from its size alone, so the
  // tasks build flattens its large subtrees in parallel into the same layout.
  // `pair_parent` receives each sibling pair's parent, `leaf_of` (sized to the scene) each scene
  // triangle's leaf.
  void flatten(BvhNodeArray& out, std::vector<uint32_t>& ids, std::vector<uint32_t>& pair_parent,
               std::vector<uint32_t>& leaf_of) {
    const uint32_t count = splitter_.count();
    ids.resize(count);
    // subtree_size() also fills in the sizes the queue build left unknown at the top.
    out.resize(count == 0 ? 0 : subtree_size(0) + 1);  // + the padding node
    pair_parent.assign((out.size() + 1) / 2, 0);
    if (count == 0) return;
    out[1] = BvhNode{{}, 0, {}, 0};  // padding: children pairs start at even indices
    const Output o{out.data(), ids.data(), pair_parent.data(), leaf_of.data()};
    place(o, 0, 0, 2, exec_.data_parallel());
  }

 private:
  // Builds everything below `id` on this thread. The descendants' build nodes go to one block
  // reserved up front (n primitives make at most 2n - 2 of them), so threads building different
  // subtrees never write neighbouring nodes (no false sharing) and take no atomic per node.
  void build_subtree(uint32_t id) {
    const BuildNode& n = nodes_[id];
    uint32_t cursor = n.range.size() > 1 ? node_count_.fetch_add(2 * n.range.size() - 2, std::memory_order_relaxed) : 0;
    build_seq(id, cursor);
  }

  void build_seq(uint32_t id, uint32_t& cursor) {
    if (split(id, false, &cursor)) {
      const uint32_t left = nodes_[id].left;
      build_seq(left, cursor);
      build_seq(left + 1, cursor);
    }
    finish(id);
  }

  // Large subtrees go to the executor's forks (the study's async and queue strategies, or oneTBB
  // tasks); small ones, and every subtree under an executor that does not fork, are built by one
  // thread. Only oneTBB also splits one node's bounds, binning and partitioning, for the few
  // large nodes near the root where there are too few subtrees to go round. The tree is the same
  // under every executor: only which thread builds which subtree differs.
  void build_node(uint32_t id) {
    const BuildNode& n = nodes_[id];
    const uint32_t size = n.range.size();
    if (size < kParallelSubtree || !exec_.forks()) {
      build_subtree(id);
      return;
    }
    if (!split(id, exec_.data_parallel() && size >= PrimSplitter::kParallelSplit)) return finish(id);
    const uint32_t left = nodes_[id].left;
    exec_.fork_join([&] { build_node(left); }, [&] { build_node(left + 1); });
    finish(id);
  }

  // Ends a node's build: records its subtree's size once its children's are known.
  void finish(uint32_t id) {
    BuildNode& n = nodes_[id];
    n.subtree = n.left == kInvalidIndex ? 1 : 1 + nodes_[n.left].subtree + nodes_[n.left + 1].subtree;
  }

  uint32_t subtree_size(uint32_t id) {
    BuildNode& n = nodes_[id];
    if (n.subtree == 0) n.subtree = n.left == kInvalidIndex ? 1 : 1 + subtree_size(n.left) + subtree_size(n.left + 1);
    return n.subtree;
  }

  struct Output {
    BvhNode* nodes;
    uint32_t* ids;
    uint32_t* pair_parent;
    uint32_t* leaf_of;
  };

  // Writes build node `id` to out.nodes[flat] and its descendants, depth first, from [next] on.
  void place(const Output& out, uint32_t id, uint32_t flat, uint32_t next, bool parallel) const {
    const BuildNode& n = nodes_[id];
    BvhNode& f = out.nodes[flat];
    const PrimRange& r = n.range;
    f.lo = r.box.lo;
    f.hi = r.box.hi;
    if (n.left == kInvalidIndex) {
      f.index = r.begin;
      f.count = r.size();
      const PrimRef* refs = splitter_.refs();
      for (uint32_t i = r.begin; i < r.end; ++i) out.ids[i] = refs[i].id();
      std::sort(out.ids + r.begin, out.ids + r.end);  // the partitions' order is not the same on every executor
      for (uint32_t i = r.begin; i < r.end; ++i) out.leaf_of[out.ids[i]] = flat;
      return;
    }
    f.index = next;
    f.count = 0;
    out.pair_parent[next / 2] = flat;
    const uint32_t left = n.left, right_next = next + 2 + (nodes_[left].subtree - 1);
    const auto place_left = [&] { place(out, left, next, next + 2, parallel); };
    const auto place_right = [&] { place(out, left + 1, next + 1, right_next, parallel); };
    if (parallel && r.size() >= kParallelSubtree) {
      exec_.fork_join(place_left, place_right);
    } else {
      place_left();
      place_right();
    }
  }

  // Decides node `id`: a leaf (false) or two children (true), placed at *cursor (which advances)
  // or, without one, wherever the shared node counter says.
  bool split(uint32_t id, bool parallel, uint32_t* cursor = nullptr) {
    BuildNode& node = nodes_[id];
    PrimRange halves[2];
    if (!splitter_.split(node.range, halves, parallel)) return false;
    const uint32_t left =
        cursor ? std::exchange(*cursor, *cursor + 2) : node_count_.fetch_add(2, std::memory_order_relaxed);
    nodes_[left] = BuildNode{halves[0]};
    nodes_[left + 1] = BuildNode{halves[1]};
    node.left = left;
    return true;
  }

  PrimSplitter splitter_;
  struct FreeNodes {
    void operator()(BuildNode* p) const { std::free(p); }
  };
  std::unique_ptr<BuildNode[], FreeNodes> nodes_;
  std::atomic<uint32_t> node_count_{0};
  const Executor& exec_;
};

}  // namespace

Bvh::Bvh(const Scene& scene, const BvhBuildOptions& options)
    : Bvh(scene, options, Executor(options.strategy, options.threads)) {}

Bvh::Bvh(const Scene& scene, const BvhBuildOptions& options_in, const Executor& exec)
    : scene_(&scene), options_(options_in), simd_(SimdDispatch::of(options_in.simd)) {
  options_.split_budget = 0.0f;  // one leaf per triangle (leaf_of)
  const BvhBuildOptions& options = options_;
  exec.run([&] {
    BvhBuilder builder(scene, options, exec);
    builder.build();
    leaf_of_.assign(scene.size(), kInvalidIndex);
    builder.flatten(nodes_, ids_, pair_parent_, leaf_of_);
    tris_.resize(ids_.size());
    const auto copy = [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) tris_[i] = scene.triangles[ids_[i]];
    };
    if (exec.data_parallel() && ids_.size() >= PrimSplitter::kParallelSplit) {
      const size_t blocks = (ids_.size() + kCopyBlock - 1) / kCopyBlock;
      exec.for_each(blocks, [&](size_t k) { copy(k * kCopyBlock, std::min(ids_.size(), (k + 1) * kCopyBlock)); });
    } else {
      copy(0, ids_.size());
    }
  });
  throw_if_cancelled(options.cancel);
}

}  // namespace tracer
