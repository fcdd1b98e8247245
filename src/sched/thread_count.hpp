// How many worker threads a "--threads" value means; shared by the schedulers and the builders.
#pragma once

#include <tbb/global_control.h>

#include <algorithm>
#include <memory>
#include <thread>

namespace tracer {

// 0 (or less): all hardware threads.
inline int resolve_thread_count(int threads) {
  return threads > 0 ? threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

// oneTBB caps every arena at the hardware thread count unless told otherwise, and says so on
// stderr in its own words. Holding this for the run lets oneTBB's arenas (the tbb scheduler, the
// tasks build) run exactly the `threads` asked for, as the std::thread schedulers do.
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads)
      : control_(threads > 0 ? std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(threads))
                             : nullptr) {}
  // True when more threads were asked for than the machine has: they time-share its cores.
  static bool oversubscribed(int threads) { return threads > resolve_thread_count(0); }

 private:
  std::unique_ptr<tbb::global_control> control_;
};

}  // namespace tracer
