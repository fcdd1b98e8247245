// The binned SAH (Wald 2007): a range's primitives binned by centroid into up to kMaxSahBins equal
// slabs of its centroid bounds on each axis, and the plane between two bins of least surface
// area times primitives. The boxes of the two sides come from the bins, exactly.
#pragma once

#include <algorithm>
#include <cstdint>

#include "accel/builders/prim_split.hpp"

namespace tracer {

inline constexpr int kMaxSahBins = 32;

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

struct SahSplit {
  int axis = -1;          // -1: none found
  int split_bin = 0;      // the left side: bins [0, split_bin) on `axis`
  float raw = kInfinity;  // half area x primitives over both sides
  float inv_area = 0.0f;  // of the node's box
  int bins = 0;           // bins per axis used
  uint32_t left_count = 0;
  Aabb left_box, right_box;  // the children's boxes: unions of their bins' boxes, exactly
};

// The cheapest binned split of `node` (bounded) with at most `max_bins` bins per axis (fewer for
// small ranges); over the executor's threads when `parallel`. The same for any executor.
SahSplit find_sah_split(const PrimRef* refs, const PrimRange& node, int max_bins, const Executor& exec, bool parallel);

}  // namespace tracer
