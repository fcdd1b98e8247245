// Which SIMD target Highway's dynamic dispatch picks for the kernels, and forcing a narrower one
// (--simd-target, and the tests that run every target).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "accel/simd_target.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "accel/wide_bvh/wide_bvh.hpp"

HWY_BEFORE_NAMESPACE();
namespace tracer {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

int64_t CurrentTarget() { return HWY_TARGET; }

}  // namespace HWY_NAMESPACE
}  // namespace tracer
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace tracer {

HWY_EXPORT(CurrentTarget);

std::string WideBvh::simd_target() { return hwy::TargetName(HWY_DYNAMIC_DISPATCH(CurrentTarget)()); }

void WideBvh::force_simd_target(SimdTarget target) {
  switch (target) {
    case SimdTarget::Auto:
    case SimdTarget::Avx512:
      hwy::DisableTargets(0);
      break;
    case SimdTarget::Avx2:
      hwy::DisableTargets(HWY_AVX3 | HWY_AVX3_DL);
      break;
    case SimdTarget::Sse4:
      hwy::DisableTargets(HWY_AVX2 | HWY_AVX3 | HWY_AVX3_DL);
      break;
  }
}

bool WideBvh::force_simd_target(const std::string& name) {
  for (const EnumName<SimdTarget>& e : kSimdTargetNames) {
    if (e.name == name) {
      force_simd_target(e.value);
      return true;
    }
  }
  return false;
}

}  // namespace tracer
#endif  // HWY_ONCE
