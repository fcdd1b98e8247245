// The 8-wide BVH's per-ray building blocks, compiled once per SIMD target: the slab test of all
// eight children at once, the watertight triangle test over a pack of eight triangles, the
// choice of the next child, and any-hit below a node. Shared by the single-ray kernels
// (wide_bvh_traverse.cpp), the AO bundles (wide_bvh_bundles.cpp) and SIMD brute force
// (simd_brute_force.cpp). Include it after foreach_target.h; the guard toggles per target as
// Highway's -inl.h convention requires.
#if defined(TRACER_ACCEL_WIDE_BVH_KERNELS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef TRACER_ACCEL_WIDE_BVH_KERNELS_INL_H_
#undef TRACER_ACCEL_WIDE_BVH_KERNELS_INL_H_
#else
#define TRACER_ACCEL_WIDE_BVH_KERNELS_INL_H_
#endif

#include <hwy/highway.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "accel/triangle_test.hpp"
#include "accel/wide_bvh.hpp"

HWY_BEFORE_NAMESPACE();
namespace tracer {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Per-ray constants of the slab test: the same arithmetic as the scalar RayBoxTest, so a child
// is kept exactly when the binary tree would keep it (NaN from 0*inf never culls).
struct WideRay {
  WideRay() = default;
  float ox, oy, oz, ix, iy, iz, fx, fy, fz;  // origin, reciprocal direction, and the latter times kFarGuard
  bool nx, ny, nz;
  explicit WideRay(const Ray& r) : ox(r.org.x), oy(r.org.y), oz(r.org.z) {
    ix = 1.0f / r.dir.x;
    iy = 1.0f / r.dir.y;
    iz = 1.0f / r.dir.z;
    fx = ix * RayBoxTest::kFarGuard;
    fy = iy * RayBoxTest::kFarGuard;
    fz = iz * RayBoxTest::kFarGuard;
    nx = std::signbit(ix);
    ny = std::signbit(iy);
    nz = std::signbit(iz);
  }
};

// max(a, b) and min(a, b) that keep b when a is NaN: x86's maxps/minps return their second
// operand whenever either is NaN, which is exactly the slab test's rule (NaN never culls), in
// one instruction instead of a compare and a blend. Other targets spell the rule out.
template <class V>
HWY_INLINE V MaxOrSecond(V a, V b) {
#if HWY_ARCH_X86 && HWY_TARGET != HWY_EMU128 && HWY_TARGET != HWY_SCALAR
  return hn::Max(a, b);
#else
  return hn::IfThenElse(a > b, a, b);
#endif
}
template <class V>
HWY_INLINE V MinOrSecond(V a, V b) {
#if HWY_ARCH_X86 && HWY_TARGET != HWY_EMU128 && HWY_TARGET != HWY_SCALAR
  return hn::Min(a, b);
#else
  return hn::IfThenElse(a < b, a, b);
#endif
}

// Tests all children of `n`; writes their entry distances to t_out and returns one bit per child hit.
HWY_INLINE uint32_t TestChildren(const WideNode& n, const WideRay& r, float tnear, float tfar,
                                 float* HWY_RESTRICT t_out) {
  const hn::CappedTag<float, kWideWidth> d;
  const size_t lanes = hn::Lanes(d);
  const float* near_x = r.nx ? n.hi_x : n.lo_x;
  const float* far_x = r.nx ? n.lo_x : n.hi_x;
  const float* near_y = r.ny ? n.hi_y : n.lo_y;
  const float* far_y = r.ny ? n.lo_y : n.hi_y;
  const float* near_z = r.nz ? n.hi_z : n.lo_z;
  const float* far_z = r.nz ? n.lo_z : n.hi_z;
  const auto ox = hn::Set(d, r.ox), oy = hn::Set(d, r.oy), oz = hn::Set(d, r.oz);
  const auto ix = hn::Set(d, r.ix), iy = hn::Set(d, r.iy), iz = hn::Set(d, r.iz);
  const auto fx = hn::Set(d, r.fx), fy = hn::Set(d, r.fy), fz = hn::Set(d, r.fz);
  const auto vnear = hn::Set(d, tnear), vfar = hn::Set(d, tfar * RayBoxTest::kTieGuard);
  uint32_t bits = 0;
  for (size_t i = 0; i < size_t(kWideWidth); i += lanes) {
    auto t0 = vnear, t1 = vfar;
    const auto a = hn::Mul(hn::Sub(hn::Load(d, near_x + i), ox), ix);
    const auto b = hn::Mul(hn::Sub(hn::Load(d, near_y + i), oy), iy);
    const auto c = hn::Mul(hn::Sub(hn::Load(d, near_z + i), oz), iz);
    t0 = MaxOrSecond(a, t0);  // NaN leaves t0 alone: no cull
    t0 = MaxOrSecond(b, t0);
    t0 = MaxOrSecond(c, t0);
    const auto e = hn::Mul(hn::Sub(hn::Load(d, far_x + i), ox), fx);
    const auto f = hn::Mul(hn::Sub(hn::Load(d, far_y + i), oy), fy);
    const auto g = hn::Mul(hn::Sub(hn::Load(d, far_z + i), oz), fz);
    t1 = MinOrSecond(e, t1);
    t1 = MinOrSecond(f, t1);
    t1 = MinOrSecond(g, t1);
    hn::Store(t0, d, t_out + i);
    uint8_t mask_bits[8] = {0};
    hn::StoreMaskBits(d, t0 <= t1, mask_bits);
    bits |= uint32_t(mask_bits[0]) << i;
  }
  return bits;
}

// One ray against the triangles of `pack`, lane-parallel: the watertight test of
// triangle_test.hpp with the same operations in the same order, so each lane's t, u, v equal
// the scalar test's bit for bit. Lanes whose edge function is exactly zero are redone by the
// scalar test (which decides them in double), as are none in the common case.
// Returns the mask of lanes hit within [tnear, tfar]; their t, u, v go to the arrays.
HWY_INLINE uint32_t IntersectPack(const TrianglePack& p, const RayShear& s, const Triangle* tris, float tnear,
                                  float tfar, float* HWY_RESTRICT t_out, float* HWY_RESTRICT u_out,
                                  float* HWY_RESTRICT v_out) {
  const hn::CappedTag<float, kWideWidth> d;
  const size_t lanes = hn::Lanes(d);
  const float org[3] = {s.org.x, s.org.y, s.org.z};
  const auto okx = hn::Set(d, org[s.kx]), oky = hn::Set(d, org[s.ky]), okz = hn::Set(d, org[s.kz]);
  const auto sx = hn::Set(d, s.sx), sy = hn::Set(d, s.sy), sz = hn::Set(d, s.sz);
  const auto zero = hn::Zero(d), one = hn::Set(d, 1.0f), inf = hn::Set(d, kInfinity);
  const auto vnear = hn::Set(d, tnear), vfar = hn::Set(d, tfar);
  uint32_t bits = 0;
  for (size_t i = 0; i < size_t(kWideWidth); i += lanes) {
    const auto ax_ = hn::Sub(hn::Load(d, p.v[0][s.kx] + i), okx), ay_ = hn::Sub(hn::Load(d, p.v[0][s.ky] + i), oky),
               az_ = hn::Sub(hn::Load(d, p.v[0][s.kz] + i), okz);
    const auto bx_ = hn::Sub(hn::Load(d, p.v[1][s.kx] + i), okx), by_ = hn::Sub(hn::Load(d, p.v[1][s.ky] + i), oky),
               bz_ = hn::Sub(hn::Load(d, p.v[1][s.kz] + i), okz);
    const auto cx_ = hn::Sub(hn::Load(d, p.v[2][s.kx] + i), okx), cy_ = hn::Sub(hn::Load(d, p.v[2][s.ky] + i), oky),
               cz_ = hn::Sub(hn::Load(d, p.v[2][s.kz] + i), okz);
    const auto ax = hn::Sub(ax_, hn::Mul(sx, az_)), ay = hn::Sub(ay_, hn::Mul(sy, az_));
    const auto bx = hn::Sub(bx_, hn::Mul(sx, bz_)), by = hn::Sub(by_, hn::Mul(sy, bz_));
    const auto cx = hn::Sub(cx_, hn::Mul(sx, cz_)), cy = hn::Sub(cy_, hn::Mul(sy, cz_));
    const auto u = hn::Sub(hn::Mul(cx, by), hn::Mul(cy, bx));
    const auto v = hn::Sub(hn::Mul(ax, cy), hn::Mul(ay, cx));
    const auto w = hn::Sub(hn::Mul(bx, ay), hn::Mul(by, ax));
    const auto neg = hn::Or(hn::Or(u < zero, v < zero), w < zero);
    const auto pos = hn::Or(hn::Or(u > zero, v > zero), w > zero);
    const auto on_edge = hn::Or(hn::Or(u == zero, v == zero), w == zero);
    // Most packs a ray reaches it misses entirely: then skip the division and the stores.
    if (hn::AllTrue(d, hn::AndNot(on_edge, hn::And(neg, pos)))) continue;
    const auto det = hn::Add(hn::Add(u, v), w);
    const auto rcp = hn::Div(one, det);
    const auto t = hn::Mul(
        hn::Add(hn::Add(hn::Mul(u, hn::Mul(sz, az_)), hn::Mul(v, hn::Mul(sz, bz_))), hn::Mul(w, hn::Mul(sz, cz_))),
        rcp);
    auto hit = hn::AndNot(hn::And(neg, pos), det != zero);
    hit = hn::And(hit, hn::And(hn::And(t >= vnear, t <= vfar), t < inf));
    hn::Store(t, d, t_out + i);
    hn::Store(hn::Mul(v, rcp), d, u_out + i);
    hn::Store(hn::Mul(w, rcp), d, v_out + i);
    uint8_t hit_bits[8] = {0}, edge_bits[8] = {0};
    hn::StoreMaskBits(d, hit, hit_bits);
    hn::StoreMaskBits(d, on_edge, edge_bits);
    uint32_t h = hit_bits[0], edge = edge_bits[0];
    while (edge) {  // exactly on an edge in float: let the scalar test decide in double
      const int k = __builtin_ctz(edge);
      edge &= edge - 1;
      const uint32_t id = p.id[i + size_t(k)];
      TriangleHit th;
      h &= ~(1u << k);
      if (id != kInvalidIndex && intersect_triangle(s, tris[id], tnear, tfar, th)) {
        h |= 1u << k;
        t_out[i + size_t(k)] = th.t;
        u_out[i + size_t(k)] = th.u;
        v_out[i + size_t(k)] = th.v;
      }
    }
    bits |= h << i;
  }
  return bits;
}

// Updates `hit` with the closest lane of `pack` (ties to the lower scene index, as everywhere).
// The nearest of several hit lanes is found by a SIMD minimum over the lanes, not a loop; only
// lanes tied exactly at that minimum (rare) are compared one by one for the lower index.
HWY_INLINE void ClosestInPack(const TrianglePack& p, const RayShear& shear, const Triangle* tris, float tnear,
                              Hit& hit) {
  HWY_ALIGN float tt[kWideWidth], uu[kWideWidth], vv[kWideWidth];
  const uint32_t bits = IntersectPack(p, shear, tris, tnear, hit.t, tt, uu, vv);
  if (bits == 0) return;
  uint32_t nearest = bits;
  if (bits & (bits - 1)) {
    const hn::CappedTag<float, kWideWidth> d;
    const size_t lanes = hn::Lanes(d);
    const auto inf = hn::Set(d, kInfinity);
    const auto lane_mask = [&](size_t i) {
      const uint8_t b[8] = {uint8_t(bits >> i), 0, 0, 0, 0, 0, 0, 0};
      return hn::LoadMaskBits(d, b);
    };
    auto tmin = inf;
    for (size_t i = 0; i < size_t(kWideWidth); i += lanes)
      tmin = hn::Min(tmin, hn::IfThenElse(lane_mask(i), hn::Load(d, tt + i), inf));
    tmin = hn::MinOfLanes(d, tmin);
    nearest = 0;
    for (size_t i = 0; i < size_t(kWideWidth); i += lanes) {
      uint8_t eq[8] = {0};
      hn::StoreMaskBits(d, hn::And(lane_mask(i), hn::Eq(hn::Load(d, tt + i), tmin)), eq);
      nearest |= uint32_t(eq[0]) << i;
    }
  }
  for (; nearest; nearest &= nearest - 1) {  // one lane, unless several tie exactly
    const int k = __builtin_ctz(nearest);
    const uint32_t id = p.id[k];
    if (closer(tt[k], id, hit)) {
      hit.t = tt[k];
      hit.u = uu[k];
      hit.v = vv[k];
      hit.tri = id;
    }
  }
}

struct StackEntry {
  uint32_t child, count;  // count > 0: a leaf pack
  float t;                // entry distance, for culling once a closer hit is known
};

// Chooses the next child to visit among the hit children `bits` of `n` and pushes the others,
// farthest first. One or two hits (by far the common cases) take no sort; more are sorted by an
// insertion sort of at most eight entries. Returns false when no child was hit.
HWY_INLINE bool Descend(const WideNode& n, uint32_t bits, const float* t, StackEntry* stack, int& sp,
                        StackEntry& next) {
  if (bits == 0) return false;
  const int i = __builtin_ctz(bits);
  bits &= bits - 1;
  if (bits == 0) {
    next = {n.child[i], n.count[i], t[i]};
    return true;
  }
  const int j = __builtin_ctz(bits);
  bits &= bits - 1;
  if (bits == 0) {
    const bool i_first = t[i] <= t[j];
    const int near = i_first ? i : j, far = i_first ? j : i;
    stack[sp++] = {n.child[far], n.count[far], t[far]};
    next = {n.child[near], n.count[near], t[near]};
    return true;
  }
  // Sorted in place on top of the stack (a local array copied over afterwards compiled to a
  // rep movs, 3 % of a path render's time in Sponza).
  StackEntry* hits = stack + sp;
  int k = 0;
  bits |= (1u << i) | (1u << j);
  while (bits) {
    const int c = __builtin_ctz(bits);
    bits &= bits - 1;
    const StackEntry e{n.child[c], n.count[c], t[c]};
    int m = k++;
    while (m > 0 && hits[m - 1].t < e.t) {  // descending: farthest first
      hits[m] = hits[m - 1];
      --m;
    }
    hits[m] = e;
  }
  next = hits[k - 1];
  sp += k - 1;
  return true;
}

// Any hit for one ray below `start` (a node, or a leaf pack when start.count > 0).
HWY_INLINE bool OccludedBelow(const WideBvh& bvh, const WideRay& wr, const RayShear& shear, float tnear, float tfar,
                              StackEntry start) {
  const WideNode* nodes = bvh.nodes().data();
  const Triangle* tris = bvh.scene().triangles.data();
  const TrianglePack* packs = bvh.packs().data();
  StackEntry stack[kWideWidth * (Bvh::kMaxDepth + 2)];
  int sp = 0;
  HWY_ALIGN float t[kWideWidth];
  HWY_ALIGN float tt[kWideWidth], uu[kWideWidth], vv[kWideWidth];
  StackEntry cur = start;
  for (;;) {
    if (cur.count == 0) {
      // Any hit ends the query, so the children need no order: push them as found.
      const WideNode& n = nodes[cur.child];
      uint32_t bits = TestChildren(n, wr, tnear, tfar, t);
      if (bits) {
        int c = __builtin_ctz(bits);
        for (bits &= bits - 1; bits; bits &= bits - 1) {
          const int o = __builtin_ctz(bits);
          stack[sp++] = {n.child[o], n.count[o], 0.0f};
        }
        cur = {n.child[c], n.count[c], 0.0f};
        continue;
      }
    } else if (IntersectPack(packs[cur.child], shear, tris, tnear, tfar, tt, uu, vv)) {
      return true;
    }
    if (sp == 0) return false;
    cur = stack[--sp];
  }
}

// Any hit for one ray, from the root.
HWY_INLINE bool OccludedFromRoot(const WideBvh& bvh, const Ray& ray) {
  if (bvh.nodes().empty()) return false;
  return OccludedBelow(bvh, WideRay(ray), RayShear(ray), ray.tnear, ray.tfar, StackEntry{0, 0, ray.tnear});
}

}  // namespace HWY_NAMESPACE
}  // namespace tracer
HWY_AFTER_NAMESPACE();

#endif  // TRACER_ACCEL_WIDE_BVH_KERNELS_INL_H_
