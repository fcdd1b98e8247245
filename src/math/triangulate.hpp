// A polygon's triangles: quads split along the shorter diagonal, larger polygons ear-clipped.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "math/vec.hpp"

namespace tracer {

// The triangles of the polygon of corners p[0..n), as corner positions within it, in its
// winding, into `out` (cleared first). Quads split along the shorter diagonal (as tinyobjloader
// does); larger polygons are ear-clipped in the plane of their Newell normal, and fanned where
// that finds no ear (a self-intersecting outline) or the polygon has more than 64 corners. Always
// n - 2 triangles.
void triangulate(const Vec3* p, uint32_t n, std::vector<std::array<uint32_t, 3>>& out);

}  // namespace tracer
