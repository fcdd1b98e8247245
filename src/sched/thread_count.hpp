// How many worker threads a "--threads" value means; shared by the schedulers and the builders.
#pragma once

#include <algorithm>
#include <thread>

namespace tracer {

// 0 (or less): all hardware threads.
inline int resolve_thread_count(int threads) {
  return threads > 0 ? threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

}  // namespace tracer
