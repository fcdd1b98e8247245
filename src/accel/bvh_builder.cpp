// BVH construction: the study's median split and a binned SAH, each built sequentially or in
// parallel (std::async fork-join, a mutex-guarded job queue, or oneTBB tasks).
//
// Determinism: every split decision is a pure function of the primitive range it is given, and
// the partitions are stable, so all builders produce the same tree. Nodes are first written into
// a scratch array in whatever order threads reach them, then flattened depth-first, which fixes
// the final layout independently of scheduling.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <condition_variable>
#include <deque>
#include <future>
#include <mutex>
#include <thread>

#include "accel/bvh.hpp"
#include "sched/thread_count.hpp"

namespace tracer {
namespace {

constexpr uint32_t kNone = 0xffffffffu;
constexpr uint32_t kParallelSubtree = 4096;   // below this a subtree is built by one thread
constexpr uint32_t kParallelSplit = 65536;    // above this one node's passes run in parallel (tasks)
constexpr uint32_t kPartitionBlock = 16384;   // block size of the parallel stable partition
constexpr uint32_t kMedianFallbackDepth = 64; // SAH switches to object median below this depth
constexpr int kMaxBins = 32;

struct BuildNode {
  Aabb box;
  uint32_t begin = 0, end = 0;
  uint32_t left = kNone;  // children at left and left+1, or kNone for a leaf
  uint32_t depth = 0;
  Aabb cbox;                  // bounds of the centroids
  bool bounds_known = false;  // box and cbox already computed by the parent's partition pass
};

// A triangle's box padded to four lanes for the binning loop.
struct alignas(32) Box4 {
  float lo[4], hi[4];
};

// Box and centroid bounds accumulated four lanes at a time (vectorised min/max).
struct Bounds4 {
  float lo[4], hi[4], clo[4], chi[4];
  Bounds4() {
    for (int k = 0; k < 4; ++k) { lo[k] = clo[k] = kInfinity; hi[k] = chi[k] = -kInfinity; }
  }
  void add(const Box4& box) {
    for (int k = 0; k < 4; ++k) {
      const float c = (box.lo[k] + box.hi[k]) * 0.5f;  // = Aabb::center(), the binning centroid
      lo[k] = box.lo[k] < lo[k] ? box.lo[k] : lo[k];
      hi[k] = box.hi[k] > hi[k] ? box.hi[k] : hi[k];
      clo[k] = c < clo[k] ? c : clo[k];
      chi[k] = c > chi[k] ? c : chi[k];
    }
  }
  void join(const Bounds4& o) {
    for (int k = 0; k < 4; ++k) {
      lo[k] = o.lo[k] < lo[k] ? o.lo[k] : lo[k];
      hi[k] = o.hi[k] > hi[k] ? o.hi[k] : hi[k];
      clo[k] = o.clo[k] < clo[k] ? o.clo[k] : clo[k];
      chi[k] = o.chi[k] > chi[k] ? o.chi[k] : chi[k];
    }
  }
  Aabb box() const { return Aabb{{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}}; }
  Aabb centroids() const { return Aabb{{clo[0], clo[1], clo[2]}, {chi[0], chi[1], chi[2]}}; }
};


class BvhBuilder {
 public:
  BvhBuilder(const Scene& scene, const BvhBuildOptions& options) : options_(options) {
    options_.bins = std::clamp(options_.bins, 2, kMaxBins);
    options_.max_leaf = std::clamp(options_.max_leaf, 1, 255);
    for (uint32_t i = 0; i < scene.size(); ++i) {
      if (!scene.triangles[i].degenerate()) prims_.push_back(i);
    }
    centroids_.resize(scene.size());
    box4_.resize(scene.size());
    for (uint32_t i : prims_) {
      const Aabb b = scene.triangles[i].bounds();
      centroids_[i] = b.center();  // box centre, not vertex mean: it is what binning sees
      box4_[i] = Box4{{b.lo.x, b.lo.y, b.lo.z, 0.0f}, {b.hi.x, b.hi.y, b.hi.z, 0.0f}};
    }
    scratch_.resize(prims_.size());
    nodes_.resize(std::max<size_t>(1, 2 * prims_.size()));
  }

  void build() {
    if (prims_.empty()) return;
    nodes_[0] = BuildNode{{}, 0, uint32_t(prims_.size()), kNone, 0};
    node_count_ = 1;
    const int threads = resolve_thread_count(options_.threads);
    switch (options_.mode) {
      case BuildMode::Seq: build_seq(0); break;
      case BuildMode::Async: build_async(0, async_depth_limit(threads)); break;
      case BuildMode::Queue: build_queue(threads); break;
      case BuildMode::Tasks: {
        tbb::task_arena arena(threads);
        arena.execute([&] { build_tasks(0); });
        publish();
        break;
      }
    }
  }

  // Depth-first flattening into the final layout: children adjacent, leaves pointing into prims_.
  void flatten(BvhNodeArray& out) const {
    out.clear();
    if (prims_.empty()) return;
    out.reserve(node_count_.load() + 1);
    out.push_back({});
    out.push_back(BvhNode{{}, 0, {}, 0});  // padding: children pairs start at even indices
    struct Item { uint32_t build, flat; };
    std::vector<Item> stack{{0, 0}};
    while (!stack.empty()) {
      const Item it = stack.back();
      stack.pop_back();
      const BuildNode& n = nodes_[it.build];
      BvhNode& f = out[it.flat];
      f.lo = n.box.lo;
      f.hi = n.box.hi;
      if (n.left == kNone) {
        f.index = n.begin;
        f.count = n.end - n.begin;
      } else {
        const auto first = static_cast<uint32_t>(out.size());
        f.index = first;
        f.count = 0;
        out.push_back({});
        out.push_back({});
        // Push right first so the left subtree is laid out right after its parent.
        stack.push_back({n.left + 1, first + 1});
        stack.push_back({n.left, first});
      }
    }
  }

  const std::vector<uint32_t>& prims() const { return prims_; }

 private:
  static int async_depth_limit(int threads) {
    // Enough forks to give every thread a subtree, plus one level for balance.
    return std::bit_width(static_cast<unsigned>(threads)) + 1;
  }

  void build_seq(uint32_t id) {
    if (!split(id, false)) return;
    const uint32_t left = nodes_[id].left;
    build_seq(left);
    build_seq(left + 1);
  }

  // The study's v1: one std::async per recursive call, but only near the root and for large
  // subtrees, so it never starts a thread per node.
  void build_async(uint32_t id, int depth_left) {
    if (!split(id, false)) return;
    const uint32_t left = nodes_[id].left;
    const BuildNode& l = nodes_[left];
    if (depth_left > 0 && l.end - l.begin >= kParallelSubtree) {
      auto right = std::async(std::launch::async, [this, left, depth_left] { build_async(left + 1, depth_left - 1); });
      build_async(left, depth_left - 1);
      right.get();
    } else {
      build_seq(left);
      build_seq(left + 1);
    }
  }

  // The study's v2: workers take node jobs from a shared FIFO. The lock covers only push/pop;
  // idle workers sleep on a condition variable until a job arrives or every job has finished.
  void build_queue(int threads) {
    std::mutex mutex;
    std::condition_variable cv;
    std::deque<uint32_t> jobs{0};
    size_t unfinished = 1;  // queued or running
    const auto worker = [&] {
      for (;;) {
        uint32_t id;
        {
          std::unique_lock lock(mutex);
          cv.wait(lock, [&] { return !jobs.empty() || unfinished == 0; });
          if (jobs.empty()) return;
          id = jobs.front();
          jobs.pop_front();
        }
        const BuildNode& n = nodes_[id];
        if (n.end - n.begin < kParallelSubtree) {
          build_seq(id);
        } else if (split(id, false)) {
          const uint32_t left = nodes_[id].left;
          std::lock_guard lock(mutex);
          jobs.push_back(left);
          jobs.push_back(left + 1);
          unfinished += 2;
          cv.notify_all();
        }
        std::lock_guard lock(mutex);
        if (--unfinished == 0) cv.notify_all();
      }
    };
    std::vector<std::thread> pool;
    for (int i = 0; i < threads; ++i) pool.emplace_back(worker);
    for (std::thread& t : pool) t.join();
  }

  // oneTBB: fork-join over subtrees, and data-parallel bounds, binning and partitioning for the
  // few large nodes near the root, where there are too few subtrees to go round.
  void build_tasks(uint32_t id) {
    const BuildNode& n = nodes_[id];
    const uint32_t size = n.end - n.begin;
    if (size < kParallelSubtree) {
      build_seq(id);
      return;
    }
    if (!split(id, size >= kParallelSplit)) return;
    const uint32_t left = nodes_[id].left;
    tbb::parallel_invoke([&] { build_tasks(left); publish(); }, [&] { build_tasks(left + 1); publish(); });
    publish();
  }

  // TBB's own joins happen inside a library ThreadSanitizer cannot see into. Every parallel piece
  // ends with an acq_rel increment of one shared counter and every join does one too, which
  // gives the happens-before edges the joins already guarantee, in a form TSan understands.
  // One atomic per task or data-parallel chunk, never per node or primitive.
  void publish() const { sync_.fetch_add(1, std::memory_order_acq_rel); }

  template <class Body, class T>
  T reduce_range(uint32_t begin, uint32_t end, bool parallel, T init, const Body& body) const {
    if (!parallel) return body(begin, end, init);
    T result = tbb::parallel_reduce(
        tbb::blocked_range<uint32_t>(begin, end, kPartitionBlock), init,
        [&](const tbb::blocked_range<uint32_t>& r, T acc) {
          T out = body(r.begin(), r.end(), acc);
          sync_.fetch_add(1, std::memory_order_acq_rel);
          return out;
        },
        [&](T a, const T& b) {
          sync_.fetch_add(1, std::memory_order_acq_rel);
          a.join(b);
          return a;
        });
    publish();
    return result;
  }

  // Decides node `id`: a leaf (false) or two children appended to nodes_ (true).
  bool split(uint32_t id, bool parallel) {
    BuildNode& node = nodes_[id];
    const uint32_t begin = node.begin, end = node.end, count = end - begin;
    if (!node.bounds_known) {
      const Bounds4 b = reduce_range(begin, end, parallel, Bounds4{}, [&](uint32_t from, uint32_t to, Bounds4 acc) {
        for (uint32_t i = from; i < to; ++i) acc.add(box4_[prims_[i]]);
        return acc;
      });
      node.box = b.box();
      node.cbox = b.centroids();
      node.bounds_known = true;
    }
    uint32_t mid;
    Bounds4 child_bounds[2];
    bool children_known = false;
    if (options_.split == BvhSplit::Median) {
      if (count <= 2) return false;  // the study's leaves of one or two triangles
      mid = median_split(begin, end, static_cast<int>(node.depth % 3));
    } else {
      if (count <= 1) return false;
      const Vec3 extent = node.cbox.extent();
      if (node.depth >= kMedianFallbackDepth || max_component(extent) <= 0.0f) {
        // Nothing to bin (all centroids equal) or pathologically deep: halve by count.
        if (count <= uint32_t(options_.max_leaf) && max_component(extent) <= 0.0f) return false;
        mid = median_split(begin, end, max_dimension(extent));
      } else {
        const auto sah = sah_split(node, node.cbox, parallel);
        if (sah.axis < 0) {
          if (count <= uint32_t(options_.max_leaf)) return false;
          mid = median_split(begin, end, max_dimension(extent));
        } else {
          const float leaf_cost = options_.intersection_cost * float(count);
          if (count <= uint32_t(options_.max_leaf) && leaf_cost <= sah.cost) return false;
          const Binner binner(node.cbox, sah.bins);
          Bounds4 lb, rb;
          mid = partition(begin, end, begin + sah.left_count, parallel, lb, rb, [&](uint32_t prim) {
            return binner(centroids_[prim][sah.axis], sah.axis) < sah.split_bin;
          });
          child_bounds[0] = lb;
          child_bounds[1] = rb;
          children_known = true;
        }
      }
    }
    const uint32_t left = node_count_.fetch_add(2, std::memory_order_relaxed);
    nodes_[left] = BuildNode{{}, begin, mid, kNone, node.depth + 1};
    nodes_[left + 1] = BuildNode{{}, mid, end, kNone, node.depth + 1};
    if (children_known) {
      for (int c = 0; c < 2; ++c) {
        nodes_[left + c].box = child_bounds[c].box();
        nodes_[left + c].cbox = child_bounds[c].centroids();
        nodes_[left + c].bounds_known = true;
      }
    }
    node.left = left;
    return true;
  }

  uint32_t median_split(uint32_t begin, uint32_t end, int axis) {
    const uint32_t mid = begin + (end - begin) / 2;
    // Ties broken by triangle index so the order is fully defined.
    std::nth_element(prims_.begin() + begin, prims_.begin() + mid, prims_.begin() + end, [&](uint32_t a, uint32_t b) {
      const float ca = centroids_[a][axis], cb = centroids_[b][axis];
      return ca < cb || (ca == cb && a < b);
    });
    return mid;
  }

  struct SahChoice { int axis = -1; int split_bin = 0; float cost = 0.0f; int bins = 0; uint32_t left_count = 0; };

  // Plain floats so a BinSet is trivially constructible: only the `nb` bins in use are
  // initialised, which matters because most nodes are small.
  // Four lanes (the fourth unused) so each min/max below compiles to one SSE instruction.
  struct alignas(16) RawBin {
    float lo[4], hi[4];
    uint32_t count;
    void reset() {
      for (int k = 0; k < 4; ++k) { lo[k] = kInfinity; hi[k] = -kInfinity; }
      count = 0;
    }
    void add(const Box4& b) {
      for (int k = 0; k < 4; ++k) lo[k] = b.lo[k] < lo[k] ? b.lo[k] : lo[k];
      for (int k = 0; k < 4; ++k) hi[k] = b.hi[k] > hi[k] ? b.hi[k] : hi[k];
      ++count;
    }
    void add(const RawBin& o) {
      for (int k = 0; k < 4; ++k) lo[k] = o.lo[k] < lo[k] ? o.lo[k] : lo[k];
      for (int k = 0; k < 4; ++k) hi[k] = o.hi[k] > hi[k] ? o.hi[k] : hi[k];
      count += o.count;
    }
    Aabb box() const { return Aabb{{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}}; }
  };

  struct BinSet {
    int nb;
    RawBin bins[3][kMaxBins];
    explicit BinSet(int n) : nb(n) {
      for (auto& axis : bins) for (int b = 0; b < nb; ++b) axis[b].reset();
    }
    void join(const BinSet& o) {
      for (int a = 0; a < 3; ++a) for (int b = 0; b < nb; ++b) bins[a][b].add(o.bins[a][b]);
    }
  };

  // Maps a centroid coordinate to its bin: precomputed offset and scale, no division per primitive.
  struct Binner {
    float lo[3], scale[3];
    int nb;
    Binner(const Aabb& cbox, int bins) : nb(bins) {
      for (int a = 0; a < 3; ++a) {
        lo[a] = cbox.lo[a];
        const float extent = cbox.hi[a] - cbox.lo[a];
        scale[a] = extent > 0.0f ? float(bins) / extent : 0.0f;
      }
    }
    int operator()(float c, int axis) const {
      return std::clamp(static_cast<int>((c - lo[axis]) * scale[axis]), 0, nb - 1);
    }
  };

  SahChoice sah_split(const BuildNode& node, const Aabb& cbox, bool parallel) const {
    // Fewer bins than primitives buy nothing: small nodes use fewer.
    const int nb = std::clamp(int(node.end - node.begin), 4, options_.bins);
    const Binner binner(cbox, nb);
    const auto fill = [&](uint32_t b, uint32_t e, BinSet& acc) {
      for (uint32_t i = b; i < e; ++i) {
        const uint32_t p = prims_[i];
        const Vec3 c = centroids_[p];
        const Box4& box = box4_[p];
        acc.bins[0][binner(c.x, 0)].add(box);
        acc.bins[1][binner(c.y, 1)].add(box);
        acc.bins[2][binner(c.z, 2)].add(box);
      }
    };
    // Sequentially the bins are filled in place: a BinSet is kilobytes, and copying it per node
    // used to cost more than the binning itself.
    BinSet bins(nb);
    if (parallel) {
      bins = reduce_range(node.begin, node.end, true, BinSet(nb), [&](uint32_t b, uint32_t e, BinSet acc) {
        fill(b, e, acc);
        return acc;
      });
    } else {
      fill(node.begin, node.end, bins);
    }
    SahChoice best;
    best.cost = kInfinity;
    const float inv_area = 1.0f / std::max(node.box.half_area(), 1e-30f);
    for (int a = 0; a < 3; ++a) {
      if (cbox.hi[a] <= cbox.lo[a]) continue;
      float right_cost[kMaxBins];  // area * count of bins [s, nb)
      RawBin acc;
      acc.reset();
      for (int s = nb - 1; s > 0; --s) {
        acc.add(bins.bins[a][s]);
        right_cost[s] = acc.count ? acc.box().half_area() * float(acc.count) : kInfinity;
      }
      acc.reset();
      for (int s = 1; s < nb; ++s) {
        acc.add(bins.bins[a][s - 1]);
        if (acc.count == 0) continue;
        const float cost = options_.traversal_cost +
                           options_.intersection_cost * (acc.box().half_area() * float(acc.count) + right_cost[s]) * inv_area;
        if (cost < best.cost) best = {a, s, cost, nb, acc.count};
      }
    }
    if (!(best.cost < kInfinity)) best.axis = -1;
    best.bins = nb;
    return best;
  }

  // Stable partition of prims_[begin, end) by `pred`, whose true count the binning already gave
  // (`mid` = begin + that count), gathering each side's box and centroid bounds on the way so
  // the children need no bounds pass of their own. The parallel path computes the same
  // permutation and bounds as the sequential one.
  template <class Pred>
  uint32_t partition(uint32_t begin, uint32_t end, uint32_t mid, bool parallel, Bounds4& lb, Bounds4& rb, const Pred& pred) {
    if (!parallel) {
      uint32_t l = begin, r = mid;
      for (uint32_t i = begin; i < end; ++i) {
        const uint32_t p = prims_[i];
        if (pred(p)) {
          scratch_[l++] = p;
          lb.add(box4_[p]);
        } else {
          scratch_[r++] = p;
          rb.add(box4_[p]);
        }
      }
      std::copy(scratch_.begin() + begin, scratch_.begin() + end, prims_.begin() + begin);
      return mid;
    }
    const uint32_t blocks = (end - begin + kPartitionBlock - 1) / kPartitionBlock;
    std::vector<uint32_t> left_counts(blocks + 1, 0);
    tbb::parallel_for(0u, blocks, [&](uint32_t k) {
      const uint32_t b = begin + k * kPartitionBlock, e = std::min(end, b + kPartitionBlock);
      uint32_t c = 0;
      for (uint32_t i = b; i < e; ++i) c += pred(prims_[i]) ? 1 : 0;
      left_counts[k + 1] = c;
      publish();
    });
    publish();
    for (uint32_t k = 0; k < blocks; ++k) left_counts[k + 1] += left_counts[k];
    std::vector<Bounds4> block_l(blocks), block_r(blocks);
    tbb::parallel_for(0u, blocks, [&](uint32_t k) {
      const uint32_t b = begin + k * kPartitionBlock, e = std::min(end, b + kPartitionBlock);
      uint32_t l = begin + left_counts[k];
      uint32_t r = mid + (b - begin) - left_counts[k];  // rights before this block
      for (uint32_t i = b; i < e; ++i) {
        const uint32_t p = prims_[i];
        if (pred(p)) {
          scratch_[l++] = p;
          block_l[k].add(box4_[p]);
        } else {
          scratch_[r++] = p;
          block_r[k].add(box4_[p]);
        }
      }
      publish();
    });
    publish();
    for (uint32_t k = 0; k < blocks; ++k) {
      lb.join(block_l[k]);
      rb.join(block_r[k]);
    }
    tbb::parallel_for(tbb::blocked_range<uint32_t>(begin, end, kPartitionBlock), [&](const tbb::blocked_range<uint32_t>& r) {
      std::copy(scratch_.begin() + r.begin(), scratch_.begin() + r.end(), prims_.begin() + r.begin());
      publish();
    });
    publish();
    return mid;
  }

  BvhBuildOptions options_;
  std::vector<uint32_t> prims_, scratch_;
  std::vector<Box4> box4_;
  std::vector<Vec3> centroids_;
  std::vector<BuildNode> nodes_;
  std::atomic<uint32_t> node_count_{0};
  mutable std::atomic<uint64_t> sync_{0};
};

}  // namespace

Bvh::Bvh(const Scene& scene, const BvhBuildOptions& options) : scene_(&scene), options_(options) {
  BvhBuilder builder(scene, options);
  builder.build();
  builder.flatten(nodes_);
  ids_ = builder.prims();
  tris_.reserve(ids_.size());
  for (uint32_t id : ids_) tris_.push_back(scene.triangles[id]);
}

}  // namespace tracer
