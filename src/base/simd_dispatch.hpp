// Which SIMD target a set of kernels runs on, chosen per object that calls them (an accelerator,
// a denoising), never for the whole process: Highway's dispatch tables are indexed by the slot of
// the target each object chose when it was made (--simd-target, and the tests that run every
// target side by side).
#pragma once

#include <cstdint>
#include <string>

#include "base/enum_names.hpp"

namespace tracer {

// The widest SIMD target the kernels may use; Auto is the CPU's best.
enum class SimdTarget { Auto, Avx512, Avx2, Sse4 };
inline constexpr EnumName<SimdTarget> kSimdTargetNames[] = {
    {SimdTarget::Auto, "auto"}, {SimdTarget::Avx512, "avx512"}, {SimdTarget::Avx2, "avx2"}, {SimdTarget::Sse4, "sse4"}};

// The best target this CPU has that is no wider than the one asked for, as the slot of every
// HWY_DISPATCH_TABLE: call a kernel exported with HWY_EXPORT(Fn) as SIMD_DISPATCH(dispatch, Fn)(...).
struct SimdDispatch {
  uint32_t slot = 0;
  static SimdDispatch of(SimdTarget target);
  std::string name() const;  // Highway's name of the target: "AVX3", "AVX2", "SSE4"
};

#define SIMD_DISPATCH(dispatch, FUNC_NAME) (*(HWY_DISPATCH_TABLE(FUNC_NAME)[(dispatch).slot]))

}  // namespace tracer
