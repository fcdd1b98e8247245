// Watertight ray/triangle test (Woop, Benthin, Wald: "Watertight Ray/Triangle Intersection",
// JCGT 2013). The ray is sheared so it runs along +z from the origin; edge functions are then
// evaluated in 2D, and exactly-zero ones are redone in double, so a ray through a shared edge or
// vertex hits at least one of the triangles around it. Two-sided.
#pragma once

#include <type_traits>
#include <utility>

#include "math/ray.hpp"
#include "scene/scene.hpp"

namespace tracer {

// Per-ray constants of the shear, computed once per query.
struct RayShear {
  Vec3 org;
  int kx = 0, ky = 1, kz = 2;
  float sx = 0, sy = 0, sz = 1;

  RayShear() = default;
  explicit RayShear(const Ray& r) : org(r.org) {
    kz = max_dimension(abs(r.dir));
    kx = kz == 2 ? 0 : kz + 1;
    ky = kx == 2 ? 0 : kx + 1;
    if (r.dir[kz] < 0.0f) std::swap(kx, ky);  // keep the winding so U, V, W keep their signs
    // One division, not three: any shear works as long as every triangle sees the same one.
    sz = 1.0f / r.dir[kz];
    sx = r.dir[kx] * sz;
    sy = r.dir[ky] * sz;
  }
};

struct TriangleHit {
  float t, u, v;
};

// Hit if t lies in [tnear, tfar]; inclusive at both ends so callers can break ties on t themselves.
inline bool intersect_triangle(const RayShear& s, const Triangle& tri, float tnear, float tfar, TriangleHit& out) {
  // Each permuted coordinate is loaded straight from the triangle (no copy to index into).
  static_assert(sizeof(Vec3) == 3 * sizeof(float) && std::is_standard_layout_v<Vec3>);
  const float* o = &s.org.x;
  const float* p0 = &tri.v0.x;
  const float* p1 = &tri.v1.x;
  const float* p2 = &tri.v2.x;
  const float okx = o[s.kx], oky = o[s.ky], okz = o[s.kz];
  const float a_z = p0[s.kz] - okz, b_z = p1[s.kz] - okz, c_z = p2[s.kz] - okz;
  const float ax = (p0[s.kx] - okx) - s.sx * a_z, ay = (p0[s.ky] - oky) - s.sy * a_z;
  const float bx = (p1[s.kx] - okx) - s.sx * b_z, by = (p1[s.ky] - oky) - s.sy * b_z;
  const float cx = (p2[s.kx] - okx) - s.sx * c_z, cy = (p2[s.ky] - oky) - s.sy * c_z;
  float u = cx * by - cy * bx;
  float v = ax * cy - ay * cx;
  float w = bx * ay - by * ax;
  if ((u == 0.0f) | (v == 0.0f) | (w == 0.0f)) [[unlikely]] {
    // The float result is ambiguous exactly on an edge: decide it in double, where the products
    // of two floats are exact.
    u = float(double(cx) * double(by) - double(cy) * double(bx));
    v = float(double(ax) * double(cy) - double(ay) * double(cx));
    w = float(double(bx) * double(ay) - double(by) * double(ax));
  }
  // Bitwise | and & rather than || and &&: each sign is as unpredictable as the ray, and a chain
  // of short-circuit branches mispredicted often enough to cost 12 % of AO-ray throughput.
  if (((u < 0.0f) | (v < 0.0f) | (w < 0.0f)) & ((u > 0.0f) | (v > 0.0f) | (w > 0.0f))) return false;
  const float det = u + v + w;
  if (det == 0.0f) return false;  // degenerate, or seen exactly edge-on
  const float az = s.sz * a_z, bz = s.sz * b_z, cz = s.sz * c_z;
  const float rcp = 1.0f / det;
  const float t = (u * az + v * bz + w * cz) * rcp;
  if (!((t >= tnear) & (t <= tfar) & (t < kInfinity))) return false;  // also rejects NaN and overflow
  out = {t, v * rcp, w * rcp};
  return true;
}

// Closest-hit ordering shared by every accelerator: nearer t wins, equal t goes to the lower
// scene triangle index, so the answer never depends on traversal order.
inline bool closer(float t, uint32_t tri, const Hit& best) { return t < best.t || (t == best.t && tri < best.tri); }

// Ends a closest-hit query: names the hit triangle by geomID/primID; false if nothing was hit.
inline bool finish_hit(const Scene& scene, Hit& hit) {
  if (!hit.valid()) return false;
  hit.geomID = scene.tri_geom[hit.tri];
  hit.primID = scene.tri_prim[hit.tri];
  return true;
}

// Closest hit among tris[begin, end) whose scene indices are ids[...]: updates `hit` (t, u, v,
// tri) where a triangle is closer. The leaf loop of every scalar accelerator.
inline void intersect_range(const RayShear& shear, const Triangle* tris, const uint32_t* ids, uint32_t begin,
                            uint32_t end, float tnear, Hit& hit) {
  for (uint32_t i = begin; i < end; ++i) {
    TriangleHit th;
    if (intersect_triangle(shear, tris[i], tnear, hit.t, th) && closer(th.t, ids[i], hit)) {
      hit.t = th.t;
      hit.u = th.u;
      hit.v = th.v;
      hit.tri = ids[i];
    }
  }
}

}  // namespace tracer
