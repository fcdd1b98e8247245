// Rays and hit records, shaped like Embree's RTCRay/RTCHit so the reference backend maps 1:1.
#pragma once

#include <cstdint>
#include <limits>

#include "base/invalid_index.hpp"
#include "math/vec.hpp"

namespace tracer {

inline constexpr float kInfinity = std::numeric_limits<float>::infinity();

struct Ray {
  Vec3 org;
  float tnear = 0.0f;
  Vec3 dir;
  float tfar = kInfinity;
};

// Closest hit. `u`, `v` are the barycentric weights of vertices 1 and 2 (Embree's convention):
// p = (1-u-v)*v0 + u*v1 + v*v2. `tri` is the scene-wide triangle index, kept for shading;
// geomID/primID name the OBJ group/object and the triangle within it.
struct Hit {
  float t = kInfinity;
  float u = 0.0f, v = 0.0f;
  uint32_t geomID = kInvalidIndex;
  uint32_t primID = kInvalidIndex;
  uint32_t tri = kInvalidIndex;
  uint32_t inst = kInvalidIndex;  // the instance whose mesh holds `tri` (instanced scenes)

  bool valid() const { return tri != kInvalidIndex; }
};

}  // namespace tracer
