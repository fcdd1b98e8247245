// Render schedulers: the study's designs side by side with the one the field uses. All of them
// hand out disjoint pixel rectangles to `render_tile`, so the image is the same from every one.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>

#include "accel/accelerator.hpp"
#include "base/errors.hpp"
#include "render/shading.hpp"
#include "sched/thread_count.hpp"

namespace tracer {

enum class SchedKind {
  Seq,     // one thread, row by row
  Async,   // the study's: one std::async(std::launch::async) per image row
  Queue,   // the study's: N threads popping row blocks from a mutex-guarded LIFO vector
  Atomic,  // lock-free: N threads claiming square tiles with one fetch_add each
  Tbb,     // oneTBB parallel_for over square tiles, work stealing (the default)
};

struct SchedOptions {
  SchedKind kind = SchedKind::Tbb;
  int threads = 0;  // 0: all hardware threads
  int tile = 16;    // square tile edge for atomic and tbb
  int block = 64;   // pixels per row block for queue
};

// Shared between the scheduler, the caller (progress, cancellation) and tests.
struct RenderControl {
  CancelFlag cancel = nullptr;  // set (e.g. by SIGINT) to stop at the next tile
  std::atomic<uint64_t> pixels_done{0};
  std::atomic<uint64_t> rays_done{0};
  AtomicRayCounts counts;
  std::function<void(const Tile&)> on_tile;  // test hook, called once per rendered tile
  bool cancelled() const { return is_cancelled(cancel); }
};

// Renders ctx.framebuffer with `accel`. Returns false if cancelled before finishing (tiles not
// reached are left untouched).
bool render_image(const Accelerator& accel, const RenderContext& ctx, const SchedOptions& options,
                  RenderControl& control);

SchedKind parse_sched(const std::string& name);  // throws UsageError
std::string to_string(SchedKind kind);

}  // namespace tracer
