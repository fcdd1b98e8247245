// A number of bytes that threads take from and give back, waiting while too few are left: the
// transient memory of decodes running at once stays within what is left of a budget.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <mutex>

namespace tracer {

class ByteBudget {
 public:
  explicit ByteBudget(uint64_t bytes) : left_(bytes) {}
  // Waits until `bytes` are left, then takes them. A request larger than the whole budget would
  // wait forever: callers admit only requests that fit it alone.
  void take(uint64_t bytes) {
    std::unique_lock lock(mutex_);
    freed_.wait(lock, [&] { return left_ >= bytes; });
    left_ -= bytes;
  }
  void give(uint64_t bytes) {
    {
      const std::lock_guard lock(mutex_);
      left_ += bytes;
    }
    freed_.notify_all();
  }

  // Takes bytes for its lifetime.
  class Taken {
   public:
    Taken(ByteBudget& budget, uint64_t bytes) : budget_(budget), bytes_(bytes) { budget_.take(bytes_); }
    ~Taken() { budget_.give(bytes_); }
    Taken(const Taken&) = delete;
    Taken& operator=(const Taken&) = delete;

   private:
    ByteBudget& budget_;
    uint64_t bytes_;
  };

 private:
  std::mutex mutex_;
  std::condition_variable freed_;
  uint64_t left_;
};

}  // namespace tracer
