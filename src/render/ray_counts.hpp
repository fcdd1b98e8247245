// The rays a render traced, by kind: per tile (RayCounts) and summed across workers
// (AtomicRayCounts).
#pragma once

#include <atomic>
#include <cstdint>

namespace tracer {

struct RayCounts {
  uint64_t primary = 0, shadow = 0, ao = 0, secondary = 0;  // secondary: reflected and refracted rays
  uint64_t total() const { return primary + shadow + ao + secondary; }
  RayCounts& operator+=(const RayCounts& o) {
    primary += o.primary;
    shadow += o.shadow;
    ao += o.ao;
    secondary += o.secondary;
    return *this;
  }
};

// Thread-safe accumulation of per-tile counts (one atomic add per tile, never per ray).
struct AtomicRayCounts {
  std::atomic<uint64_t> primary{0}, shadow{0}, ao{0}, secondary{0};
  void add(const RayCounts& c) {
    primary.fetch_add(c.primary, std::memory_order_relaxed);
    shadow.fetch_add(c.shadow, std::memory_order_relaxed);
    ao.fetch_add(c.ao, std::memory_order_relaxed);
    secondary.fetch_add(c.secondary, std::memory_order_relaxed);
  }
  RayCounts load() const { return {primary.load(), shadow.load(), ao.load(), secondary.load()}; }
};

}  // namespace tracer
