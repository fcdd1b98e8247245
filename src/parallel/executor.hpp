// An executor: how work is spread over threads, knowing nothing of what the work is (rays,
// pixels, tree nodes). The five strategies the study compares are written once, here, and both
// the tile loops of a render and the BVH builders are handed one (as bvh v2's builders are):
//   seq     one thread
//   async   the study's v1: std::async per forked call or per item (a bounded number in flight)
//   queue   the study's v2: N threads taking jobs from one mutex-guarded queue
//   atomic  N threads claiming items with one fetch_add each (for_each; forks like seq)
//   tbb     oneTBB work stealing in an arena of N threads, with data-parallel reduce
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <future>
#include <memory>

#include <tbb/task_arena.h>

#include "base/enum_names.hpp"
#include "base/errors.hpp"
#include "parallel/tbb_sync.hpp"

namespace tracer {

enum class Strategy { Seq, Async, Queue, Atomic, Tbb };

inline constexpr EnumName<Strategy> kStrategyNames[] = {{Strategy::Seq, "seq"},
                                                        {Strategy::Async, "async"},
                                                        {Strategy::Queue, "queue"},
                                                        {Strategy::Atomic, "atomic"},
                                                        {Strategy::Tbb, "tbb"}};

class Executor {
 public:
  // `threads` 0: every hardware thread the process may use (seq: always one).
  explicit Executor(Strategy strategy = Strategy::Tbb, int threads = 0);
  ~Executor();
  Executor(const Executor&) = delete;
  Executor& operator=(const Executor&) = delete;

  Strategy strategy() const { return strategy_; }
  int threads() const { return threads_; }
  // Whether fork_join() may run its two calls at once, and whether reduce() splits its range.
  bool forks() const {
    return strategy_ == Strategy::Async || strategy_ == Strategy::Queue || strategy_ == Strategy::Tbb;
  }
  bool data_parallel() const { return strategy_ == Strategy::Tbb; }

  // Runs `fn` where this executor's forks run: inside its oneTBB arena (tbb), with its queue's
  // workers started (queue, which forks sequentially outside run()), or on this thread.
  void run(const std::function<void()>& fn) const;

  // Runs f and g, at the same time where the strategy forks, and returns when both have.
  template <class F, class G>
  void fork_join(const F& f, const G& g) const {
    switch (strategy_) {
      case Strategy::Tbb:
        sync_.fork_join(f, g);
        return;
      case Strategy::Async:
        if (async_forks_.fetch_add(1, std::memory_order_relaxed) < max_async_forks_) {
          auto right = std::async(std::launch::async, [&g] { g(); });
          f();
          right.get();
          return;
        }
        break;
      case Strategy::Queue:
        if (queue_fork_join(std::function<void()>(f), std::function<void()>(g))) return;
        break;
      case Strategy::Seq:
      case Strategy::Atomic:
        break;
    }
    f();
    g();
  }

  // body(i) once for every i in [0, count), handed out as the strategy does; once `cancel` is set
  // no further item starts. Returns false if cancelled. Safe to call concurrently only where body is.
  bool for_each(size_t count, const std::function<void(size_t)>& body, CancelFlag cancel = nullptr) const;

  // body(begin, end, acc) over chunks of [begin, end) of at least `grain`, joined with T::join
  // (tbb); one chunk on this thread otherwise.
  template <class T, class Body>
  T reduce(uint32_t begin, uint32_t end, uint32_t grain, T init, const Body& body) const {
    if (data_parallel()) return sync_.reduce(begin, end, grain, init, body);
    return body(begin, end, init);
  }

 private:
  struct Queue;
  bool queue_fork_join(std::function<void()> f, std::function<void()> g) const;

  Strategy strategy_;
  int threads_;
  int max_async_forks_;
  mutable std::atomic<int> async_forks_{0};
  std::unique_ptr<tbb::task_arena> arena_;
  mutable std::unique_ptr<Queue> queue_;  // while run() runs, for the queue strategy
  TbbSync sync_;                          // oneTBB's calls, with edges ThreadSanitizer sees
};

}  // namespace tracer
