#include "frontend/progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace tracer::frontend {

ProgressBar::ProgressBar(bool enabled, uint64_t total_pixels, const std::atomic<uint64_t>& pixels,
                         const std::atomic<uint64_t>& rays, const std::atomic<uint64_t>* active, uint64_t image_pixels)
    : total_(total_pixels),
      pixels_(pixels),
      rays_(rays),
      active_(active),
      image_pixels_(image_pixels),
      start_(std::chrono::steady_clock::now()) {
  if (enabled && ::isatty(STDERR_FILENO)) thread_ = std::thread([this] { run(); });
}

void ProgressBar::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void ProgressBar::run() {
  using namespace std::chrono;
  std::unique_lock lock(mutex_);
  if (cv_.wait_for(lock, seconds(1), [this] { return stopping_; })) return;  // short renders: no bar
  for (;;) {
    const double elapsed = duration<double>(steady_clock::now() - start_).count();
    const double frac = total_ ? double(pixels_.load()) / double(total_) : 1.0;
    const double eta = frac > 0.0 ? elapsed * (1.0 - frac) / frac : 0.0;
    const double mrays = double(rays_.load()) / elapsed * 1e-6;
    constexpr int kWidth = 30;
    char bar[kWidth + 1];
    for (int i = 0; i < kWidth; ++i) bar[i] = i < int(frac * kWidth) ? '#' : '.';
    bar[kWidth] = '\0';
    std::fprintf(stderr, "\r[%s] %5.1f%%  %6.1fs elapsed  ETA %6.1fs  %8.2f Mrays/s", bar, frac * 100.0, elapsed, eta,
                 mrays);
    if (active_ && image_pixels_) {
      std::fprintf(stderr, "  active %5.1f%%", 100.0 * double(active_->load()) / double(image_pixels_));
    }
    std::fflush(stderr);
    drawn_ = true;
    if (cv_.wait_for(lock, milliseconds(200), [this] { return stopping_; })) break;
  }
  if (drawn_) std::fprintf(stderr, "\r%105s\r", "");  // clear the line
}

}  // namespace tracer::frontend
