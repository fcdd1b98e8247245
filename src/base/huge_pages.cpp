#include "base/huge_pages.hpp"

#include <sys/mman.h>

#include <cstdlib>

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

}  // namespace tracer
