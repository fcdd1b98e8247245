// How many worker threads a "--threads" value means; shared by the schedulers and the builders.
#pragma once

#include <tbb/global_control.h>
#include <tbb/info.h>

#include <algorithm>
#include <memory>

namespace tracer {

// 0 (or less): every hardware thread this process may run on. oneTBB's count honours the CPU
// affinity mask (taskset, cgroups), which std::thread::hardware_concurrency() does not: asking
// oneTBB for more than that made it print a warning and run fewer.
inline int resolve_thread_count(int threads) {
  return threads > 0 ? threads : std::max(1, tbb::info::default_concurrency());
}

// oneTBB caps every arena at the hardware thread count unless told otherwise, and says so on
// stderr in its own words. Holding this for the run lets oneTBB's arenas (the tbb scheduler, the
// tasks build) run exactly the `threads` asked for, as the std::thread schedulers do.
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads)
      : control_(threads > 0 ? std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                                     size_t(threads))
                             : nullptr) {}
  // True when more threads were asked for than the process may use: they time-share its cores.
  static bool oversubscribed(int threads) { return threads > resolve_thread_count(0); }

 private:
  std::unique_ptr<tbb::global_control> control_;
};

}  // namespace tracer
