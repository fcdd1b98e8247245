// Spatial splits (SBVH, Stich, Friedrich and Dietrich 2009): a node may split space rather than
// its set of triangles, so a triangle crossing the plane is referenced on both sides, each
// reference bounded by the part of the triangle on its side. Long triangles (walls, floors,
// columns) then stop inflating every box they cross; the price is more references, kept within a
// budget by the splitter (PrimSplitter).
#pragma once

#include <cstdint>
#include <vector>

#include "accel/builders/prim_split.hpp"

namespace tracer {

inline constexpr int kMaxSpatialBins = 32;

// The boxes of the parts of `tri` left (x[axis] <= pos) and right (x[axis] >= pos) of a plane,
// each within `box` (the reference's box, already cut by earlier splits). A side the triangle
// does not reach is empty. The cut points are rounded, so the boxes are widened by a few units in
// the last place of the scene's coordinates: a reference's box always holds its part.
void clip_triangle(const Triangle& tri, const Aabb& box, int axis, float pos, Aabb& left, Aabb& right);

// A plane through one of `bins` equal slabs of a node's box on one axis.
struct SpatialSplit {
  int axis = -1;  // -1: none found
  int bin = 0;    // the plane is the left edge of this slab
  int bins = 0;
  float lo = 0.0f, width = 0.0f;  // of the slabs on `axis`
  float raw = kInfinity;          // half area x references, summed over both sides (as the SAH's)
  Aabb left_box, right_box;       // as binned
  uint32_t left_count = 0, right_count = 0;
  float plane() const { return lo + width * float(bin); }
  // The slab holding coordinate x, as the binning placed it.
  int slab(float x) const;
};

// The cheapest spatial split of refs[begin, end) (their bounds `box`) over `bins` slabs per axis.
SpatialSplit find_spatial_split(const Triangle* tris, const PrimRef* refs, uint32_t begin, uint32_t end,
                                const Aabb& box, int bins);

// Sorts refs[begin, end) to the two sides of `split` (a reference crossing the plane to both,
// cut, unless keeping it whole on one side costs less: Stich's reference unsplitting).
void divide_spatially(const Triangle* tris, const PrimRef* refs, uint32_t begin, uint32_t end,
                      const SpatialSplit& split, std::vector<PrimRef>& left, std::vector<PrimRef>& right);

}  // namespace tracer
