// BVH construction: the study's median split and a binned SAH, each built sequentially or in
// parallel (std::async fork-join, a mutex-guarded job queue, or oneTBB tasks).
//
// Determinism: every split decision is a pure function of the primitive range it is given, and
// the partitions are stable, so all builders produce the same tree. Nodes are first written into
// a scratch array in whatever order threads reach them, then flattened depth-first, which fixes
// the final layout independently of scheduling.
#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdlib>
#include <memory>
#include <utility>

#include <immintrin.h>  // SSE2, part of every x86-64

#include "accel/bvh.hpp"

namespace tracer {
namespace {

constexpr uint32_t kParallelSubtree = 4096;    // below this a subtree is built by one thread
constexpr uint32_t kParallelSplit = 65536;     // above this one node's passes run in parallel (tasks)
constexpr uint32_t kPartitionBlock = 16384;    // block size of the parallel stable partition
constexpr uint32_t kMedianFallbackDepth = 64;  // SAH switches to object median below this depth
constexpr int kMaxBins = 32;

struct BuildNode {
  Aabb box;
  uint32_t begin = 0, end = 0;
  uint32_t left = kInvalidIndex;  // children at left and left+1, or kInvalidIndex for a leaf
  uint32_t depth = 0;
  uint32_t subtree = 0;       // nodes in this subtree, itself included; 0 until its build ends
  Aabb cbox;                  // bounds of the centroids
  bool bounds_known = false;  // box and cbox already computed by the parent's partition pass
  uint8_t buffer = 0;         // which of the two PrimRef buffers holds [begin, end)
};

// One primitive as the builder moves it around: its box in two SSE registers, the triangle's
// scene index in the otherwise unused fourth lane of `lo`. Binning and partitioning stream
// through one array of these, so no pass gathers from per-triangle arrays in random order.
struct alignas(32) PrimRef {
  __m128 lo, hi;  // lane 3 of hi is 0
  static PrimRef make(const Aabb& b, uint32_t id) {
    return {_mm_setr_ps(b.lo.x, b.lo.y, b.lo.z, std::bit_cast<float>(id)), _mm_setr_ps(b.hi.x, b.hi.y, b.hi.z, 0.0f)};
  }
  uint32_t id() const {
    return std::bit_cast<uint32_t>(_mm_cvtss_f32(_mm_shuffle_ps(lo, lo, _MM_SHUFFLE(3, 3, 3, 3))));
  }
  // (lo + hi) / 2 per axis, as Aabb::center() computes it; lane 3 is masked off first so the
  // id's bits never enter arithmetic (they may look like a denormal).
  __m128 center() const {
    const __m128 xyz = _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0));
    return _mm_mul_ps(_mm_add_ps(_mm_and_ps(lo, xyz), hi), _mm_set1_ps(0.5f));
  }
  template <int Axis>
  float center() const {
    const __m128 c = center();
    return _mm_cvtss_f32(_mm_shuffle_ps(c, c, _MM_SHUFFLE(Axis, Axis, Axis, Axis)));
  }
  float center(int axis) const { return axis == 0 ? center<0>() : axis == 1 ? center<1>() : center<2>(); }
};
static_assert(sizeof(PrimRef) == 32);

// Box and centroid bounds accumulated four lanes at a time; lane 3 is meaningless.
struct Bounds4 {
  __m128 lo = _mm_set1_ps(kInfinity), hi = _mm_set1_ps(-kInfinity);
  __m128 clo = _mm_set1_ps(kInfinity), chi = _mm_set1_ps(-kInfinity);
  void add(const PrimRef& r) {
    const __m128 c = r.center();
    lo = _mm_min_ps(lo, r.lo);
    hi = _mm_max_ps(hi, r.hi);
    clo = _mm_min_ps(clo, c);
    chi = _mm_max_ps(chi, c);
  }
  void join(const Bounds4& o) {
    lo = _mm_min_ps(lo, o.lo);
    hi = _mm_max_ps(hi, o.hi);
    clo = _mm_min_ps(clo, o.clo);
    chi = _mm_max_ps(chi, o.chi);
  }
  static Aabb to_aabb(__m128 l, __m128 h) {
    alignas(16) float a[4], b[4];
    _mm_store_ps(a, l);
    _mm_store_ps(b, h);
    return Aabb{{a[0], a[1], a[2]}, {b[0], b[1], b[2]}};
  }
  Aabb box() const { return to_aabb(lo, hi); }
  Aabb centroids() const { return to_aabb(clo, chi); }
};

class BvhBuilder {
 public:
  BvhBuilder(const Scene& scene, const BvhBuildOptions& options, const Executor& exec)
      : options_(options), exec_(exec) {
    options_.bins = std::clamp(options_.bins, 2, kMaxBins);
    options_.max_leaf = std::clamp(options_.max_leaf, 1, 255);
    const auto n = static_cast<uint32_t>(scene.size());
    // Left uninitialised (trivial types; implicit-lifetime BuildNodes from malloc): every slot
    // is written before it is read, and zeroing 2N nodes cost more than the top-level splits.
    for (auto& b : buffers_) b = std::make_unique_for_overwrite<PrimRef[]>(n);
    PrimRef* refs = buffers_[0].get();
    nodes_.reset(static_cast<BuildNode*>(std::malloc(std::max<size_t>(1, 2 * size_t(n)) * sizeof(BuildNode))));
    if (!nodes_) throw std::bad_alloc();
    // Degenerate triangles are left out. In parallel: count per block, then fill at the offsets.
    const auto fill = [&](uint32_t b, uint32_t e, uint32_t out) {
      for (uint32_t i = b; i < e; ++i) {
        if (!scene.triangles[i].degenerate()) refs[out++] = PrimRef::make(scene.triangles[i].bounds(), i);
      }
      return out;
    };
    if (!exec_.data_parallel() || n < kParallelSplit) {
      count_ = fill(0, n, 0);
      return;
    }
    const uint32_t blocks = (n + kPartitionBlock - 1) / kPartitionBlock;
    std::vector<uint32_t> offsets(blocks + 1, 0);
    exec_.for_each(blocks, [&](size_t k) {
      uint32_t c = 0;
      for (uint32_t i = k * kPartitionBlock, e = std::min(n, i + kPartitionBlock); i < e; ++i)
        c += scene.triangles[i].degenerate() ? 0 : 1;
      offsets[k + 1] = c;
    });
    for (uint32_t k = 0; k < blocks; ++k) offsets[k + 1] += offsets[k];
    exec_.for_each(blocks, [&](size_t k) {
      fill(uint32_t(k) * kPartitionBlock, std::min(n, uint32_t(k + 1) * kPartitionBlock), offsets[k]);
    });
    count_ = offsets[blocks];
  }

  void build() {
    if (count_ == 0) return;
    nodes_[0] = BuildNode{{}, 0, count_, kInvalidIndex, 0};
    node_count_ = 1;
    build_node(0);
  }

  // Depth-first flattening into the final layout, children adjacent; `ids` receives the scene
  // triangle index of every leaf slot. Each subtree's place follows from its size alone, so the
  // tasks build flattens its large subtrees in parallel into the same layout.
  // `pair_parent` (if not null) receives each sibling pair's parent, `leaf_of` (if not null,
  // sized to the scene) each scene triangle's leaf.
  void flatten(BvhNodeArray& out, std::vector<uint32_t>& ids, std::vector<uint32_t>* pair_parent,
               std::vector<uint32_t>* leaf_of) {
    ids.resize(count_);
    // subtree_size() also fills in the sizes the queue build left unknown at the top.
    out.resize(count_ == 0 ? 0 : subtree_size(0) + 1);  // + the padding node
    if (pair_parent) pair_parent->assign((out.size() + 1) / 2, 0);
    if (count_ == 0) return;
    out[1] = BvhNode{{}, 0, {}, 0};  // padding: children pairs start at even indices
    const Output o{out.data(), ids.data(), pair_parent ? pair_parent->data() : nullptr,
                   leaf_of ? leaf_of->data() : nullptr};
    place(o, 0, 0, 2, exec_.data_parallel());
  }

 private:
  // Builds everything below `id` on this thread. The descendants' build nodes go to one block
  // reserved up front (n primitives make at most 2n - 2 of them), so threads building different
  // subtrees never write neighbouring nodes (no false sharing) and take no atomic per node.
  void build_subtree(uint32_t id) {
    const BuildNode& n = nodes_[id];
    uint32_t cursor =
        n.end - n.begin > 1 ? node_count_.fetch_add(2 * (n.end - n.begin) - 2, std::memory_order_relaxed) : 0;
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
    const uint32_t size = n.end - n.begin;
    if (size < kParallelSubtree || !exec_.forks()) {
      build_subtree(id);
      return;
    }
    if (!split(id, exec_.data_parallel() && size >= kParallelSplit)) return finish(id);
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
    f.lo = n.box.lo;
    f.hi = n.box.hi;
    if (n.left == kInvalidIndex) {
      f.index = n.begin;
      f.count = n.end - n.begin;
      const PrimRef* refs = buffers_[n.buffer].get();
      for (uint32_t i = n.begin; i < n.end; ++i) {
        out.ids[i] = refs[i].id();
        if (out.leaf_of) out.leaf_of[refs[i].id()] = flat;
      }
      return;
    }
    f.index = next;
    f.count = 0;
    if (out.pair_parent) out.pair_parent[next / 2] = flat;
    const uint32_t left = n.left, right_next = next + 2 + (nodes_[left].subtree - 1);
    const auto place_left = [&] { place(out, left, next, next + 2, parallel); };
    const auto place_right = [&] { place(out, left + 1, next + 1, right_next, parallel); };
    if (parallel && n.end - n.begin >= kParallelSubtree) {
      exec_.fork_join(place_left, place_right);
    } else {
      place_left();
      place_right();
    }
  }

  template <class Body, class T>
  T reduce_range(uint32_t begin, uint32_t end, bool parallel, T init, const Body& body) const {
    if (!parallel) return body(begin, end, init);
    return exec_.reduce(begin, end, kPartitionBlock, init, body);
  }

  // Decides node `id`: a leaf (false) or two children (true), placed at *cursor (which advances)
  // or, without one, wherever the shared node counter says.
  bool split(uint32_t id, bool parallel, uint32_t* cursor = nullptr) {
    if (is_cancelled(options_.cancel)) return false;  // the constructor then throws Cancelled
    BuildNode& node = nodes_[id];
    const uint32_t begin = node.begin, end = node.end, count = end - begin;
    PrimRef* refs = buffers_[node.buffer].get();
    uint8_t child_buffer = node.buffer;  // partitions move the children to the other buffer
    if (!node.bounds_known) {
      const Bounds4 b = reduce_range(begin, end, parallel, Bounds4{}, [&](uint32_t from, uint32_t to, Bounds4 acc) {
        for (uint32_t i = from; i < to; ++i) acc.add(refs[i]);
        return acc;
      });
      node.box = b.box();
      node.cbox = b.centroids();
      node.bounds_known = true;
    }
    uint32_t mid;
    Aabb child_box[2], child_cbox[2];
    bool children_known = false;
    if (options_.split == BvhSplit::Median) {
      if (count <= 2) return false;  // the study's leaves of one or two triangles
      mid = median_split(refs, begin, end, static_cast<int>(node.depth % 3));
    } else {
      if (count <= 1) return false;
      const Vec3 extent = node.cbox.extent();
      if (node.depth >= kMedianFallbackDepth || max_component(extent) <= 0.0f) {
        // Nothing to bin (all centroids equal) or pathologically deep: halve by count.
        if (count <= uint32_t(options_.max_leaf) && max_component(extent) <= 0.0f) return false;
        mid = median_split(refs, begin, end, max_dimension(extent));
      } else {
        const auto sah = sah_split(refs, node, node.cbox, parallel);
        if (sah.axis < 0) {
          if (count <= uint32_t(options_.max_leaf)) return false;
          mid = median_split(refs, begin, end, max_dimension(extent));
        } else {
          const float leaf_cost = options_.intersection_cost * float(count);
          if (count <= uint32_t(options_.max_leaf) && leaf_cost <= sah.cost) return false;
          const Binner binner(node.cbox, sah.bins);
          child_buffer = uint8_t(1 - node.buffer);
          SideCentroids centroids;
          mid = partition(refs, buffers_[child_buffer].get(), begin, end, begin + sah.left_count, parallel, centroids,
                          [&](const PrimRef& prim) { return binner(prim.center(sah.axis), sah.axis) < sah.split_bin; });
          child_box[0] = sah.left_box;
          child_box[1] = sah.right_box;
          child_cbox[0] = Bounds4::to_aabb(centroids.llo, centroids.lhi);
          child_cbox[1] = Bounds4::to_aabb(centroids.rlo, centroids.rhi);
          children_known = true;
        }
      }
    }
    const uint32_t left =
        cursor ? std::exchange(*cursor, *cursor + 2) : node_count_.fetch_add(2, std::memory_order_relaxed);
    nodes_[left] = BuildNode{{}, begin, mid, kInvalidIndex, node.depth + 1};
    nodes_[left + 1] = BuildNode{{}, mid, end, kInvalidIndex, node.depth + 1};
    if (children_known) {
      for (int c = 0; c < 2; ++c) {
        nodes_[left + c].box = child_box[c];
        nodes_[left + c].cbox = child_cbox[c];
        nodes_[left + c].bounds_known = true;
      }
    }
    nodes_[left].buffer = nodes_[left + 1].buffer = child_buffer;
    node.left = left;
    return true;
  }

  uint32_t median_split(PrimRef* refs, uint32_t begin, uint32_t end, int axis) {
    switch (axis) {
      case 0:
        return median_split<0>(refs, begin, end);
      case 1:
        return median_split<1>(refs, begin, end);
      default:
        return median_split<2>(refs, begin, end);
    }
  }
  template <int Axis>
  uint32_t median_split(PrimRef* refs, uint32_t begin, uint32_t end) {
    const uint32_t mid = begin + (end - begin) / 2;
    // Ties broken by triangle index so the order is fully defined.
    std::nth_element(refs + begin, refs + mid, refs + end, [](const PrimRef& a, const PrimRef& b) {
      const float ca = a.center<Axis>(), cb = b.center<Axis>();
      return ca < cb || (ca == cb && a.id() < b.id());
    });
    return mid;
  }

  struct SahChoice {
    int axis = -1;
    int split_bin = 0;
    float cost = 0.0f;
    int bins = 0;
    uint32_t left_count = 0;
    Aabb left_box, right_box;  // the children's boxes: unions of their bins' boxes, exactly
  };

  // Plain floats so a BinSet is trivially constructible: only the `nb` bins in use are
  // initialised, which matters because most nodes are small.
  // Four lanes (the fourth unused) so each min/max below compiles to one SSE instruction.
  struct RawBin {
    __m128 lo, hi;
    uint32_t count;
    void reset() {
      lo = _mm_set1_ps(kInfinity);
      hi = _mm_set1_ps(-kInfinity);
      count = 0;
    }
    void add(const PrimRef& r) {
      lo = _mm_min_ps(lo, r.lo);
      hi = _mm_max_ps(hi, r.hi);
      ++count;
    }
    void add(const RawBin& o) {
      lo = _mm_min_ps(lo, o.lo);
      hi = _mm_max_ps(hi, o.hi);
      count += o.count;
    }
    // Aabb::half_area() of a non-empty bin, summed in the same order, without leaving SSE.
    float half_area() const {
      const __m128 e = _mm_and_ps(_mm_sub_ps(hi, lo), _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0)));
      const __m128 p = _mm_mul_ps(e, _mm_shuffle_ps(e, e, _MM_SHUFFLE(3, 0, 2, 1)));  // xy, yz, zx, 0
      const __m128 xy_yz = _mm_add_ss(p, _mm_shuffle_ps(p, p, _MM_SHUFFLE(1, 1, 1, 1)));
      return _mm_cvtss_f32(_mm_add_ss(xy_yz, _mm_movehl_ps(p, p)));  // (xy + yz) + zx
    }
  };

  struct BinSet {
    int nb;
    RawBin bins[3][kMaxBins];
    explicit BinSet(int n) : nb(n) {
      for (auto& axis : bins)
        for (int b = 0; b < nb; ++b) axis[b].reset();
    }
    void join(const BinSet& o) {
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < nb; ++b) bins[a][b].add(o.bins[a][b]);
    }
  };

  // Maps a centroid coordinate to its bin: precomputed offset and scale, no division per primitive.
  // The float clamp before truncation gives what clamping the truncated int would; both paths
  // below compute the same bin for the same centroid, which the partition relies on.
  struct Binner {
    alignas(16) float lo[4], scale[4];
    float top;
    Binner(const Aabb& cbox, int bins) : top(float(bins - 1)) {
      for (int a = 0; a < 3; ++a) {
        lo[a] = cbox.lo[a];
        const float extent = cbox.hi[a] - cbox.lo[a];
        scale[a] = extent > 0.0f ? float(bins) / extent : 0.0f;
      }
      lo[3] = scale[3] = 0.0f;
    }
    int operator()(float c, int axis) const {
      return static_cast<int>(std::min(std::max((c - lo[axis]) * scale[axis], 0.0f), top));
    }
    // Bins of a centroid on all three axes at once (lane 3 is 0).
    __m128i operator()(__m128 c) const {
      const __m128 x = _mm_mul_ps(_mm_sub_ps(c, _mm_load_ps(lo)), _mm_load_ps(scale));
      return _mm_cvttps_epi32(_mm_min_ps(_mm_max_ps(x, _mm_setzero_ps()), _mm_set1_ps(top)));
    }
  };

  SahChoice sah_split(const PrimRef* refs, const BuildNode& node, const Aabb& cbox, bool parallel) const {
    // Fewer bins than primitives buy nothing: small nodes use fewer.
    const int nb = std::clamp(4 + int(node.end - node.begin) / 16, 4, options_.bins);
    const Binner binner(cbox, nb);
    const auto add = [&](const PrimRef& r, BinSet& acc) {
      alignas(16) int32_t bin[4];
      _mm_store_si128(reinterpret_cast<__m128i*>(bin), binner(r.center()));
      acc.bins[0][bin[0]].add(r);
      acc.bins[1][bin[1]].add(r);
      acc.bins[2][bin[2]].add(r);
    };
    const auto fill = [&](uint32_t b, uint32_t e, BinSet& acc) {
      if (e - b < 256) {
        for (uint32_t i = b; i < e; ++i) add(refs[i], acc);
        return;
      }
      // Neighbouring primitives often land in the same bin; alternating between two bin sets
      // breaks the store-to-load chain through that bin. min/max and counts merge exactly.
      BinSet odd(acc.nb);
      uint32_t i = b;
      for (; i + 1 < e; i += 2) {
        add(refs[i], acc);
        add(refs[i + 1], odd);
      }
      if (i < e) add(refs[i], acc);
      acc.join(odd);
    };
    // Sequentially the bins are filled in place: a BinSet is kilobytes, and copying it per node
    // costs more than the binning itself.
    BinSet bins(nb);
    if (parallel) {
      bins = reduce_range(node.begin, node.end, true, BinSet(nb), [&](uint32_t b, uint32_t e, BinSet acc) {
        fill(b, e, acc);
        return acc;
      });
    } else {
      fill(node.begin, node.end, bins);
    }
    // The sweep compares the split's raw area-count sum, keeping the best in scalars selected with
    // masks (which bin wins is unpredictable, and the compiler turned ?: back into a branch); the
    // cost is formed once, at the end.
    uint32_t best_choice = 0, best_left = 0;  // axis * kMaxBins + bin
    float best_raw = kInfinity;
    for (int a = 0; a < 3; ++a) {
      if (cbox.hi[a] <= cbox.lo[a]) continue;
      float right_cost[kMaxBins];  // area * count of bins [s, nb)
      RawBin acc;
      acc.reset();
      for (int s = nb - 1; s > 0; --s) {
        acc.add(bins.bins[a][s]);
        right_cost[s] = acc.count ? acc.half_area() * float(acc.count) : kInfinity;
      }
      acc.reset();
      for (int s = 1; s < nb; ++s) {
        acc.add(bins.bins[a][s - 1]);
        const float raw = acc.count ? acc.half_area() * float(acc.count) + right_cost[s] : kInfinity;
        const uint32_t better = 0u - uint32_t(raw < best_raw);
        best_raw = std::min(raw, best_raw);
        best_choice = (uint32_t(a * kMaxBins + s) & better) | (best_choice & ~better);
        best_left = (acc.count & better) | (best_left & ~better);
      }
    }
    const float inv_area = 1.0f / std::max(node.box.half_area(), 1e-30f);
    SahChoice best;
    best.axis = int(best_choice / kMaxBins);
    best.split_bin = int(best_choice % kMaxBins);
    best.left_count = best_left;
    best.cost = options_.traversal_cost + options_.intersection_cost * best_raw * inv_area;
    if (!(best_raw < kInfinity)) {
      best.axis = -1;
    } else {
      RawBin l, r;
      l.reset();
      r.reset();
      for (int b = 0; b < best.split_bin; ++b) l.add(bins.bins[best.axis][b]);
      for (int b = best.split_bin; b < nb; ++b) r.add(bins.bins[best.axis][b]);
      best.left_box = Bounds4::to_aabb(l.lo, l.hi);
      best.right_box = Bounds4::to_aabb(r.lo, r.hi);
    }
    best.bins = nb;
    return best;
  }

  // Centroid bounds of the two sides of a partition, accumulated without a branch per primitive.
  struct SideCentroids {
    __m128 llo = _mm_set1_ps(kInfinity), lhi = _mm_set1_ps(-kInfinity);
    __m128 rlo = _mm_set1_ps(kInfinity), rhi = _mm_set1_ps(-kInfinity);
    void add(bool left, const PrimRef& p) {
      const __m128 m = _mm_castsi128_ps(_mm_set1_epi32(-int32_t(left)));
      const __m128 c = p.center();
      const __m128 inf = _mm_set1_ps(kInfinity), ninf = _mm_set1_ps(-kInfinity);
      llo = _mm_min_ps(llo, _mm_or_ps(_mm_and_ps(m, c), _mm_andnot_ps(m, inf)));
      lhi = _mm_max_ps(lhi, _mm_or_ps(_mm_and_ps(m, c), _mm_andnot_ps(m, ninf)));
      rlo = _mm_min_ps(rlo, _mm_or_ps(_mm_andnot_ps(m, c), _mm_and_ps(m, inf)));
      rhi = _mm_max_ps(rhi, _mm_or_ps(_mm_andnot_ps(m, c), _mm_and_ps(m, ninf)));
    }
    void join(const SideCentroids& o) {
      llo = _mm_min_ps(llo, o.llo);
      lhi = _mm_max_ps(lhi, o.lhi);
      rlo = _mm_min_ps(rlo, o.rlo);
      rhi = _mm_max_ps(rhi, o.rhi);
    }
  };

  // Stable partition of src[begin, end) into dst[begin, end) by `pred`, whose true count the
  // binning already gave (`mid` = begin + that count), gathering each side's centroid bounds on
  // the way (the boxes come from the bins) so the children need no bounds pass of their own.
  // Each primitive is stored once at a selected index: the side decides no branch, which the
  // CPU could not predict. The parallel path computes the same permutation and bounds.
  template <class Pred>
  uint32_t partition(const PrimRef* src, PrimRef* dst, uint32_t begin, uint32_t end, uint32_t mid, bool parallel,
                     SideCentroids& out, const Pred& pred) {
    const auto run = [&](uint32_t b, uint32_t e, uint32_t l, uint32_t r, SideCentroids& acc) {
      for (uint32_t i = b; i < e; ++i) {
        const PrimRef& p = src[i];
        const bool left = pred(p);
        dst[left ? l : r] = p;
        l += uint32_t(left);
        r += uint32_t(!left);
        acc.add(left, p);
      }
    };
    if (!parallel) {
      run(begin, end, begin, mid, out);
      return mid;
    }
    const uint32_t blocks = (end - begin + kPartitionBlock - 1) / kPartitionBlock;
    std::vector<uint32_t> left_counts(blocks + 1, 0);
    exec_.for_each(blocks, [&](size_t k) {
      const uint32_t b = begin + k * kPartitionBlock, e = std::min(end, b + kPartitionBlock);
      uint32_t c = 0;
      for (uint32_t i = b; i < e; ++i) c += pred(src[i]) ? 1 : 0;
      left_counts[k + 1] = c;
    });
    for (uint32_t k = 0; k < blocks; ++k) left_counts[k + 1] += left_counts[k];
    std::vector<SideCentroids> block(blocks);
    exec_.for_each(blocks, [&](size_t k) {
      const uint32_t b = begin + k * kPartitionBlock, e = std::min(end, b + kPartitionBlock);
      run(b, e, begin + left_counts[k], mid + (b - begin) - left_counts[k], block[k]);  // rights before this block
    });
    for (uint32_t k = 0; k < blocks; ++k) out.join(block[k]);
    return mid;
  }

  BvhBuildOptions options_;
  struct FreeNodes {
    void operator()(BuildNode* p) const { std::free(p); }
  };
  // Two buffers of count_ primitives: a partition reads a node's range from one and writes the
  // children's ranges into the other (no copy back); BuildNode::buffer says which holds a node.
  std::unique_ptr<PrimRef[]> buffers_[2];
  uint32_t count_ = 0;
  std::unique_ptr<BuildNode[], FreeNodes> nodes_;
  std::atomic<uint32_t> node_count_{0};
  const Executor& exec_;
};

}  // namespace

Strategy strategy_for(BuildMode mode) {
  switch (mode) {
    case BuildMode::Seq:
      return Strategy::Seq;
    case BuildMode::Async:
      return Strategy::Async;
    case BuildMode::Queue:
      return Strategy::Queue;
    case BuildMode::Tasks:
      break;
  }
  return Strategy::Tbb;
}

BvhTopology build_bvh_topology(const Scene& scene, const BvhBuildOptions& options, const Executor& exec) {
  BvhTopology t;
  exec.run([&] {
    BvhBuilder builder(scene, options, exec);
    builder.build();
    builder.flatten(t.nodes, t.ids, nullptr, nullptr);
  });
  throw_if_cancelled(options.cancel);
  return t;
}

Bvh::Bvh(const Scene& scene, const BvhBuildOptions& options)
    : Bvh(scene, options, Executor(strategy_for(options.mode), options.threads)) {}

Bvh::Bvh(const Scene& scene, const BvhBuildOptions& options, const Executor& exec) : scene_(&scene), options_(options) {
  exec.run([&] {
    BvhBuilder builder(scene, options, exec);
    builder.build();
    leaf_of_.assign(scene.size(), kInvalidIndex);
    builder.flatten(nodes_, ids_, &pair_parent_, &leaf_of_);
    tris_.resize(ids_.size());
    const auto copy = [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) tris_[i] = scene.triangles[ids_[i]];
    };
    if (exec.data_parallel() && ids_.size() >= kParallelSplit) {
      const size_t blocks = (ids_.size() + kPartitionBlock - 1) / kPartitionBlock;
      exec.for_each(blocks,
                    [&](size_t k) { copy(k * kPartitionBlock, std::min(ids_.size(), (k + 1) * kPartitionBlock)); });
    } else {
      copy(0, ids_.size());
    }
  });
  throw_if_cancelled(options.cancel);
}

}  // namespace tracer
