#include "math/triangulate.hpp"

#include <cmath>
#include <cstddef>
#include <iterator>

namespace tracer {

namespace {

// Polygons of more corners than this are fanned, not ear-clipped (ear clipping is cubic at worst).
constexpr size_t kMaxEarClipCorners = 64;

}  // namespace

void triangulate(const Vec3* p, uint32_t n, std::vector<std::array<uint32_t, 3>>& out) {
  out.clear();
  if (n == 3) {
    out.push_back({0, 1, 2});
    return;
  }
  if (n == 4) {
    const Vec3 e02 = p[2] - p[0], e13 = p[3] - p[1];
    const float sqr02 = e02.x * e02.x + e02.y * e02.y + e02.z * e02.z;
    const float sqr13 = e13.x * e13.x + e13.y * e13.y + e13.z * e13.z;
    if (sqr02 < sqr13) {
      out.push_back({0, 1, 2});
      out.push_back({0, 2, 3});
    } else {
      out.push_back({0, 1, 3});
      out.push_back({1, 2, 3});
    }
    return;
  }
  std::vector<uint32_t> left(n);
  for (uint32_t i = 0; i < n; ++i) left[i] = i;
  if (n <= kMaxEarClipCorners) {
    Vec3 normal{0.0f};
    for (uint32_t i = 0; i < n; ++i) normal = normal + cross(p[i], p[(i + 1) % n]);
    const float ax = std::fabs(normal.x), ay = std::fabs(normal.y), az = std::fabs(normal.z);
    const int drop = ax >= ay && ax >= az ? 0 : (ay >= az ? 1 : 2);
    const float sign = (drop == 0 ? normal.x : (drop == 1 ? normal.y : normal.z)) >= 0.0f ? 1.0f : -1.0f;
    const auto uv = [&](uint32_t i) -> Vec2 {
      const Vec3& q = p[i];
      return drop == 0 ? Vec2{q.y, q.z} : (drop == 1 ? Vec2{q.z, q.x} : Vec2{q.x, q.y});
    };
    const auto turn = [&](Vec2 a, Vec2 b, Vec2 c) {
      return sign * ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
    };
    while (left.size() > 3) {
      bool clipped = false;
      // Ears centred on corner 1 first: a convex polygon becomes the fan around corner 0.
      for (size_t j = 0; j < left.size() && !clipped; ++j) {
        const size_t m = left.size(), k = (j + 1) % m;
        const uint32_t a = left[(k + m - 1) % m], b = left[k], c = left[(k + 1) % m];
        const Vec2 pa = uv(a), pb = uv(b), pc = uv(c);
        if (turn(pa, pb, pc) <= 0.0f) continue;  // reflex or flat: not an ear
        bool empty = true;
        for (const uint32_t o : left) {
          if (o == a || o == b || o == c) continue;
          const Vec2 q = uv(o);
          if (turn(pa, pb, q) >= 0.0f && turn(pb, pc, q) >= 0.0f && turn(pc, pa, q) >= 0.0f) {
            empty = false;
            break;
          }
        }
        if (!empty) continue;
        out.push_back({a, b, c});
        left.erase(left.begin() + std::ptrdiff_t(k));
        clipped = true;
      }
      if (!clipped) break;
    }
  }
  for (size_t k = 1; k + 1 < left.size(); ++k) out.push_back({left[0], left[k], left[k + 1]});
}

}  // namespace tracer
