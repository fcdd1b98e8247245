// The NL-means weight shared by the denoiser's filter and regression kernels. Include it after
// foreach_target.h; the guard toggles per target as Highway's -inl.h convention requires.
#if defined(TRACER_DENOISE_WEIGHT_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef TRACER_DENOISE_WEIGHT_INL_H_
#undef TRACER_DENOISE_WEIGHT_INL_H_
#else
#define TRACER_DENOISE_WEIGHT_INL_H_
#endif

#include <hwy/highway.h>
// After highway.h, once per target (Highway's -inl convention).
#include <hwy/contrib/math/math-inl.h>

HWY_BEFORE_NAMESPACE();
namespace tracer::denoise {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;
using D = hn::ScalableTag<float>;
using V = hn::Vec<D>;

// exp(-max(0, distance) * inv_k2) times valid: an NL-means weight. A weight below exp(-30)
// (1e-13 of the centre's) is zero: the sums it would add to are far below float precision, and
// products of such weights fall into denormals, which cost x86 a microcode assist each (they made
// the regression eight times slower).
HWY_INLINE V Weight(D d, V distance, V inv_k2, V valid) {
  const V arg = hn::Neg(hn::Max(distance, hn::Zero(d))) * inv_k2;
  const V cut = hn::Set(d, -30.0f);
  return hn::IfThenElseZero(arg > cut, hn::Exp(d, hn::Max(arg, cut)) * valid);
}

}  // namespace HWY_NAMESPACE
}  // namespace tracer::denoise
HWY_AFTER_NAMESPACE();

#endif  // TRACER_DENOISE_WEIGHT_INL_H_
