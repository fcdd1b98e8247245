// The denoiser's per-pixel regression (kernels.hpp), compiled once per SIMD target by Highway.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "denoise/regression_kernels.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <utility>

#include "denoise/kernels.hpp"
#include "denoise/weight-inl.h"

HWY_BEFORE_NAMESPACE();
namespace tracer::denoise {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// The regression of Dim unknowns: the constant, the two screen coordinates where Dim is kDim
// (none where it is kDim - 2), then the features.
template <int Dim>
struct Regressors {
  static constexpr int kFirstFeature = Dim - kFeatures;
  static constexpr int kGram = Dim * (Dim + 1) / 2;
  // Where row r of X^T W X starts among the upper triangle's entries.
  static constexpr int RowStart(int r) { return r * Dim - r * (r - 1) / 2; }
};

// What a row-vector of pixels reads at each offset.
struct RowView {
  const float* features[kFeatures];  // at p
  const float* image[3];             // at p
  ptrdiff_t stride;
  int radius;
  float scale;
};

// Adds row R of X^T W X and of X^T W Y over every offset, for B bandwidths at once (the
// regressors loaded once for both), in registers, and stores them to sums[b]
// (kRegressionEntries vectors of the row-vector each, at most).
template <int Dim, int B, int R>
HWY_INLINE void AccumulateRow(D d, const RowView& v, const V* fp, const float* weights, size_t weight_stride,
                              float* sums, size_t sums_stride) {
  using X = Regressors<Dim>;
  constexpr int kS = Dim - R;
  const size_t n = hn::Lanes(d);
  V acc[B][kS + 3];
  for (int b = 0; b < B; ++b) {
    for (int k = 0; k < kS + 3; ++k) acc[b][k] = hn::Zero(d);
  }
  int o = 0;
  for (int oy = -v.radius; oy <= v.radius; ++oy) {
    for (int ox = -v.radius; ox <= v.radius; ++ox, ++o) {
      const ptrdiff_t q = ptrdiff_t(oy) * v.stride + ox;
      V x[kS];
      HWY_UNROLL(16)
      for (int k = 0; k < kS; ++k) {
        const int s = R + k;
        x[k] = s == 0                  ? hn::Set(d, 1.0f)
               : s >= X::kFirstFeature ? hn::LoadU(d, v.features[s - X::kFirstFeature] + q) - fp[s - X::kFirstFeature]
               : s == 1                ? hn::Set(d, float(ox) * v.scale)
                                       : hn::Set(d, float(oy) * v.scale);
      }
      V y[3];
      for (int c = 0; c < 3; ++c) y[c] = hn::LoadU(d, v.image[c] + q);
      HWY_UNROLL(2)
      for (int b = 0; b < B; ++b) {
        const V wr = hn::Load(d, weights + size_t(b) * weight_stride + size_t(o) * n) * x[0];
        HWY_UNROLL(16)
        for (int k = 0; k < kS; ++k) acc[b][k] = hn::MulAdd(wr, x[k], acc[b][k]);
        for (int c = 0; c < 3; ++c) acc[b][kS + c] = hn::MulAdd(wr, y[c], acc[b][kS + c]);
      }
    }
  }
  for (int b = 0; b < B; ++b) {
    float* out = sums + size_t(b) * sums_stride;
    for (int k = 0; k < kS; ++k) hn::Store(acc[b][k], d, out + size_t(X::RowStart(R) + k) * n);
    for (int c = 0; c < 3; ++c) hn::Store(acc[b][kS + c], d, out + size_t(X::kGram + R * 3 + c) * n);
  }
}

template <int Dim, int B, int... R>
HWY_INLINE void AccumulateRows(D d, const RowView& v, const V* fp, const float* weights, size_t weight_stride,
                               float* sums, size_t sums_stride, std::integer_sequence<int, R...>) {
  (AccumulateRow<Dim, B, R>(d, v, fp, weights, weight_stride, sums, sums_stride), ...);
}

// beta's first term for each lane from the sums (see RegressionRow), by a Cholesky factorisation
// lane by lane; the weighted mean where it fails.
template <int Dim>
HWY_INLINE void SolveLanes(D d, const float* sums, float* l, V out[3]) {
  using X = Regressors<Dim>;
  constexpr int kDim = Dim;  // NOLINT: shadows the widest on purpose
  const size_t n = hn::Lanes(d);
  const auto gram = [&](int r, int s) {
    const int a = r < s ? r : s, b = r < s ? s : r;
    return hn::Load(d, sums + size_t(X::RowStart(a) + b - a) * n);
  };
  const auto rhs = [&](int r, int c) { return hn::Load(d, sums + size_t(X::kGram + r * 3 + c) * n); };
  const V weights = gram(0, 0);
  const V ridge = weights * hn::Set(d, 1e-3f);
  const V floor = weights * hn::Set(d, 1e-6f);
  auto ok = weights > hn::Zero(d);
  const auto lv = [&](int r, int s) { return l + size_t(r * kDim + s) * n; };
  // L's diagonal is kept as its reciprocal: the substitutions below multiply by it, since the
  // divider's throughput is a few lanes a cycle.
  for (int j = 0; j < kDim; ++j) {
    V s = gram(j, j);
    if (j > 0) s = s + ridge;
    for (int k = 0; k < j; ++k) {
      const V ljk = hn::Load(d, lv(j, k));
      s = hn::NegMulAdd(ljk, ljk, s);
    }
    ok = hn::And(ok, s > floor);
    const V inv = hn::Set(d, 1.0f) / hn::Sqrt(hn::Max(s, floor + hn::Set(d, 1e-30f)));
    hn::Store(inv, d, lv(j, j));
    for (int r = j + 1; r < kDim; ++r) {
      V t = gram(r, j);
      for (int k = 0; k < j; ++k) t = hn::NegMulAdd(hn::Load(d, lv(r, k)), hn::Load(d, lv(j, k)), t);
      hn::Store(t * inv, d, lv(r, j));
    }
  }
  const V safe_weights = hn::Max(weights, hn::Set(d, 1e-30f));
  for (int c = 0; c < 3; ++c) {
    V z[kDim], beta[kDim];
    for (int r = 0; r < kDim; ++r) {
      V t = rhs(r, c);
      for (int k = 0; k < r; ++k) t = hn::NegMulAdd(hn::Load(d, lv(r, k)), z[k], t);
      z[r] = t * hn::Load(d, lv(r, r));
    }
    for (int r = kDim - 1; r >= 0; --r) {
      V t = z[r];
      for (int k = r + 1; k < kDim; ++k) t = hn::NegMulAdd(hn::Load(d, lv(k, r)), beta[k], t);
      beta[r] = t * hn::Load(d, lv(r, r));
    }
    const V mean = rhs(0, c) / safe_weights;
    const auto finite = hn::IsFinite(beta[0]);
    out[c] = hn::Max(hn::IfThenElse(hn::And(ok, finite), beta[0], mean), hn::Zero(d));
  }
}

template <int Dim>
void RegressionRowOf(const RegressionRow& a) {
  const D d;
  const size_t n = hn::Lanes(d);
  const int edge = 2 * a.radius + 1, offsets = edge * edge;
  float* weights = a.scratch;                                  // bandwidths x offsets vectors
  float* sums = weights + size_t(a.bandwidths * offsets) * n;  // kRegressionEntries vectors a bandwidth
  float* l = sums + size_t(2 * kRegressionEntries) * n;        // kDim x kDim vectors
  const int y = a.y0 + a.ty;
  // The paper's bandwidths, k = 0.5 and 1: the first's weights are the second's to the fourth.
  const bool quartic = a.bandwidths == 2 && a.inv_k2[0] == 4.0f * a.inv_k2[1];
  for (size_t i = 0; i < size_t(kTileWidth); i += n) {
    const int x = a.x0 + int(i);
    if (x >= a.image->width()) break;
    RowView v;
    v.stride = a.image->stride();
    v.radius = a.radius;
    v.scale = a.position_scale;
    V fp[kFeatures];
    for (int j = 0; j < kFeatures; ++j) {
      v.features[j] = a.features->at(j, x, y);
      fp[j] = hn::LoadU(d, v.features[j]);
    }
    for (int c = 0; c < 3; ++c) v.image[c] = a.image->at(c, x, y);
    const float* valid = a.valid->at(0, x, y);
    for (int o = 0; o < offsets; ++o) {
      const int ox = o % edge - a.radius, oy = o / edge - a.radius;
      const V dist = hn::Load(d, a.distances + size_t(o) * kTilePixels + size_t(a.ty) * kTileWidth + i);
      const V ok = hn::LoadU(d, valid + ptrdiff_t(oy) * v.stride + ox);
      if (quartic) {
        // exp(-4x) as exp(-x)^4: one exponential for both bandwidths.
        const V wide = Weight(d, dist, hn::Set(d, a.inv_k2[1]), ok), wide2 = wide * wide;
        const V arg = hn::Max(dist, hn::Zero(d)) * hn::Set(d, a.inv_k2[0]);
        hn::Store(hn::IfThenElseZero(arg < hn::Set(d, 30.0f), wide2 * wide2), d, weights + size_t(o) * n);
        hn::Store(wide, d, weights + size_t(offsets + o) * n);
        continue;
      }
      for (int b = 0; b < a.bandwidths; ++b) {
        hn::Store(Weight(d, dist, hn::Set(d, a.inv_k2[b]), ok), d, weights + size_t(b * offsets + o) * n);
      }
    }
    const size_t weight_stride = size_t(offsets) * n, sums_stride = size_t(kRegressionEntries) * n;
    // Both bandwidths in one sweep where the registers hold their sums (AVX-512's 32); on
    // narrower targets the second set of sums would spill, so each takes a sweep of its own.
    constexpr bool kSweepBoth = HWY_TARGET <= HWY_AVX3;
    if (a.bandwidths == 2 && !kSweepBoth) {
      AccumulateRows<Dim, 1>(d, v, fp, weights, weight_stride, sums, sums_stride,
                             std::make_integer_sequence<int, Dim>{});
      AccumulateRows<Dim, 1>(d, v, fp, weights + weight_stride, weight_stride, sums + sums_stride, sums_stride,
                             std::make_integer_sequence<int, Dim>{});
    } else if (a.bandwidths == 2) {
      AccumulateRows<Dim, 2>(d, v, fp, weights, weight_stride, sums, sums_stride,
                             std::make_integer_sequence<int, Dim>{});
    } else {
      AccumulateRows<Dim, 1>(d, v, fp, weights, weight_stride, sums, sums_stride,
                             std::make_integer_sequence<int, Dim>{});
    }
    for (int b = 0; b < a.bandwidths; ++b) {
      V out[3];
      SolveLanes<Dim>(d, sums + size_t(b) * sums_stride, l, out);
      HWY_ALIGN float lanes[3][16];
      for (int c = 0; c < 3; ++c) hn::Store(out[c], d, lanes[c]);
      for (size_t k = 0; k < n && x + int(k) < a.image->width(); ++k) {
        for (int c = 0; c < 3; ++c) (*a.out[b])(c, x + int(k), y) = lanes[c][k];
      }
    }
  }
}

// Without the screen position (a scale of 0) the two coordinates' rows and columns would be
// zero: the system is two smaller instead.
void RegressionRowT(const RegressionRow& a) {
  if (a.position_scale == 0.0f) {
    RegressionRowOf<kDim - 2>(a);
  } else {
    RegressionRowOf<kDim>(a);
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace tracer::denoise
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace tracer::denoise {

HWY_EXPORT(RegressionRowT);

void regression_row(const RegressionRow& a, SimdDispatch simd) { SIMD_DISPATCH(simd, RegressionRowT)(a); }
size_t regression_scratch_floats(int radius) {
  const size_t widest = 16, offsets = size_t(2 * radius + 1) * size_t(2 * radius + 1);
  return widest * (2 * offsets + size_t(2 * kRegressionEntries) + size_t(kDim * kDim));
}

}  // namespace tracer::denoise
#endif  // HWY_ONCE
