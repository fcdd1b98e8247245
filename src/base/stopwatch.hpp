// Elapsed wall time in milliseconds, for --stats and the progress lines.
#pragma once

#include <chrono>

namespace tracer {

using Clock = std::chrono::steady_clock;

inline double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace tracer
