#include "parallel/parallel_for_tiles.hpp"

#include <algorithm>

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
  switch (o.strategy) {
    case Strategy::Seq:
    case Strategy::Async:
      return make_tiles(width, height, width, 1);
    case Strategy::Queue:
      return make_tiles(width, height, o.block, 1);
    case Strategy::Atomic:
    case Strategy::Tbb:
      break;
  }
  return make_tiles(width, height, o.tile, o.tile);
}

bool parallel_for_tiles(int width, int height, const SchedOptions& options, CancelFlag cancel,
                        const std::function<void(const Tile&)>& fn) {
  const std::vector<Tile> tiles = tiles_for(width, height, options);
  return Executor(options.strategy, options.threads)
      .for_each(
          tiles.size(), [&](size_t i) { fn(tiles[i]); }, cancel);
}

}  // namespace tracer
