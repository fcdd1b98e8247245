// Watertight ray/triangle test (Woop, Benthin, Wald: "Watertight Ray/Triangle Intersection",
// JCGT 2013). The ray is sheared so it runs along +z from the origin; edge functions are then
// evaluated in 2D, and exactly-zero ones are redone in double, so a ray through a shared edge or
// vertex hits at least one of the triangles around it. Two-sided.
#pragma once

#include <type_traits>
#include <utility>

#include "accel/kernels/lane_kernels.hpp"
#include "math/ray.hpp"
#include "scene/scene.hpp"

namespace tracer {

// Per-ray constants of the shear, computed once per query.
struct RayShear {
  Vec3 org;
  int kx = 0, ky = 1, kz = 2;
  float sx = 0, sy = 0, sz = 1;

  RayShear() = default;
  [[gnu::always_inline]] explicit RayShear(const Ray& r) : org(r.org) {
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
// The arithmetic is lane_kernels.hpp's, one lane.
inline bool intersect_triangle(const RayShear& s, const Triangle& tri, float tnear, float tfar, TriangleHit& out) {
  // Each permuted coordinate is loaded straight from the triangle (no copy to index into).
  static_assert(sizeof(Vec3) == 3 * sizeof(float) && std::is_standard_layout_v<Vec3>);
  const float* o = &s.org.x;
  const auto relative = [&](const Vec3& p) {
    const float* q = &p.x;
    return Lanes3<float>{q[s.kx] - o[s.kx], q[s.ky] - o[s.ky], q[s.kz] - o[s.kz]};
  };
  using L = ScalarLanes;
  ShearedTriangle<float> st = shear_triangle<L>(relative(tri.v0), relative(tri.v1), relative(tri.v2), s.sx, s.sy);
  if (on_an_edge<L>(st)) [[unlikely]] {
    // The float result is ambiguous exactly on an edge: decide it in double, where the products
    // of two floats are exact.
    st.u = float(double(st.cx) * double(st.by) - double(st.cy) * double(st.bx));
    st.v = float(double(st.ax) * double(st.cy) - double(st.ay) * double(st.cx));
    st.w = float(double(st.bx) * double(st.ay) - double(st.by) * double(st.ax));
  }
  // Bitwise | and & inside passes_outside rather than || and &&: each sign is as unpredictable as
  // the ray, and a chain of short-circuit branches mispredicts (docs/bench/LOG.md measures the
  // AO-ray throughput it cost).
  if (passes_outside<L>(st)) return false;
  const TriangleLanes<L> h = triangle_hit<L>(st, false, s.sz, tnear, tfar);
  if (!h.hit) return false;
  out = {h.t, h.u, h.v};
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
