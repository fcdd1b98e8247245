// Where a texture slot reads on a triangle: its set's corner coordinates moved by its transform,
// and those interpolated at a point's barycentric coordinates. Shared by shading (shade/) and by
// what the scene computes from its textures (the emitters' power).
#pragma once

#include <cstdint>

#include "scene/scene.hpp"

namespace tracer {

// The coordinates at barycentric (b1, b2) (the weights of corners 1 and 2, as Hit's u and v)
// interpolated from corners `c`.
inline Vec2 interpolate_uv(const Vec2* c, float b1, float b2) {
  const float w = 1.0f - b1 - b2;
  return {c[0].x * w + c[1].x * b1 + c[2].x * b2, c[0].y * w + c[1].y * b1 + c[2].y * b2};
}

// The corners' coordinates that `slot` reads on scene triangle `tri`: its set's, moved by its
// transform. False where the slot is empty or the scene has no such set.
inline bool slot_corners(const Scene& scene, uint32_t tri, const TextureSlot& slot, Vec2 out[3]) {
  if (!slot.present()) return false;
  const LargeVector<Vec2>& set = slot.uv_set == 1 ? scene.corner_uvs1 : scene.corner_uvs;
  if (set.empty()) return false;
  const Vec2* c = &set[3 * size_t(tri)];
  for (int k = 0; k < 3; ++k) out[k] = slot.transform.identity() ? c[k] : slot.transform.apply(c[k]);
  return true;
}

}  // namespace tracer
