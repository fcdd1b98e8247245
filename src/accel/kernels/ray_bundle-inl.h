// The per-lane constants of a RayBundle and its box test, one SIMD lane per ray: shared by the
// binary BVH's bundles (bvh_bundles.cpp) and the 8-wide BVH's (wide_bvh_bundles.cpp). Per-target code:
// include it after foreach_target.h; the guard toggles per target as Highway's -inl.h
// convention requires.
#if defined(TRACER_ACCEL_RAY_BUNDLE_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef TRACER_ACCEL_RAY_BUNDLE_INL_H_
#undef TRACER_ACCEL_RAY_BUNDLE_INL_H_
#else
#define TRACER_ACCEL_RAY_BUNDLE_INL_H_
#endif

#include <hwy/highway.h>

#include <cmath>
#include <cstdint>

#include "accel/kernels/simd_lanes-inl.h"
#include "accel/kernels/triangle_test.hpp"
#include "math/ray_packet.hpp"
#include "scene/scene.hpp"

HWY_BEFORE_NAMESPACE();
namespace tracer {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Per-lane constants of a bundle as SoA arrays: RayBoxTest's and RayShear's, lane by lane,
// computed for all lanes at once with the scalar constructors' operations (so the same floats).
struct BundleState {
  HWY_ALIGN float ix[kPacketSize], iy[kPacketSize], iz[kPacketSize];    // reciprocal direction
  HWY_ALIGN float fx[kPacketSize], fy[kPacketSize], fz[kPacketSize];    // ... times SlabGuards::kFarGuard
  HWY_ALIGN int32_t nx[kPacketSize], ny[kPacketSize], nz[kPacketSize];  // -1 where that reciprocal is negative
  HWY_ALIGN int32_t kx[kPacketSize], ky[kPacketSize], kz[kPacketSize];  // RayShear's axes ...
  HWY_ALIGN float sx[kPacketSize], sy[kPacketSize], sz[kPacketSize];    // ... and factors
  float org[3];
  float tnear, tfar;

  HWY_INLINE explicit BundleState(const RayBundle& rays)
      : org{rays.org.x, rays.org.y, rays.org.z}, tnear(rays.tnear), tfar(rays.tfar) {
    const hn::ScalableTag<float> d;
    const hn::RebindToSigned<decltype(d)> di;
    const size_t N = hn::Lanes(d);
    const auto one = hn::Set(d, 1.0f), guard = hn::Set(d, SlabGuards::kFarGuard), zero = hn::Zero(d);
    const auto i0 = hn::Zero(di), i1 = hn::Set(di, 1), i2 = hn::Set(di, 2);
    for (size_t i = 0; i < size_t(kPacketSize); i += N) {
      const auto dx = hn::Load(d, rays.dx + i), dy = hn::Load(d, rays.dy + i), dz = hn::Load(d, rays.dz + i);
      const auto rx = hn::Div(one, dx), ry = hn::Div(one, dy), rz = hn::Div(one, dz);
      hn::Store(rx, d, ix + i);
      hn::Store(ry, d, iy + i);
      hn::Store(rz, d, iz + i);
      hn::Store(hn::Mul(rx, guard), d, fx + i);
      hn::Store(hn::Mul(ry, guard), d, fy + i);
      hn::Store(hn::Mul(rz, guard), d, fz + i);
      // std::signbit as -1 / 0: the sign bit shifted across the lane.
      hn::Store(hn::ShiftRight<31>(hn::BitCast(di, rx)), di, nx + i);
      hn::Store(hn::ShiftRight<31>(hn::BitCast(di, ry)), di, ny + i);
      hn::Store(hn::ShiftRight<31>(hn::BitCast(di, rz)), di, nz + i);
      // RayShear: kz = max_dimension(abs(dir)), kx and ky the next axes, swapped when dir[kz] < 0.
      const auto axd = hn::Abs(dx), ayd = hn::Abs(dy), azd = hn::Abs(dz);
      const auto k_z = hn::IfThenElse(hn::RebindMask(di, hn::Gt(axd, ayd)),
                                      hn::IfThenElse(hn::RebindMask(di, hn::Gt(axd, azd)), i0, i2),
                                      hn::IfThenElse(hn::RebindMask(di, hn::Gt(ayd, azd)), i1, i2));
      auto k_x = hn::IfThenElse(hn::Eq(k_z, i2), i0, hn::Add(k_z, i1));
      auto k_y = hn::IfThenElse(hn::Eq(k_x, i2), i0, hn::Add(k_x, i1));
      const auto pick = [&](hn::Vec<decltype(di)> k) {
        return hn::IfThenElse(hn::RebindMask(d, hn::Eq(k, i0)), dx,
                              hn::IfThenElse(hn::RebindMask(d, hn::Eq(k, i1)), dy, dz));
      };
      const auto dkz = pick(k_z);
      const auto flip = hn::RebindMask(di, hn::Lt(dkz, zero));
      const auto swapped_x = hn::IfThenElse(flip, k_y, k_x);
      k_y = hn::IfThenElse(flip, k_x, k_y);
      k_x = swapped_x;
      const auto s_z = hn::Div(one, dkz);
      hn::Store(k_x, di, kx + i);
      hn::Store(k_y, di, ky + i);
      hn::Store(k_z, di, kz + i);
      hn::Store(hn::Mul(pick(k_x), s_z), d, sx + i);
      hn::Store(hn::Mul(pick(k_y), s_z), d, sy + i);
      hn::Store(s_z, d, sz + i);
    }
  }

  // Lane k's RayShear, for the scalar triangle test.
  RayShear shear(int k) const {
    RayShear s;
    s.org = {org[0], org[1], org[2]};
    s.kx = kx[k];
    s.ky = ky[k];
    s.kz = kz[k];
    s.sx = sx[k];
    s.sy = sy[k];
    s.sz = sz[k];
    return s;
  }
};

// The lanes of `mask` whose rays enter the box [lo, hi] within [tnear, tfar]: lane_kernels-inl.h's
// slab test, one lane per ray, with plane - origin (the origin is shared) computed once per plane.
HWY_INLINE uint32_t TestBundleBox(const float lo[3], const float hi[3], const BundleState& st, uint32_t mask) {
  const hn::ScalableTag<float> d;
  using L = SimdLanes<decltype(d)>;
  const size_t N = hn::Lanes(d);
  const auto lo_x = hn::Set(d, lo[0] - st.org[0]), lo_y = hn::Set(d, lo[1] - st.org[1]),
             lo_z = hn::Set(d, lo[2] - st.org[2]);
  const auto hi_x = hn::Set(d, hi[0] - st.org[0]), hi_y = hn::Set(d, hi[1] - st.org[1]),
             hi_z = hn::Set(d, hi[2] - st.org[2]);
  const auto tnear = hn::Set(d, st.tnear), tfar = hn::Set(d, st.tfar);
  uint32_t hits = 0;
  for (size_t i = 0; i < size_t(kPacketSize); i += N) {
    const uint32_t chunk = ChunkBits(mask, i, N);
    if (chunk == 0) continue;
    Lanes3<L::V> near, far;
    NearFarPlanes(d, st.nx, st.ny, st.nz, i, {lo_x, lo_y, lo_z}, {hi_x, hi_y, hi_z}, near, far);
    const Lanes3<L::V> inv{hn::Load(d, st.ix + i), hn::Load(d, st.iy + i), hn::Load(d, st.iz + i)};
    const Lanes3<L::V> inv_far{hn::Load(d, st.fx + i), hn::Load(d, st.fy + i), hn::Load(d, st.fz + i)};
    L::V t0;
    hits |= Bits(d, hn::And(slab_test<L>(near, far, inv, inv_far, tnear, tfar, t0), LaneMask(d, chunk))) << i;
  }
  return hits;
}

// The lanes of `mask` whose rays hit triangle `tri` (vertices v0, v1, v2; `tri` itself is only
// read for lanes the float test cannot decide): lane_kernels-inl.h's watertight test, one lane
// per ray. The origin is shared, so vertex - origin is one scalar per coordinate, and each lane
// picks its shear axes from those with selects. Lanes with an edge function exactly zero are
// redone by the scalar test, which decides them in double.
HWY_INLINE uint32_t OccludedByTriangle(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Triangle& tri,
                                       const BundleState& st, uint32_t mask) {
  const hn::ScalableTag<float> d;
  using L = SimdLanes<decltype(d)>;
  const hn::RebindToSigned<decltype(d)> di;
  const size_t N = hn::Lanes(d);
  const float a[3] = {v0.x - st.org[0], v0.y - st.org[1], v0.z - st.org[2]};
  const float b[3] = {v1.x - st.org[0], v1.y - st.org[1], v1.z - st.org[2]};
  const float c[3] = {v2.x - st.org[0], v2.y - st.org[1], v2.z - st.org[2]};
  const auto tnear = hn::Set(d, st.tnear), tfar = hn::Set(d, st.tfar);
  const auto zero_i = hn::Zero(di), one_i = hn::Set(di, 1);
  uint32_t hits = 0;
  for (size_t i = 0; i < size_t(kPacketSize); i += N) {
    const uint32_t chunk = ChunkBits(mask, i, N);
    if (chunk == 0) continue;
    // v[axis] per lane, for the lane's axis index k (0, 1 or 2).
    const auto pick = [&](const float* v, hn::Vec<decltype(di)> k) {
      return hn::IfThenElse(hn::RebindMask(d, hn::Eq(k, zero_i)), hn::Set(d, v[0]),
                            hn::IfThenElse(hn::RebindMask(d, hn::Eq(k, one_i)), hn::Set(d, v[1]), hn::Set(d, v[2])));
    };
    const auto kx = hn::Load(di, st.kx + i), ky = hn::Load(di, st.ky + i), kz = hn::Load(di, st.kz + i);
    const auto vertex = [&](const float* v) { return Lanes3<L::V>{pick(v, kx), pick(v, ky), pick(v, kz)}; };
    const ShearedTriangle<L::V> s =
        shear_triangle<L>(vertex(a), vertex(b), vertex(c), hn::Load(d, st.sx + i), hn::Load(d, st.sy + i));
    const auto lanes = LaneMask(d, chunk);
    const auto on_edge = hn::And(lanes, on_an_edge<L>(s));
    uint32_t edge = Bits(d, on_edge);
    const auto outside = passes_outside<L>(s);
    const auto inside = hn::AndNot(outside, hn::AndNot(on_edge, lanes));
    if (!hn::AllFalse(d, inside)) {
      const TriangleLanes<L> h = triangle_hit<L>(s, outside, hn::Load(d, st.sz + i), tnear, tfar);
      hits |= Bits(d, hn::And(h.hit, inside)) << i;
    }
    for (; edge; edge &= edge - 1) {  // exactly on an edge in float: the scalar test decides
      const int k = int(i) + __builtin_ctz(edge);
      TriangleHit th;
      if (intersect_triangle(st.shear(k), tri, st.tnear, st.tfar, th)) hits |= 1u << k;
    }
  }
  return hits;
}

}  // namespace HWY_NAMESPACE
}  // namespace tracer
HWY_AFTER_NAMESPACE();

#endif  // include guard toggle
