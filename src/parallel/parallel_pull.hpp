// Pools of workers that find their own work: parallel_run() runs one function on N threads;
// parallel_pull() has each of them pull items from next() until it returns nothing. For work
// whose order is decided elsewhere (a tile server on another machine answering one request at a
// time), where parallel_for_tiles() would need the whole list up front. Knows nothing of what an
// item is.
#pragma once

#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace tracer {

// Runs worker() on `threads` threads (the caller's among them) and waits for all. The first
// exception a worker throws ends that worker and is rethrown here once all have joined.
template <class Worker>
void parallel_run(int threads, Worker&& worker) {
  std::exception_ptr failure;
  std::mutex failure_mutex;
  const auto guarded = [&] {
    try {
      worker();
    } catch (...) {
      std::lock_guard lock(failure_mutex);
      if (!failure) failure = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  for (int i = 1; i < threads; ++i) pool.emplace_back(guarded);
  guarded();
  for (std::thread& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
}

// Each of `threads` workers calls next() until it returns nothing and passes every item to
// body(). Both are called concurrently and must be safe so; next() decides when the workers stop.
template <class Next, class Body>
void parallel_pull(int threads, Next&& next, Body&& body) {
  parallel_run(threads, [&] {
    while (auto item = next()) body(*item);
  });
}

}  // namespace tracer
