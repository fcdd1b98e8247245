// Large arrays on transparent huge pages. On a Linux kernel whose THP mode is `madvise` (Debian's
// default), memory asks for 2 MiB pages with madvise(MADV_HUGEPAGE): the first touch
// of each 2 MiB then costs one page fault instead of 512, and the TLB holds 512 times the reach.
// In a VM a fault costs 7-16 us, which at millions of triangles is seconds of a build (Embree's
// allocator asks for huge pages the same way). Small arrays are plain 64-byte aligned blocks.
#pragma once

#include <cstddef>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace tracer {

inline constexpr size_t kHugePageBytes = size_t(2) << 20;
// From this size an array is 2 MiB-aligned and advised to live on huge pages.
inline constexpr size_t kHugeArrayMinBytes = size_t(1) << 20;

// At least `bytes`, 64-byte aligned; 2 MiB-aligned and huge-page advised from kHugeArrayMinBytes.
// Throws std::bad_alloc. Free with free_large(p, bytes), the same `bytes`.
void* allocate_large(size_t bytes);
void free_large(void* p, size_t bytes) noexcept;
// The same, zero-filled: from kHugeArrayMinBytes a fresh mapping, whose pages come zeroed from the
// kernel when first touched -- by whichever thread writes them first, not all by the caller.
// Free with free_large_zeroed(p, bytes).
void* allocate_large_zeroed(size_t bytes);
void free_large_zeroed(void* p, size_t bytes) noexcept;

// A std::allocator on allocate_large: cache-line aligned, on huge pages when large.
template <class T>
struct HugePageAllocator {
  using value_type = T;
  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) {}
  T* allocate(size_t n) { return static_cast<T*>(allocate_large(n * sizeof(T))); }
  void deallocate(T* p, size_t n) noexcept { free_large(p, n * sizeof(T)); }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const {
    return true;
  }
};

// HugePageAllocator for arrays of plain data whose resize() leaves new elements uninitialised
// (implicit-lifetime aggregates the caller overwrites, often in parallel: zeroing them first
// costs a pass over the memory).
template <class T>
struct LargeArrayAllocator : HugePageAllocator<T> {
  LargeArrayAllocator() = default;
  template <class U>
  LargeArrayAllocator(const LargeArrayAllocator<U>&) {}
  template <class U>
  void construct(U*) noexcept {
    static_assert(std::is_trivially_copyable_v<U> && std::is_trivially_destructible_v<U>);
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

// A vector on HugePageAllocator, value-initialising as std::vector does.
template <class T>
using LargeVector = std::vector<T, HugePageAllocator<T>>;

struct ZeroFilled {};
inline constexpr ZeroFilled kZeroFilled{};

// A fixed-size array of T from allocate_large, left uninitialised (or zero-filled, when asked).
template <class T>
class LargeBuffer {
 public:
  LargeBuffer() = default;
  explicit LargeBuffer(size_t n) : n_(n), p_(static_cast<T*>(allocate_large(n * sizeof(T)))) {
    static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);
  }
  LargeBuffer(size_t n, ZeroFilled) : n_(n), zeroed_(true), p_(static_cast<T*>(allocate_large_zeroed(n * sizeof(T)))) {
    static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);
  }
  LargeBuffer(LargeBuffer&& o) noexcept
      : n_(std::exchange(o.n_, 0)), zeroed_(o.zeroed_), p_(std::exchange(o.p_, nullptr)) {}
  LargeBuffer& operator=(LargeBuffer&& o) noexcept {
    std::swap(n_, o.n_);
    std::swap(zeroed_, o.zeroed_);
    std::swap(p_, o.p_);
    return *this;
  }
  ~LargeBuffer() {
    if (!p_) return;
    if (zeroed_) {
      free_large_zeroed(p_, n_ * sizeof(T));
    } else {
      free_large(p_, n_ * sizeof(T));
    }
  }
  T* get() const { return p_; }
  T& operator[](size_t i) const { return p_[i]; }
  size_t size() const { return n_; }

 private:
  size_t n_ = 0;
  bool zeroed_ = false;
  T* p_ = nullptr;
};

}  // namespace tracer
