// Triangles eight to a SIMD pack (SoA), one per lane: the 8-wide BVH's leaves and the SIMD brute
// force test a ray against a pack in one pass.
#pragma once

#include <cstdint>
#include <span>

#include "base/invalid_index.hpp"
#include "scene/scene.hpp"

namespace tracer {

inline constexpr int kWideWidth = 8;

// Up to eight triangles in SoA form, one per lane, tested against one ray in one SIMD pass.
// Unused lanes hold NaN vertices, which fail every comparison and so never hit.
struct alignas(64) TrianglePack {
  float v[3][3][kWideWidth];  // [vertex][axis][lane]
  // The scene triangle in each lane (its index in Scene::triangles, which the exact-edge fallback
  // and the any-hit bundles read), or kInvalidIndex for padding: a hit names its triangle with
  // no further lookup.
  uint32_t id[kWideWidth];
};

// Packs the scene triangles ids[first, first+count) (count <= 8) into one TrianglePack: lane k
// holds triangles[ids[first + k]] and that id; padding lanes are NaN.
TrianglePack make_triangle_pack(std::span<const Triangle> triangles, std::span<const uint32_t> ids, uint32_t first,
                                uint32_t count);

}  // namespace tracer
