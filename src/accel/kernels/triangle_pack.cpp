#include "accel/kernels/triangle_pack.hpp"

#include <limits>

namespace tracer {

TrianglePack make_triangle_pack(std::span<const Triangle> triangles, std::span<const uint32_t> ids, uint32_t first,
                                uint32_t count) {
  TrianglePack p;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int lane = 0; lane < kWideWidth; ++lane) {
    const bool used = uint32_t(lane) < count;
    const uint32_t id = ids[used ? first + uint32_t(lane) : first];
    const Triangle& t = triangles[id];
    const Vec3 vs[3] = {t.v0, t.v1, t.v2};
    for (int vtx = 0; vtx < 3; ++vtx) {
      for (int axis = 0; axis < 3; ++axis) p.v[vtx][axis][lane] = used ? vs[vtx][axis] : nan;
    }
    p.id[lane] = used ? id : kInvalidIndex;
  }
  return p;
}

}  // namespace tracer
