// Image tiles: the unit of parallel work. Rectangles only; nothing here knows what a pixel holds.
#pragma once

#include <vector>

namespace tracer {

struct Tile {
  int x0, y0, x1, y1;  // half-open pixel rectangle [x0, x1) x [y0, y1)
  int pixel_count() const { return (x1 - x0) * (y1 - y0); }
};

// Tiles of tile_w x tile_h in row-major order; edge tiles are clipped to the image.
std::vector<Tile> make_tiles(int width, int height, int tile_w, int tile_h);

}  // namespace tracer
