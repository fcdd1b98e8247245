// A progress line on stderr for long renders: percent, elapsed, ETA, Mrays/s (and with adaptive
// sampling the share of pixels still sampled). Shown only when
// stderr is a terminal and the render has run for over a second; never written to logs or pipes.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>

#include "render/render_settings.hpp"

namespace tracer::frontend {

// The pixel samples `frames` images of `settings` take at most: a progress bar's whole (adaptive
// sampling may end sooner).
inline uint64_t pixel_samples(const RenderSettings& s, int frames) {
  return uint64_t(s.width) * uint64_t(s.height) * uint64_t(s.spp) * uint64_t(frames);
}

class ProgressBar {
 public:
  // `active` (adaptive sampling): the pixels still taking samples, of `image_pixels`.
  ProgressBar(bool enabled, uint64_t total_pixels, const std::atomic<uint64_t>& pixels,
              const std::atomic<uint64_t>& rays, const std::atomic<uint64_t>* active = nullptr,
              uint64_t image_pixels = 0);
  ~ProgressBar() { stop(); }
  void stop();

 private:
  void run();
  uint64_t total_;
  const std::atomic<uint64_t>& pixels_;
  const std::atomic<uint64_t>& rays_;
  const std::atomic<uint64_t>* active_;
  uint64_t image_pixels_;
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable cv_;
  bool stopping_ = false, drawn_ = false;
  std::thread thread_;
};

}  // namespace tracer::frontend
