#include "parallel/executor.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <thread>
#include <vector>

#include "parallel/thread_count.hpp"

namespace tracer {

// The study's v2 for forks: a FIFO of jobs under one mutex, N - 1 workers sleeping on a condition
// variable, and a forking thread that runs jobs itself while it waits for its own.
struct Executor::Queue {
  struct Job {
    std::function<void()> fn;
    bool done = false;  // under the mutex
  };
  std::mutex mutex;
  std::condition_variable cv;
  std::deque<Job*> jobs;
  bool stopping = false;
  std::vector<std::thread> workers;

  // Runs one queued job if there is one; false if the queue was empty. Called with `lock` held.
  bool run_one(std::unique_lock<std::mutex>& lock) {
    if (jobs.empty()) return false;
    Job* job = jobs.front();
    jobs.pop_front();
    lock.unlock();
    job->fn();
    lock.lock();
    job->done = true;
    cv.notify_all();
    return true;
  }
};

Executor::Executor(Strategy strategy, int threads)
    : strategy_(strategy), threads_(strategy == Strategy::Seq ? 1 : resolve_thread_count(threads)) {
  // The study's async build forked only near the root: enough forks for a subtree per thread,
  // plus one level for balance.
  max_async_forks_ = (1 << (std::bit_width(unsigned(threads_)) + 1)) - 1;
  if (strategy_ == Strategy::Tbb) arena_ = std::make_unique<tbb::task_arena>(threads_);
}

Executor::~Executor() = default;

void Executor::run(const std::function<void()>& fn) const {
  async_forks_.store(0, std::memory_order_relaxed);
  if (strategy_ == Strategy::Tbb) {
    arena_->execute(fn);
    return;
  }
  if (strategy_ != Strategy::Queue || threads_ < 2 || queue_) {
    fn();
    return;
  }
  queue_ = std::make_unique<Queue>();
  Queue& q = *queue_;
  for (int i = 1; i < threads_; ++i) {
    q.workers.emplace_back([&q] {
      std::unique_lock lock(q.mutex);
      for (;;) {
        q.cv.wait(lock, [&] { return !q.jobs.empty() || q.stopping; });
        if (!q.run_one(lock)) return;  // stopping, and nothing left
      }
    });
  }
  const auto stop = [&] {
    {
      const std::lock_guard lock(q.mutex);
      q.stopping = true;
    }
    q.cv.notify_all();
    for (std::thread& t : q.workers) t.join();
    queue_.reset();
  };
  try {
    fn();
  } catch (...) {
    stop();
    throw;
  }
  stop();
}

bool Executor::queue_fork_join(std::function<void()> f, std::function<void()> g) const {
  if (!queue_) return false;
  Queue& q = *queue_;
  Queue::Job right{std::move(g)};
  {
    const std::lock_guard lock(q.mutex);
    q.jobs.push_back(&right);
  }
  q.cv.notify_one();
  f();
  std::unique_lock lock(q.mutex);
  while (!right.done) {
    // Help rather than sleep: this thread may itself hold the job it waits for.
    if (!q.run_one(lock)) q.cv.wait(lock, [&] { return right.done || !q.jobs.empty(); });
  }
  return true;
}

namespace {

void for_each_async(size_t count, const std::function<void(size_t)>& body, CancelFlag cancel) {
  // The study launched every item at once. Past a few hundred in flight that only exhausts
  // thread limits, so the oldest is awaited first; each item still gets its own thread.
  constexpr size_t kMaxInFlight = 256;
  std::deque<std::future<void>> running;
  for (size_t i = 0; i < count && !is_cancelled(cancel); ++i) {
    if (running.size() >= kMaxInFlight) {
      running.front().get();
      running.pop_front();
    }
    running.push_back(std::async(std::launch::async, [&body, i] { body(i); }));
  }
  for (auto& f : running) f.get();
}

void for_each_queue(size_t count, int threads, const std::function<void(size_t)>& body, CancelFlag cancel) {
  // The study's v2 for loops: a LIFO vector of items under one mutex, popped from the back, so
  // reversed first to hand out item 0 first.
  std::vector<size_t> items(count);
  for (size_t i = 0; i < count; ++i) items[i] = count - 1 - i;
  std::mutex mutex;
  const auto worker = [&] {
    for (;;) {
      size_t item;
      {
        const std::lock_guard lock(mutex);
        if (items.empty()) return;  // checked under the lock, as the study's fix did
        item = items.back();
        items.pop_back();
      }
      if (is_cancelled(cancel)) return;
      body(item);
    }
  };
  std::vector<std::thread> pool;
  for (int i = 0; i < threads; ++i) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
}

void for_each_atomic(size_t count, int threads, const std::function<void(size_t)>& body, CancelFlag cancel) {
  std::atomic<size_t> next{0};
  const auto worker = [&] {
    for (size_t i = next.fetch_add(1, std::memory_order_relaxed); i < count && !is_cancelled(cancel);
         i = next.fetch_add(1, std::memory_order_relaxed)) {
      body(i);
    }
  };
  std::vector<std::thread> pool;
  for (int i = 1; i < threads; ++i) pool.emplace_back(worker);
  worker();  // the calling thread is worker 0
  for (auto& t : pool) t.join();
}

}  // namespace

bool Executor::for_each(size_t count, const std::function<void(size_t)>& body, CancelFlag cancel) const {
  // An item that starts after the cancel does nothing, whichever strategy started it.
  const std::function<void(size_t)> checked = [&](size_t i) {
    if (!is_cancelled(cancel)) body(i);
  };
  switch (strategy_) {
    case Strategy::Seq:
      for (size_t i = 0; i < count && !is_cancelled(cancel); ++i) body(i);
      break;
    case Strategy::Async:
      for_each_async(count, checked, cancel);
      break;
    case Strategy::Queue:
      for_each_queue(count, threads_, checked, cancel);
      break;
    case Strategy::Atomic:
      for_each_atomic(count, threads_, checked, cancel);
      break;
    case Strategy::Tbb:
      arena_->execute([&] { sync_.for_each(uint32_t(count), [&](uint32_t i) { checked(i); }); });
      break;
  }
  return !is_cancelled(cancel);
}

}  // namespace tracer
