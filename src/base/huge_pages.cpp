#include "base/huge_pages.hpp"

#include <sys/mman.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>

namespace tracer {

// From the C heap, so freed arrays are reused as malloc reuses any block (a process that loads
// twice, or a benchmark that keeps freed memory, does not fault them in again); aligned to 2 MiB
// and advised, because THP only backs aligned 2 MiB ranges.
void* allocate_large(size_t bytes) {
  if (bytes < kHugeArrayMinBytes) return ::operator new (bytes == 0 ? 1 : bytes, std::align_val_t{64});
  const size_t len = (bytes + kHugePageBytes - 1) & ~(kHugePageBytes - 1);
  void* p = std::aligned_alloc(kHugePageBytes, len);
  if (!p) throw std::bad_alloc();
  madvise(p, len, MADV_HUGEPAGE);  // advice only: without THP the array works on 4 KiB pages
  return p;
}

void free_large(void* p, size_t bytes) noexcept {
  if (!p) return;
  if (bytes < kHugeArrayMinBytes) return ::operator delete (p, std::align_val_t{64});
  std::free(p);
}

void* allocate_large_zeroed(size_t bytes) {
  if (bytes < kHugeArrayMinBytes) return std::memset(allocate_large(bytes), 0, bytes);
  // A mapping 2 MiB longer than asked, trimmed to a 2 MiB-aligned one: THP backs aligned ranges.
  const size_t len = (bytes + kHugePageBytes - 1) & ~(kHugePageBytes - 1);
  void* raw = mmap(nullptr, len + kHugePageBytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED) throw std::bad_alloc();
  const uintptr_t start = reinterpret_cast<uintptr_t>(raw);
  const uintptr_t aligned = (start + kHugePageBytes - 1) & ~uintptr_t(kHugePageBytes - 1);
  if (aligned > start) munmap(raw, aligned - start);
  if (const size_t tail = start + len + kHugePageBytes - (aligned + len); tail > 0) {
    munmap(reinterpret_cast<void*>(aligned + len), tail);
  }
  madvise(reinterpret_cast<void*>(aligned), len, MADV_HUGEPAGE);
  return reinterpret_cast<void*>(aligned);
}

void free_large_zeroed(void* p, size_t bytes) noexcept {
  if (!p) return;
  if (bytes < kHugeArrayMinBytes) return free_large(p, bytes);
  munmap(p, (bytes + kHugePageBytes - 1) & ~(kHugePageBytes - 1));
}

}  // namespace tracer
