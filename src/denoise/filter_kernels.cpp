// The denoiser's NL-means filter loops (kernels.hpp), compiled once per SIMD target by Highway.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "denoise/filter_kernels.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <utility>

#include "denoise/kernels.hpp"
#include "denoise/weight-inl.h"

HWY_BEFORE_NAMESPACE();
namespace tracer::denoise {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

void PatchDistances(const PatchDistance& a) {
  const D d;
  const size_t n = hn::Lanes(d);
  const int f = a.patch, rows = kTileHeight + 2 * f, channels = a.guide->channels();
  HWY_ALIGN float dist[(kTileHeight + 2 * kMaxPatch) * kPatchColumns];
  HWY_ALIGN float hbox[(kTileHeight + 2 * kMaxPatch) * kTileWidth];
  const V inv_channels = hn::Set(d, 1.0f / float(channels));
  const V eps = hn::Set(d, 1e-10f), clamp = hn::Set(d, 10000.0f);
  // The columns the box filter reads, in whole vectors (at most kPatchColumns).
  const size_t columns = (size_t(kTileWidth + 2 * f) + n - 1) / n * n;
  for (int r = 0; r < rows; ++r) {
    const int y = a.y0 - f + r;
    for (size_t i = 0; i < columns; i += n) {
      const int x = a.x0 - f + int(i);
      V sum = hn::Zero(d);
      for (int c = 0; c < channels; ++c) {
        const V gp = hn::LoadU(d, a.guide->at(c, x, y));
        const V gq = hn::LoadU(d, a.guide->at(c, x + a.ox, y + a.oy));
        const V vp = hn::LoadU(d, a.variance->at(c, x, y));
        const V vq = hn::LoadU(d, a.variance->at(c, x + a.ox, y + a.oy));
        const V diff = gp - gq;
        const V num = hn::MulSub(diff, diff, vp + hn::Min(vp, vq));
        // A reciprocal estimate refined by one Newton step (relative error about 1e-7), not a
        // division: the divider's throughput was a third of the denoiser's time.
        const V den = vp + vq + eps;
        const V r0 = hn::ApproximateReciprocal(den);
        const V inv = r0 * hn::NegMulAdd(den, r0, hn::Set(d, 2.0f));
        sum = sum + hn::Min(num * inv, clamp);
      }
      hn::Store(sum * inv_channels, d, dist + r * kPatchColumns + int(i));
    }
  }
  for (int r = 0; r < rows; ++r) {
    for (size_t i = 0; i < size_t(kTileWidth); i += n) {
      V sum = hn::Zero(d);
      for (int j = 0; j <= 2 * f; ++j) sum = sum + hn::LoadU(d, dist + r * kPatchColumns + int(i) + j);
      hn::Store(sum, d, hbox + r * kTileWidth + int(i));
    }
  }
  const V inv_area = hn::Set(d, 1.0f / float((2 * f + 1) * (2 * f + 1)));
  for (int y = 0; y < kTileHeight; ++y) {
    for (size_t i = 0; i < size_t(kTileWidth); i += n) {
      V sum = hn::Zero(d);
      for (int j = 0; j <= 2 * f; ++j) sum = sum + hn::Load(d, hbox + (y + j) * kTileWidth + int(i));
      hn::Store(sum * inv_area, d, a.out + y * kTileWidth + int(i));
    }
  }
}

void FilterStepT(const FilterStep& a) {
  const D d;
  const size_t n = hn::Lanes(d);
  const int channels = a.image->channels();
  const V inv_k2 = hn::Set(d, a.inv_k2);
  for (int ty = 0; ty < kTileHeight; ++ty) {
    const int y = a.y0 + ty;
    for (size_t i = 0; i < size_t(kTileWidth); i += n) {
      const int x = a.x0 + int(i), idx = ty * kTileWidth + int(i);
      const V w = Weight(d, hn::Load(d, a.distance + idx), inv_k2, hn::LoadU(d, a.valid->at(0, x + a.ox, y + a.oy)));
      for (int c = 0; c < channels; ++c) {
        float* acc = a.acc + c * kTilePixels + idx;
        hn::Store(hn::MulAdd(w, hn::LoadU(d, a.image->at(c, x + a.ox, y + a.oy)), hn::Load(d, acc)), d, acc);
      }
      float* wsum = a.acc + channels * kTilePixels + idx;
      hn::Store(hn::Load(d, wsum) + w, d, wsum);
    }
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace tracer::denoise
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace tracer::denoise {

HWY_EXPORT(PatchDistances);
HWY_EXPORT(FilterStepT);

void patch_distances(const PatchDistance& a, SimdDispatch simd) { SIMD_DISPATCH(simd, PatchDistances)(a); }
void filter_step(const FilterStep& a, SimdDispatch simd) { SIMD_DISPATCH(simd, FilterStepT)(a); }

}  // namespace tracer::denoise
#endif  // HWY_ONCE
