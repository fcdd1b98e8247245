// The 8-wide tree over any set of boxes (wide_bvh_build.cpp): the 8-wide BVH's over triangles,
// whose leaves become packs, and the two-level tree's over instances, whose leaves are one each.
#pragma once

#include <cstdint>
#include <vector>

#include "accel/builders/prim_split.hpp"
#include "accel/wide_bvh/wide_bvh.hpp"

namespace tracer {

// A leaf's primitives: splitter.refs()[first, first + count).
struct LeafRun {
  uint32_t first, count;
};

// Builds an 8-wide tree over `splitter`'s primitives with leaves of at most `leaf_size` (splits by
// options' SAH; options.max_leaf at most leaf_size): `nodes`, in which a leaf child's `child` is
// the index of its run in `runs`, and `runs`. Returns the bounds of every primitive. Run inside
// exec.run.
Aabb build_wide_tree(PrimSplitter& splitter, const BvhBuildOptions& options, const Executor& exec, uint32_t leaf_size,
                     WideNodeArray& nodes, std::vector<LeafRun>& runs);

}  // namespace tracer
