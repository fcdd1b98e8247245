#include "sched/scheduler.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <deque>
#include <future>
#include <mutex>
#include <thread>
#include <vector>

#include "base/errors.hpp"

namespace tracer {

namespace {

// Renders one tile: the only place the accelerator variant is dispatched.
void run_tile(const Accelerator& accel, const RenderContext& ctx, RenderControl& control, const Tile& tile) {
  if (control.cancelled()) return;
  const RayCounts counts = accel.visit([&](const auto& a) { return render_tile(a, ctx, tile); });
  control.counts.add(counts);
  control.rays_done.fetch_add(counts.total(), std::memory_order_relaxed);
  // acq_rel: the final acquire load after the schedulers' joins then orders every tile's pixel
  // writes before the image is read, in a form ThreadSanitizer sees even through oneTBB.
  control.pixels_done.fetch_add(uint64_t(tile.pixel_count()), std::memory_order_acq_rel);
  if (control.on_tile) control.on_tile(tile);
}

void render_seq(const Accelerator& accel, const RenderContext& ctx, RenderControl& control) {
  const int w = ctx.framebuffer->width(), h = ctx.framebuffer->height();
  for (int y = 0; y < h && !control.cancelled(); ++y) run_tile(accel, ctx, control, Tile{0, y, w, y + 1});
}

void render_async(const Accelerator& accel, const RenderContext& ctx, RenderControl& control) {
  const int w = ctx.framebuffer->width(), h = ctx.framebuffer->height();
  // The study launched every row at once. Past a few hundred rows in flight that only exhausts
  // thread limits, so the oldest row is awaited first; each row still gets its own thread.
  constexpr size_t kMaxInFlight = 256;
  std::deque<std::future<void>> rows;
  for (int y = 0; y < h && !control.cancelled(); ++y) {
    if (rows.size() >= kMaxInFlight) {
      rows.front().get();
      rows.pop_front();
    }
    rows.push_back(std::async(std::launch::async, [&, y] { run_tile(accel, ctx, control, Tile{0, y, w, y + 1}); }));
  }
  for (auto& f : rows) f.get();
}

void render_queue(const Accelerator& accel, const RenderContext& ctx, const SchedOptions& o, RenderControl& control) {
  const int w = ctx.framebuffer->width(), h = ctx.framebuffer->height();
  std::vector<Tile> blocks = make_tiles(w, h, o.block, 1);
  std::reverse(blocks.begin(), blocks.end());  // popped from the back: top-left first
  std::mutex mutex;
  const auto worker = [&] {
    for (;;) {
      Tile tile;
      {
        std::lock_guard lock(mutex);
        if (blocks.empty()) return;  // checked under the lock, as the study's fix did
        tile = blocks.back();
        blocks.pop_back();
      }
      if (control.cancelled()) return;
      run_tile(accel, ctx, control, tile);
    }
  };
  std::vector<std::thread> pool;
  for (int i = 0; i < resolve_thread_count(o.threads); ++i) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
}

void render_atomic(const Accelerator& accel, const RenderContext& ctx, const SchedOptions& o, RenderControl& control) {
  const std::vector<Tile> tiles = make_tiles(ctx.framebuffer->width(), ctx.framebuffer->height(), o.tile, o.tile);
  std::atomic<size_t> next{0};
  const auto worker = [&] {
    for (size_t i = next.fetch_add(1, std::memory_order_relaxed); i < tiles.size() && !control.cancelled();
         i = next.fetch_add(1, std::memory_order_relaxed)) {
      run_tile(accel, ctx, control, tiles[i]);
    }
  };
  const int n = resolve_thread_count(o.threads);
  std::vector<std::thread> pool;
  for (int i = 1; i < n; ++i) pool.emplace_back(worker);
  worker();  // the calling thread is worker 0
  for (auto& t : pool) t.join();
}

void render_tbb(const Accelerator& accel, const RenderContext& ctx, const SchedOptions& o, RenderControl& control) {
  const std::vector<Tile> tiles = make_tiles(ctx.framebuffer->width(), ctx.framebuffer->height(), o.tile, o.tile);
  tbb::task_arena arena(resolve_thread_count(o.threads));
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles.size(), 1), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) run_tile(accel, ctx, control, tiles[i]);
    });
  });
}

}  // namespace

bool render_image(const Accelerator& accel, const RenderContext& ctx, const SchedOptions& options,
                  RenderControl& control) {
  switch (options.kind) {
    case SchedKind::Seq:
      render_seq(accel, ctx, control);
      break;
    case SchedKind::Async:
      render_async(accel, ctx, control);
      break;
    case SchedKind::Queue:
      render_queue(accel, ctx, options, control);
      break;
    case SchedKind::Atomic:
      render_atomic(accel, ctx, options, control);
      break;
    case SchedKind::Tbb:
      render_tbb(accel, ctx, options, control);
      break;
  }
  (void)control.pixels_done.load(std::memory_order_acquire);
  return !control.cancelled();
}

SchedKind parse_sched(const std::string& name) {
  if (name == "seq") return SchedKind::Seq;
  if (name == "async") return SchedKind::Async;
  if (name == "queue") return SchedKind::Queue;
  if (name == "atomic") return SchedKind::Atomic;
  if (name == "tbb") return SchedKind::Tbb;
  throw UsageError("--sched: unknown scheduler '" + name + "' (seq, async, queue, atomic, tbb)");
}

std::string to_string(SchedKind kind) {
  switch (kind) {
    case SchedKind::Seq:
      return "seq";
    case SchedKind::Async:
      return "async";
    case SchedKind::Queue:
      return "queue";
    case SchedKind::Atomic:
      return "atomic";
    case SchedKind::Tbb:
      return "tbb";
  }
  return "?";
}

}  // namespace tracer
