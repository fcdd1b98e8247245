#include "base/huge_pages.hpp"

#include <sys/mman.h>

#include <cstdint>

namespace tracer {

void* allocate_large(size_t bytes) {
  if (bytes < kHugeArrayMinBytes) return ::operator new (bytes == 0 ? 1 : bytes, std::align_val_t{64});
  // Map one huge page more than needed and trim both ends to a 2 MiB boundary: THP only backs
  // aligned 2 MiB ranges.
  const size_t len = (bytes + kHugePageBytes - 1) & ~(kHugePageBytes - 1);
  void* raw = mmap(nullptr, len + kHugePageBytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED) throw std::bad_alloc();
  const auto start = reinterpret_cast<uintptr_t>(raw);
  const uintptr_t aligned = (start + kHugePageBytes - 1) & ~uintptr_t(kHugePageBytes - 1);
  if (aligned > start) munmap(raw, aligned - start);
  const uintptr_t end = start + len + kHugePageBytes;
  if (end > aligned + len) munmap(reinterpret_cast<void*>(aligned + len), end - (aligned + len));
  // Advice only: where THP is off the mapping works on 4 KiB pages as before.
  madvise(reinterpret_cast<void*>(aligned), len, MADV_HUGEPAGE);
  return reinterpret_cast<void*>(aligned);
}

void free_large(void* p, size_t bytes) noexcept {
  if (!p) return;
  if (bytes < kHugeArrayMinBytes) return ::operator delete (p, std::align_val_t{64});
  munmap(p, (bytes + kHugePageBytes - 1) & ~(kHugePageBytes - 1));
}

}  // namespace tracer
