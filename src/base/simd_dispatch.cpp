#include "base/simd_dispatch.hpp"

#include <hwy/highway.h>
#include <hwy/targets.h>

namespace tracer {

SimdDispatch SimdDispatch::of(SimdTarget target) {
  int64_t wider = 0;  // the targets wider than the one asked for
  switch (target) {
    case SimdTarget::Auto:
    case SimdTarget::Avx512:
      break;
    case SimdTarget::Avx2:
      wider = HWY_AVX3 | HWY_AVX3_DL;
      break;
    case SimdTarget::Sse4:
      wider = HWY_AVX2 | HWY_AVX3 | HWY_AVX3_DL;
      break;
  }
  // What this CPU runs, of what was compiled (HWY_TARGETS: every translation unit that includes
  // hwy/foreach_target.h compiles the same list), but the wider ones.
  hwy::ChosenTarget chosen;
  chosen.Update(hwy::SupportedTargets() & HWY_TARGETS & ~wider);
  return {uint32_t(chosen.GetIndex())};
}

std::string SimdDispatch::name() const {
  // The slot's target: the one bit of the compiled list that maps to it.
  for (int64_t bits = HWY_TARGETS; bits != 0; bits &= bits - 1) {
    const int64_t target = bits & -bits;
    hwy::ChosenTarget one;
    one.Update(target);
    if (one.GetIndex() == slot) return hwy::TargetName(target);
  }
  return "?";
}

}  // namespace tracer
