// The splitter shared by the binary and 8-wide BVH builders: bounds, the choice among the binned
// SAH (sah_bins.hpp), spatial splits (spatial_split.hpp) and the object median, and the
// partition in place.
#include "accel/builders/prim_split.hpp"

#include <algorithm>
#include <cstring>
#include <utility>
#include <vector>

#include "accel/builders/sah_bins.hpp"
#include "accel/builders/spatial_split.hpp"

namespace tracer {
namespace {

constexpr uint32_t kMedianFallbackDepth = 64;  // SAH switches to object median below this depth
// Spatial splits are tried only where the object split's two boxes overlap by more than this
// fraction of the root's area (Stich et al.'s alpha). Their 1e-5 tried Sponza's spatial binning
// at 5261 nodes to take 312; 1e-3 keeps the same nodes per ray at half the build time
// (docs/bench/LOG.md).
constexpr float kSpatialOverlap = 1e-3f;

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
  Aabb box() const { return SseBox::to_aabb(lo, hi); }
  Aabb centroids() const { return SseBox::to_aabb(clo, chi); }
};

template <int Axis>
uint32_t median_partition(PrimRef* refs, uint32_t begin, uint32_t end) {
  const uint32_t mid = begin + (end - begin) / 2;
  // Ties broken by triangle index so the order is fully defined.
  std::nth_element(refs + begin, refs + mid, refs + end, [](const PrimRef& a, const PrimRef& b) {
    const float ca = a.center<Axis>(), cb = b.center<Axis>();
    return ca < cb || (ca == cb && a.id() < b.id());
  });
  return mid;
}

}  // namespace

// Centroid bounds of the two sides of a partition, accumulated without a branch per primitive.
struct PrimSplitter::SideCentroids {
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

PrimSplitter::PrimSplitter(const Scene& scene, TriangleRange range, const BvhBuildOptions& options,
                           const Executor& exec)
    : options_(options), exec_(exec), tris_(scene.triangles.data()) {
  const Triangle* tris = scene.triangles.data() + range.first;
  // Degenerate triangles are left out.
  fill(
      range.count, [&](uint32_t i) { return !tris[i].degenerate(); },
      [&](uint32_t i) { return PrimRef::make(tris[i].bounds(), range.first + i); });
}

PrimSplitter::PrimSplitter(std::span<const Aabb> boxes, const BvhBuildOptions& options, const Executor& exec)
    : options_(options), exec_(exec), tris_(nullptr) {
  options_.split_budget = 0.0f;  // a box has no triangle to cut
  fill(
      uint32_t(boxes.size()), [&](uint32_t i) { return !boxes[i].empty(); },
      [&](uint32_t i) { return PrimRef::make(boxes[i], i); });
}

template <class Keep, class Make>
void PrimSplitter::fill(uint32_t n, const Keep& keep, const Make& make) {
  options_.bins = std::clamp(options_.bins, 2, kMaxSahBins);
  options_.max_leaf = std::clamp(options_.max_leaf, 1, 255);
  options_.split_budget = std::clamp(options_.split_budget, 0.0f, 4.0f);
  capacity_ = uint32_t(std::min<uint64_t>(uint64_t(n) + uint64_t(double(n) * options_.split_budget), UINT32_MAX));
  // Left uninitialised: every slot is written before it is read.
  refs_ = LargeBuffer<PrimRef>(capacity_);
  PrimRef* refs = refs_.get();
  // In parallel: count per block, then fill at the offsets.
  const auto fill_block = [&](uint32_t b, uint32_t e, uint32_t out) {
    for (uint32_t i = b; i < e; ++i) {
      if (keep(i)) refs[out++] = make(i);
    }
    return out;
  };
  if (!exec_.data_parallel() || n < kParallelSplit) {
    count_ = fill_block(0, n, 0);
    capacity_ -= n - count_;
    return;
  }
  const uint32_t blocks = (n + kPartitionBlock - 1) / kPartitionBlock;
  std::vector<uint32_t> offsets(blocks + 1, 0);
  exec_.for_each(blocks, [&](size_t k) {
    uint32_t c = 0;
    for (uint32_t i = k * kPartitionBlock, e = std::min(n, i + kPartitionBlock); i < e; ++i) c += keep(i) ? 1 : 0;
    offsets[k + 1] = c;
  });
  for (uint32_t k = 0; k < blocks; ++k) offsets[k + 1] += offsets[k];
  exec_.for_each(blocks, [&](size_t k) {
    fill_block(uint32_t(k) * kPartitionBlock, std::min(n, uint32_t(k + 1) * kPartitionBlock), offsets[k]);
  });
  count_ = offsets[blocks];
  capacity_ -= n - count_;
}

void PrimSplitter::bound(PrimRange& r, bool parallel) const {
  if (r.bounds_known) return;
  const PrimRef* refs = refs_.get();
  const auto body = [&](uint32_t from, uint32_t to, Bounds4 acc) {
    for (uint32_t i = from; i < to; ++i) acc.add(refs[i]);
    return acc;
  };
  const Bounds4 b =
      parallel ? exec_.reduce(r.begin, r.end, kPartitionBlock, Bounds4{}, body) : body(r.begin, r.end, Bounds4{});
  r.box = b.box();
  r.cbox = b.centroids();
  r.bounds_known = true;
}

bool PrimSplitter::split(PrimRange& node, PrimRange (&out)[2], bool parallel) {
  if (is_cancelled(options_.cancel)) return false;  // the builder then throws Cancelled
  bound(node, parallel);
  if (node.depth == 0) root_area_ = node.box.half_area();
  const uint32_t begin = node.begin, end = node.end, count = end - begin;
  PrimRef* refs = refs_.get();
  uint32_t mid;
  bool halves_known = false;
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
      const SahSplit sah = find_sah_split(refs, node, options_.bins, exec_, parallel);
      if (sah.axis < 0) {
        if (count <= uint32_t(options_.max_leaf)) return false;
        mid = median_split(refs, begin, end, max_dimension(extent));
      } else {
        SpatialSplit spatial;
        if (node.room > 0) {
          Aabb overlap{max(sah.left_box.lo, sah.right_box.lo), min(sah.left_box.hi, sah.right_box.hi)};
          if (overlap.half_area() > kSpatialOverlap * root_area_)
            spatial = find_spatial_split(tris_, refs, begin, end, node.box, sah.bins);
        }
        const float raw = std::min(sah.raw, spatial.raw);
        const float cost = options_.traversal_cost + options_.intersection_cost * raw * sah.inv_area;
        const float leaf_cost = options_.intersection_cost * float(count);
        if (count <= uint32_t(options_.max_leaf) && leaf_cost <= cost) return false;
        if (spatial.raw < sah.raw && split_spatially(node, spatial, out)) return true;
        const Binner binner(node.cbox, sah.bins);
        SideCentroids centroids;
        mid = begin + sah.left_count;
        partition(refs, begin, end, mid, parallel, centroids,
                  [&](const PrimRef& prim) { return binner(prim.center(sah.axis), sah.axis) < sah.split_bin; });
        out[0].box = sah.left_box;
        out[1].box = sah.right_box;
        out[0].cbox = SseBox::to_aabb(centroids.llo, centroids.lhi);
        out[1].cbox = SseBox::to_aabb(centroids.rlo, centroids.rhi);
        halves_known = true;
      }
    }
  }
  share_room(node, mid, out);
  for (int c = 0; c < 2; ++c) {
    PrimRange& h = out[c];
    h.depth = node.depth + 1;
    h.bounds_known = halves_known;
    bound(h, parallel && h.size() >= kParallelSplit);
  }
  return true;
}

// The halves [begin, mid) and [mid, end) of r; r's room is shared in proportion to their sizes,
// moving the right half up past the left's share.
void PrimSplitter::share_room(const PrimRange& r, uint32_t mid, PrimRange (&out)[2]) {
  const uint32_t left_room = uint32_t(uint64_t(r.room) * (mid - r.begin) / r.size());
  if (left_room > 0)
    std::memmove(static_cast<void*>(refs_.get() + mid + left_room), refs_.get() + mid,
                 size_t(r.end - mid) * sizeof(PrimRef));
  out[0].begin = r.begin;
  out[0].end = mid;
  out[0].room = left_room;
  out[1].begin = mid + left_room;
  out[1].end = r.end + left_room;
  out[1].room = r.room - left_room;
}

// Cuts r at a spatial split, writing each side's references to its part of r's slots; false
// (r untouched) where a side would be empty or the references would not fit r's room.
bool PrimSplitter::split_spatially(PrimRange& r, const SpatialSplit& s, PrimRange (&out)[2]) {
  std::vector<PrimRef> left, right;
  divide_spatially(tris_, refs_.get(), r.begin, r.end, s, left, right);
  const uint64_t total = left.size() + right.size(), slots = uint64_t(r.size()) + r.room;
  if (left.empty() || right.empty() || total > slots) return false;
  const auto nl = uint32_t(left.size()), nr = uint32_t(right.size());
  const auto free = uint32_t(slots - total);
  const auto left_room = uint32_t(uint64_t(free) * nl / total);
  PrimRef* refs = refs_.get();
  std::copy(left.begin(), left.end(), refs + r.begin);
  std::copy(right.begin(), right.end(), refs + r.begin + nl + left_room);
  out[0].begin = r.begin;
  out[0].end = r.begin + nl;
  out[0].room = left_room;
  out[1].begin = out[0].end + left_room;
  out[1].end = out[1].begin + nr;
  out[1].room = free - left_room;
  for (PrimRange& h : out) {
    h.depth = r.depth + 1;
    h.bounds_known = false;
    bound(h, false);
  }
  return true;
}

uint32_t PrimSplitter::median_split(PrimRef* refs, uint32_t begin, uint32_t end, int axis) {
  switch (axis) {
    case 0:
      return median_partition<0>(refs, begin, end);
    case 1:
      return median_partition<1>(refs, begin, end);
    default:
      return median_partition<2>(refs, begin, end);
  }
}

// Partition of refs[begin, end) in place by `pred`, whose true count the binning already gave
// (`mid` = begin + that count), gathering each side's centroid bounds on the way (the boxes come
// from the bins) so the halves need no bounds pass of their own. The order within each half
// depends on the path taken (sequential, or blocks in parallel); which primitives go to each half
// does not, and every later decision depends only on that set (the leaves are ordered by
// triangle at the end), so every executor still builds the same tree.
template <class Pred>
void PrimSplitter::partition(PrimRef* refs, uint32_t begin, uint32_t end, uint32_t mid, bool parallel,
                             SideCentroids& out, const Pred& pred) {
  // Lomuto's partition without a branch on the side, which the CPU could not predict: each
  // primitive is swapped with the first right one, and the boundary moves past it if it is left.
  const auto run = [&](uint32_t b, uint32_t e, SideCentroids& acc) {
    uint32_t k = b;
    for (uint32_t i = b; i < e; ++i) {
      const PrimRef p = refs[i];
      const bool left = pred(p);
      refs[i] = refs[k];
      refs[k] = p;
      k += uint32_t(left);
      acc.add(left, p);
    }
    return k - b;
  };
  if (!parallel) {
    run(begin, end, out);
    return;
  }
  // In parallel: each block partitioned in place, then the right primitives left of `mid` and the
  // left ones right of it (as many of each) swapped pairwise, in chunks of ranks.
  const uint32_t blocks = (end - begin + kPartitionBlock - 1) / kPartitionBlock;
  std::vector<uint32_t> left_count(blocks);
  std::vector<SideCentroids> block(blocks);
  exec_.for_each(blocks, [&](size_t k) {
    const uint32_t b = begin + uint32_t(k) * kPartitionBlock;
    left_count[k] = run(b, std::min(end, b + kPartitionBlock), block[k]);
  });
  for (uint32_t k = 0; k < blocks; ++k) out.join(block[k]);
  // The misplaced runs, in position order: rights in [begin, mid), lefts in [mid, end).
  struct Run {
    uint32_t first, size;
  };
  std::vector<Run> rights, lefts;
  for (uint32_t k = 0; k < blocks; ++k) {
    const uint32_t b = begin + k * kPartitionBlock, e = std::min(end, b + kPartitionBlock), m = b + left_count[k];
    if (std::min(e, mid) > std::max(m, begin)) rights.push_back({m, std::min(e, mid) - m});
    if (m > std::max(b, mid)) lefts.push_back({std::max(b, mid), m - std::max(b, mid)});
  }
  // Rank of each run's first element; both lists hold the same number of primitives.
  const auto ranks = [](const std::vector<Run>& runs) {
    std::vector<uint64_t> r(runs.size() + 1, 0);
    for (size_t i = 0; i < runs.size(); ++i) r[i + 1] = r[i] + runs[i].size;
    return r;
  };
  const std::vector<uint64_t> rank_r = ranks(rights), rank_l = ranks(lefts);
  const uint64_t misplaced = rank_r.back();
  const auto chunks = uint32_t((misplaced + kPartitionBlock - 1) / kPartitionBlock);
  exec_.for_each(chunks, [&](size_t c) {
    const uint64_t from = uint64_t(c) * kPartitionBlock, to = std::min(misplaced, from + kPartitionBlock);
    // The run holding rank `from`, and the offset in it, in each list.
    const auto locate = [from](const std::vector<uint64_t>& r) {
      const size_t i = size_t(std::upper_bound(r.begin(), r.end(), from) - r.begin()) - 1;
      return std::pair<size_t, uint32_t>(i, uint32_t(from - r[i]));
    };
    auto [ri, ro] = locate(rank_r);
    auto [li, lo] = locate(rank_l);
    for (uint64_t n = from; n < to; ++n) {
      std::swap(refs[rights[ri].first + ro], refs[lefts[li].first + lo]);
      if (++ro == rights[ri].size) ++ri, ro = 0;
      if (++lo == lefts[li].size) ++li, lo = 0;
    }
  });
}

}  // namespace tracer
