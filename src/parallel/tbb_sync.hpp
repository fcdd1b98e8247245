// oneTBB's fork-join, parallel-for and reduce, each with happens-before edges ThreadSanitizer can
// see. oneTBB's own forks and joins happen inside a library TSan cannot see into, so without
// these TSan reports (and, with oneTBB's frames suppressed, still processes) every datum handed
// between threads: minutes per BVH build. Every parallel piece starts and ends with an acq_rel
// increment of one shared counter, as does every fork and join: the edges oneTBB already
// guarantees, in a form TSan understands. A few atomics per task or chunk, never per element.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include <atomic>
#include <cstdint>

namespace tracer {

class TbbSync {
 public:
  // Runs f and g in parallel.
  template <class F, class G>
  void fork_join(const F& f, const G& g) const {
    publish();
    tbb::parallel_invoke(
        [&] {
          publish();
          f();
          publish();
        },
        [&] {
          publish();
          g();
          publish();
        });
    publish();
  }

  // body(k) for every k in [0, count), in parallel.
  template <class Body>
  void for_each(uint32_t count, const Body& body) const {
    publish();
    tbb::parallel_for(uint32_t(0), count, [&](uint32_t k) {
      publish();
      body(k);
      publish();
    });
    publish();
  }

  // body(begin, end, acc) over chunks of [begin, end) of at least `grain`, joined with T::join.
  template <class T, class Body>
  T reduce(uint32_t begin, uint32_t end, uint32_t grain, T init, const Body& body) const {
    publish();
    T result = tbb::parallel_reduce(
        tbb::blocked_range<uint32_t>(begin, end, grain), init,
        [&](const tbb::blocked_range<uint32_t>& r, T acc) {
          publish();
          T out = body(r.begin(), r.end(), acc);
          publish();
          return out;
        },
        [&](T a, const T& b) {
          publish();
          a.join(b);
          return a;
        });
    publish();
    return result;
  }

  // An edge by itself: what this thread wrote so far, to whichever thread publishes next.
  void publish() const { counter_.fetch_add(1, std::memory_order_acq_rel); }

 private:
  mutable std::atomic<uint64_t> counter_{0};
};

}  // namespace tracer
