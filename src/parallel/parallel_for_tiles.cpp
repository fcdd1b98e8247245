#include "parallel/parallel_for_tiles.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <deque>
#include <future>
#include <mutex>
#include <thread>

namespace tracer {

std::vector<Tile> make_tiles(int width, int height, int tile_w, int tile_h) {
  std::vector<Tile> tiles;
  for (int y = 0; y < height; y += tile_h) {
    for (int x = 0; x < width; x += tile_w) {
      tiles.push_back({x, y, std::min(x + tile_w, width), std::min(y + tile_h, height)});
    }
  }
  return tiles;
}

std::vector<Tile> tiles_for(int width, int height, const SchedOptions& o) {
  switch (o.kind) {
    case SchedKind::Seq:
    case SchedKind::Async:
      return make_tiles(width, height, width, 1);
    case SchedKind::Queue:
      return make_tiles(width, height, o.block, 1);
    case SchedKind::Atomic:
    case SchedKind::Tbb:
      break;
  }
  return make_tiles(width, height, o.tile, o.tile);
}

namespace {

using TileFn = std::function<void(const Tile&)>;

void run_seq(const std::vector<Tile>& tiles, CancelFlag cancel, const TileFn& fn) {
  for (const Tile& t : tiles) {
    if (is_cancelled(cancel)) return;
    fn(t);
  }
}

void run_async(const std::vector<Tile>& tiles, CancelFlag cancel, const TileFn& fn) {
  // The study launched every row at once. Past a few hundred rows in flight that only exhausts
  // thread limits, so the oldest row is awaited first; each row still gets its own thread.
  constexpr size_t kMaxInFlight = 256;
  std::deque<std::future<void>> rows;
  for (const Tile& t : tiles) {
    if (is_cancelled(cancel)) break;
    if (rows.size() >= kMaxInFlight) {
      rows.front().get();
      rows.pop_front();
    }
    rows.push_back(std::async(std::launch::async, [&fn, &t] { fn(t); }));
  }
  for (auto& f : rows) f.get();
}

void run_queue(std::vector<Tile> blocks, int threads, CancelFlag cancel, const TileFn& fn) {
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
      if (is_cancelled(cancel)) return;
      fn(tile);
    }
  };
  std::vector<std::thread> pool;
  for (int i = 0; i < threads; ++i) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
}

void run_atomic(const std::vector<Tile>& tiles, int threads, CancelFlag cancel, const TileFn& fn) {
  std::atomic<size_t> next{0};
  const auto worker = [&] {
    for (size_t i = next.fetch_add(1, std::memory_order_relaxed); i < tiles.size() && !is_cancelled(cancel);
         i = next.fetch_add(1, std::memory_order_relaxed)) {
      fn(tiles[i]);
    }
  };
  std::vector<std::thread> pool;
  for (int i = 1; i < threads; ++i) pool.emplace_back(worker);
  worker();  // the calling thread is worker 0
  for (auto& t : pool) t.join();
}

void run_tbb(const std::vector<Tile>& tiles, int threads, const TileFn& fn) {
  tbb::task_arena arena(threads);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles.size(), 1), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) fn(tiles[i]);
    });
  });
}

}  // namespace

bool parallel_for_tiles(int width, int height, const SchedOptions& options, CancelFlag cancel, const TileFn& fn) {
  std::vector<Tile> tiles = tiles_for(width, height, options);
  // Every tile ends with an acq_rel increment and the loop with an acquire load, so whatever a
  // tile wrote happens-before the return in a form ThreadSanitizer sees, even through oneTBB.
  // A tile that starts after the cancel does nothing, whichever strategy started it.
  std::atomic<size_t> finished{0};
  const TileFn counted = [&](const Tile& t) {
    if (is_cancelled(cancel)) return;
    fn(t);
    finished.fetch_add(1, std::memory_order_acq_rel);
  };
  const int threads = thread_count(options);
  switch (options.kind) {
    case SchedKind::Seq:
      run_seq(tiles, cancel, counted);
      break;
    case SchedKind::Async:
      run_async(tiles, cancel, counted);
      break;
    case SchedKind::Queue:
      run_queue(std::move(tiles), threads, cancel, counted);
      break;
    case SchedKind::Atomic:
      run_atomic(tiles, threads, cancel, counted);
      break;
    case SchedKind::Tbb:
      run_tbb(tiles, threads, counted);
      break;
  }
  (void)finished.load(std::memory_order_acquire);
  return !is_cancelled(cancel);
}

}  // namespace tracer
