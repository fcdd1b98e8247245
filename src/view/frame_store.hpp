// The newest frame of the viewer, and waiting for a newer one. One slot, never a queue: a client
// that reads slowly skips the frames it missed and gets the latest, so a slow browser costs the
// server nothing that grows.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

namespace tracer::view {

struct Frame {
  uint64_t seq = 0;         // 1, 2, ... in publication order
  uint64_t generation = 0;  // the view state it shows (ViewSession::state()'s "generation")
  std::string mime;         // image/jpeg while refining, image/png once the target is reached
  std::string bytes;
  int width = 0, height = 0;                       // of this image (smaller than the view's while previewing a move)
  uint32_t spp = 0;                                // samples in every pixel so far
  uint32_t spp_target = 0;                         // what the accumulation stops at
  double pass_fraction = 0.0;                      // of the pass in progress, 0 at a pass boundary
  bool preview = false;                            // a reduced-resolution frame of a camera in motion
  bool complete = false;                           // spp == spp_target: nothing more will come for this state
  bool denoised = false;                           // the film's samples so far, denoised (--denoise)
  double frame_ms = 0.0;                           // rendering time of the last pass (or of the preview)
  double msamples_per_s = 0.0, mrays_per_s = 0.0;  // over this state's accumulation so far
};

class FrameStore {
 public:
  void publish(std::shared_ptr<Frame> frame) {
    {
      const std::lock_guard lock(mu_);
      frame->seq = ++seq_;
      latest_ = std::move(frame);
    }
    cv_.notify_all();
  }
  // The latest frame if it is newer than `after`, waiting up to `timeout` for one; null if none
  // came or close() was called.
  std::shared_ptr<const Frame> wait_newer(uint64_t after, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mu_);
    cv_.wait_for(lock, timeout, [&] { return closed_ || (latest_ && latest_->seq > after); });
    if (closed_ || !latest_ || latest_->seq <= after) return nullptr;
    return latest_;
  }
  std::shared_ptr<const Frame> latest() const {
    const std::lock_guard lock(mu_);
    return latest_;
  }
  // Wakes every waiter for good (the server is stopping).
  void close() {
    {
      const std::lock_guard lock(mu_);
      closed_ = true;
    }
    cv_.notify_all();
  }
  bool closed() const {
    const std::lock_guard lock(mu_);
    return closed_;
  }

 private:
  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::shared_ptr<const Frame> latest_;
  uint64_t seq_ = 0;
  bool closed_ = false;
};

}  // namespace tracer::view
