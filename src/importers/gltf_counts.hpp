// Counts of a glTF node subtree, taken without expanding its instances: what the expansion
// would place (Placed: the memory check before loading) and what tracer info prints (Summary).
// Both saturate at kSaturated, so a file that reuses a mesh 2^60 times counts without overflow.
#pragma once

#include <algorithm>
#include <cstdint>

#include "importers/indexed_mesh.hpp"
#include "math/aabb.hpp"
#include "math/affine.hpp"

namespace tracer::gltf {

inline constexpr uint64_t kSaturated = uint64_t(1) << 62;  // counts stop growing here

// What node `index` and its descendants place: triangles and primitives (each a geometry of
// the scene). Saturating at kSaturated.
struct Placed {
  uint64_t triangles = 0, primitives = 0, nodes = 0;  // nodes: visits of the expansion
  uint64_t instances = 0;                             // placements of a mesh
  void add(const Placed& o) {
    triangles = std::min(triangles + o.triangles, kSaturated);
    primitives = std::min(primitives + o.primitives, kSaturated);
    nodes = std::min(nodes + o.nodes, kSaturated);
    instances = std::min(instances + o.instances, kSaturated);
  }
};
// A subtree's sums for tracer info, in the frame of its node's parent.
struct Summary {
  Placed placed;
  uint64_t vertices = 0, degenerate = 0, emissive = 0;
  Aabb box;
  uint64_t listed = 0;  // nodes walked to place its cameras and point lights (0: it holds none)
  void add(const Summary& o, const Affine& to) {
    placed.add(o.placed);
    vertices = std::min(vertices + o.vertices, kSaturated);
    degenerate = std::min(degenerate + o.degenerate, kSaturated);
    emissive = std::min(emissive + o.emissive, kSaturated);
    if (!o.box.empty()) {
      for (int c = 0; c < 8; ++c) {
        box.extend(to.point(
            Vec3{c & 1 ? o.box.hi.x : o.box.lo.x, c & 2 ? o.box.hi.y : o.box.lo.y, c & 4 ? o.box.hi.z : o.box.lo.z}));
      }
    }
    listed = std::min(listed + o.listed, kSaturated);
  }
};

// One placed primitive's Summary, in its node's frame.
Summary summary_of(const IndexedMesh& mesh, bool emissive);

}  // namespace tracer::gltf
