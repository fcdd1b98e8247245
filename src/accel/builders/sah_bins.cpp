#include "accel/builders/sah_bins.hpp"

namespace tracer {
namespace {

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
  RawBin bins[3][kMaxSahBins];
  explicit BinSet(int n) : nb(n) {
    for (auto& axis : bins)
      for (int b = 0; b < nb; ++b) axis[b].reset();
  }
  void join(const BinSet& o) {
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < nb; ++b) bins[a][b].add(o.bins[a][b]);
  }
};

}  // namespace

SahSplit find_sah_split(const PrimRef* refs, const PrimRange& node, int max_bins, const Executor& exec, bool parallel) {
  const Aabb& cbox = node.cbox;
  // Fewer bins than primitives buy nothing: small nodes use fewer.
  const int nb = std::clamp(4 + int(node.end - node.begin) / 16, 4, max_bins);
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
    bins = exec.reduce(node.begin, node.end, kPartitionBlock, BinSet(nb), [&](uint32_t b, uint32_t e, BinSet acc) {
      fill(b, e, acc);
      return acc;
    });
  } else {
    fill(node.begin, node.end, bins);
  }
  // The sweep compares the split's raw area-count sum, keeping the best in scalars selected with
  // masks (which bin wins is unpredictable, and the compiler turned ?: back into a branch); the
  // cost is formed once, at the end.
  uint32_t best_choice = 0, best_left = 0;  // axis * kMaxSahBins + bin
  float best_raw = kInfinity;
  for (int a = 0; a < 3; ++a) {
    if (cbox.hi[a] <= cbox.lo[a]) continue;
    float right_cost[kMaxSahBins];  // area * count of bins [s, nb)
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
      best_choice = (uint32_t(a * kMaxSahBins + s) & better) | (best_choice & ~better);
      best_left = (acc.count & better) | (best_left & ~better);
    }
  }
  const float inv_area = 1.0f / std::max(node.box.half_area(), 1e-30f);
  SahSplit best;
  best.axis = int(best_choice / kMaxSahBins);
  best.split_bin = int(best_choice % kMaxSahBins);
  best.left_count = best_left;
  best.raw = best_raw;
  best.inv_area = inv_area;
  if (!(best_raw < kInfinity)) {
    best.axis = -1;
  } else {
    RawBin l, r;
    l.reset();
    r.reset();
    for (int b = 0; b < best.split_bin; ++b) l.add(bins.bins[best.axis][b]);
    for (int b = best.split_bin; b < nb; ++b) r.add(bins.bins[best.axis][b]);
    best.left_box = SseBox::to_aabb(l.lo, l.hi);
    best.right_box = SseBox::to_aabb(r.lo, r.hi);
  }
  best.bins = nb;
  return best;
}

}  // namespace tracer
