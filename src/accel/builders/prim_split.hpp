// Splitting a set of triangles in two, as every BVH builder here does it: the binned SAH (or the
// study's object median), over an array of primitive boxes partitioned in place of the triangles,
// and, where the build has a reference budget, spatial splits (spatial_split.hpp).
// The binary BVH's builder and the 8-wide BVH's direct builder both split with this one class, so
// a range gets the same two halves in either tree.
//
// Determinism: a split is a pure function of the set of primitives in the range (bounds, bins and
// the median are the same in any order), so every executor (sequential, forked, data-parallel)
// gives the same halves; only their order inside a range may differ, which the builders remove
// by ordering each leaf's triangles.
#pragma once

#include <bit>
#include <cstdint>
#include <span>

#include <immintrin.h>  // SSE2, part of every x86-64

#include "accel/bvh/bvh.hpp"
#include "base/huge_pages.hpp"

namespace tracer {

struct SpatialSplit;  // spatial_split.hpp

// Primitives per block of the splitter's parallel passes (bounds, binning, partition).
inline constexpr uint32_t kPartitionBlock = 16384;

// A box in two SSE registers (lane 3 unused), as the builders bin, sweep and cut boxes.
struct SseBox {
  __m128 lo = _mm_set1_ps(kInfinity), hi = _mm_set1_ps(-kInfinity);
  void extend(__m128 p) {
    lo = _mm_min_ps(lo, p);
    hi = _mm_max_ps(hi, p);
  }
  void extend(const SseBox& b) {
    lo = _mm_min_ps(lo, b.lo);
    hi = _mm_max_ps(hi, b.hi);
  }
  bool empty() const { return (_mm_movemask_ps(_mm_cmpgt_ps(lo, hi)) & 7) != 0; }
  Aabb aabb() const { return to_aabb(lo, hi); }
  static Aabb to_aabb(__m128 lo, __m128 hi) {
    alignas(16) float a[4], b[4];
    _mm_store_ps(a, lo);
    _mm_store_ps(b, hi);
    return Aabb{{a[0], a[1], a[2]}, {b[0], b[1], b[2]}};
  }
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
  Aabb box() const { return SseBox::to_aabb(lo, hi); }
};
static_assert(sizeof(PrimRef) == 32);

// A run [begin, end) of the splitter's primitives, with its bounds once known (a split computes
// its halves' bounds on the way, so most ranges never need a pass).
struct PrimRange {
  Aabb box;   // of the primitives' boxes
  Aabb cbox;  // of their centroids
  uint32_t begin = 0, end = 0;
  uint32_t room = 0;          // free slots after `end` this range may fill with spatial splits
  uint32_t depth = 0;         // splits from the root: past kMedianFallbackDepth, halve by count
  bool bounds_known = false;  // box and cbox valid
  uint32_t size() const { return end - begin; }
};

class PrimSplitter {
 public:
  // Ranges this large split their bounds, binning and partition over the executor's threads.
  static constexpr uint32_t kParallelSplit = 65536;

  // Every non-degenerate triangle of `range` of the scene's, in scene order (filled in parallel
  // when the executor is data-parallel); a primitive's id is its scene index.
  PrimSplitter(const Scene& scene, TriangleRange range, const BvhBuildOptions& options, const Executor& exec);
  PrimSplitter(const Scene& scene, const BvhBuildOptions& options, const Executor& exec)
      : PrimSplitter(scene, TriangleRange::all(scene), options, exec) {}
  // Every non-empty box (a top-level tree's instances); a primitive's id is its index in `boxes`.
  // No spatial splits: there is no triangle to cut.
  PrimSplitter(std::span<const Aabb> boxes, const BvhBuildOptions& options, const Executor& exec);

  uint32_t count() const { return count_; }
  // Slots for references: count() and the spatial splits' budget.
  uint32_t capacity() const { return capacity_; }
  PrimRange root() const { return PrimRange{{}, {}, 0, count_, capacity_ - count_, 0, false}; }
  // The primitives; a range's are refs()[begin, end), in no particular order. With spatial
  // splits a triangle may have several, in different ranges, and slots between ranges are unused.
  const PrimRef* refs() const { return refs_.get(); }

  // Computes r's bounds if not yet known.
  void bound(PrimRange& r, bool parallel) const;
  // Splits r (bounding it first) into out[0] and out[1], both bounded, and returns true; or
  // returns false where r is better left a leaf (SAH: at most max_leaf primitives and cheaper
  // whole; median: at most two) or the build is cancelled. r's room is shared by the halves in
  // proportion to their sizes.
  bool split(PrimRange& r, PrimRange (&out)[2], bool parallel);

 private:
  struct SideCentroids;
  // Fills refs_ with make(i) for each i in [0, n) that keep(i) admits, in order.
  template <class Keep, class Make>
  void fill(uint32_t n, const Keep& keep, const Make& make);
  uint32_t median_split(PrimRef* refs, uint32_t begin, uint32_t end, int axis);
  bool split_spatially(PrimRange& r, const SpatialSplit& s, PrimRange (&out)[2]);
  void share_room(const PrimRange& r, uint32_t mid, PrimRange (&out)[2]);
  template <class Pred>
  void partition(PrimRef* refs, uint32_t begin, uint32_t end, uint32_t mid, bool parallel, SideCentroids& out,
                 const Pred& pred);

  BvhBuildOptions options_;
  const Executor& exec_;
  const Triangle* tris_;       // the scene's, to cut at spatial splits
  LargeBuffer<PrimRef> refs_;  // capacity_ slots, each range's partitioned in place
  uint32_t count_ = 0, capacity_ = 0;
  float root_area_ = 0.0f;  // half area of the root's box, once split
};

}  // namespace tracer
