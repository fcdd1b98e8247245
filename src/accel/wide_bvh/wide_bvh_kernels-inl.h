// The 8-wide BVH's per-ray building blocks, compiled once per SIMD target: lane_kernels' slab
// test over all eight children at once and its watertight test over a pack of eight triangles,
// the choice of the next child, and any-hit below a node. Shared by the single-ray kernels
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
#include <cstddef>
#include <limits>

#include "accel/kernels/simd_lanes-inl.h"
#include "accel/kernels/triangle_test.hpp"
#include "accel/wide_bvh/wide_bvh.hpp"

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
    fx = ix * SlabGuards::kFarGuard;
    fy = iy * SlabGuards::kFarGuard;
    fz = iz * SlabGuards::kFarGuard;
    nx = std::signbit(ix);
    ny = std::signbit(iy);
    nz = std::signbit(iz);
  }
};

using WideTag = hn::CappedTag<float, kWideWidth>;
using WideV = hn::Vec<WideTag>;

// A WideRay as the node test uses it: splatted to vectors once per query (the compiler does not
// hoist the splats out of the traversal loop by itself), and the planes each slab is entered and
// left by as offsets into a WideNode, so no step branches on the direction's signs.
struct NodeRay {
  WideV ox, oy, oz, ix, iy, iz, fx, fy, fz;
  uint32_t near[3], far[3];  // in floats from the node's start
  HWY_INLINE explicit NodeRay(const WideRay& r) {
    const WideTag d;
    ox = hn::Set(d, r.ox), oy = hn::Set(d, r.oy), oz = hn::Set(d, r.oz);
    ix = hn::Set(d, r.ix), iy = hn::Set(d, r.iy), iz = hn::Set(d, r.iz);
    fx = hn::Set(d, r.fx), fy = hn::Set(d, r.fy), fz = hn::Set(d, r.fz);
    constexpr uint32_t lo = 0, hi = 3 * kWideWidth, axis = kWideWidth;  // lo_x, hi_x, and the next axis
    const bool neg[3] = {r.nx, r.ny, r.nz};
    for (uint32_t a = 0; a < 3; ++a) {
      near[a] = (neg[a] ? hi : lo) + a * axis;
      far[a] = (neg[a] ? lo : hi) + a * axis;
    }
  }
};
static_assert(offsetof(WideNode, hi_x) == 3 * kWideWidth * sizeof(float) &&
              offsetof(WideNode, lo_y) == kWideWidth * sizeof(float));

// Tests all children of `n` (lane_kernels-inl.h's slab test, one lane per child); writes their
// entry distances to t_out and returns one bit per child hit.
HWY_INLINE uint32_t TestChildren(const WideNode& n, const NodeRay& r, float tnear, float tfar,
                                 float* HWY_RESTRICT t_out) {
  const WideTag d;
  using L = SimdLanes<WideTag>;
  const size_t lanes = hn::Lanes(d);
  const float* base = n.lo_x;
  const auto vnear = hn::Set(d, tnear), vfar = hn::Set(d, tfar);
  uint32_t bits = 0;
  for (size_t i = 0; i < size_t(kWideWidth); i += lanes) {
    const Lanes3<L::V> near{hn::Load(d, base + r.near[0] + i) - r.ox, hn::Load(d, base + r.near[1] + i) - r.oy,
                            hn::Load(d, base + r.near[2] + i) - r.oz};
    const Lanes3<L::V> far{hn::Load(d, base + r.far[0] + i) - r.ox, hn::Load(d, base + r.far[1] + i) - r.oy,
                           hn::Load(d, base + r.far[2] + i) - r.oz};
    L::V t0;
    const auto hit = slab_test<L>(near, far, {r.ix, r.iy, r.iz}, {r.fx, r.fy, r.fz}, vnear, vfar, t0);
    hn::Store(t0, d, t_out + i);
    bits |= Bits(d, hit) << i;
  }
  return bits;
}

// A RayShear as the pack test uses it: splatted once per query, the shear's axes as offsets into
// a pack's vertex rows.
struct PackRay {
  const RayShear* shear;  // for the lanes the scalar test decides
  WideV okx, oky, okz, sx, sy, sz;
  uint32_t axis[3];  // in floats from a vertex's first row: axes kx, ky, kz
  HWY_INLINE explicit PackRay(const RayShear& s) : shear(&s) {
    const WideTag d;
    const float org[3] = {s.org.x, s.org.y, s.org.z};
    okx = hn::Set(d, org[s.kx]), oky = hn::Set(d, org[s.ky]), okz = hn::Set(d, org[s.kz]);
    sx = hn::Set(d, s.sx), sy = hn::Set(d, s.sy), sz = hn::Set(d, s.sz);
    axis[0] = uint32_t(s.kx) * kWideWidth;
    axis[1] = uint32_t(s.ky) * kWideWidth;
    axis[2] = uint32_t(s.kz) * kWideWidth;
  }
};

// One ray against the triangles of `pack`, one lane per triangle: lane_kernels-inl.h's
// watertight test, so each lane's t, u, v equal the scalar test's bit for bit. Lanes whose edge
// function is exactly zero are redone by the scalar test (which decides them in double), as are
// none in the common case. Returns the mask of lanes hit within [tnear, tfar]; their t, u, v go
// to the arrays.
HWY_INLINE uint32_t IntersectPack(const TrianglePack& p, const PackRay& r, const Triangle* tris, float tnear,
                                  float tfar, float* HWY_RESTRICT t_out, float* HWY_RESTRICT u_out,
                                  float* HWY_RESTRICT v_out) {
  const WideTag d;
  using L = SimdLanes<WideTag>;
  const size_t lanes = hn::Lanes(d);
  const auto vnear = hn::Set(d, tnear), vfar = hn::Set(d, tfar);
  const auto vertex = [&](int k, size_t i) {
    const float* row = p.v[k][0] + i;
    return Lanes3<L::V>{hn::Load(d, row + r.axis[0]) - r.okx, hn::Load(d, row + r.axis[1]) - r.oky,
                        hn::Load(d, row + r.axis[2]) - r.okz};
  };
  uint32_t bits = 0;
  for (size_t i = 0; i < size_t(kWideWidth); i += lanes) {
    const ShearedTriangle<L::V> st = shear_triangle<L>(vertex(0, i), vertex(1, i), vertex(2, i), r.sx, r.sy);
    const auto on_edge = on_an_edge<L>(st);
    const auto outside = passes_outside<L>(st);
    // Most packs a ray reaches it misses entirely: then skip the division and the stores.
    if (hn::AllTrue(d, hn::AndNot(on_edge, outside))) continue;
    const TriangleLanes<L> h = triangle_hit<L>(st, outside, r.sz, vnear, vfar);
    hn::Store(h.t, d, t_out + i);
    hn::Store(h.u, d, u_out + i);
    hn::Store(h.v, d, v_out + i);
    uint32_t hit = Bits(d, h.hit), edge = Bits(d, on_edge);
    while (edge) {  // exactly on an edge in float: let the scalar test decide in double
      const int k = __builtin_ctz(edge);
      edge &= edge - 1;
      const uint32_t id = p.id[i + size_t(k)];
      TriangleHit th;
      hit &= ~(1u << k);
      if (id != kInvalidIndex && intersect_triangle(*r.shear, tris[id], tnear, tfar, th)) {
        hit |= 1u << k;
        t_out[i + size_t(k)] = th.t;
        u_out[i + size_t(k)] = th.u;
        v_out[i + size_t(k)] = th.v;
      }
    }
    bits |= hit << i;
  }
  return bits;
}

// Updates `hit` with the closest lane of `pack` (ties to the lower scene index, as everywhere).
// The nearest of several hit lanes is found by a SIMD minimum over the lanes, not a loop; only
// lanes tied exactly at that minimum (rare) are compared one by one for the lower index.
HWY_INLINE void ClosestInPack(const TrianglePack& p, const PackRay& shear, const Triangle* tris, float tnear,
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
  // Sorted in place on top of the stack: a local array copied over afterwards compiled to a
  // rep movs that showed in a path render's profile (docs/bench/LOG.md).
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

// The closest-hit walk of one ray down an 8-wide tree of `nodes` from the root, nearest child
// first, dropping entries beyond hit.t (<=: ties still count). `leaf(e)` answers a leaf entry
// (e.child, e.count), updating hit: a pack of triangles in the flat tree, an instance in the
// two-level tree's top level.
template <class Count, class Leaf>
HWY_INLINE void ClosestWalk(const WideNode* nodes, const Ray& ray, Hit& hit, Count count, const Leaf& leaf) {
  const NodeRay wr{WideRay(ray)};
  StackEntry stack[kWideWidth * (Bvh::kMaxDepth + 2)];
  int sp = 0;
  HWY_ALIGN float t[kWideWidth];
  StackEntry cur{0, 0, ray.tnear};
  for (;;) {
    if (cur.count == 0) {
      count.node(1);
      const WideNode& n = nodes[cur.child];
      if (Descend(n, TestChildren(n, wr, ray.tnear, hit.t, t), t, stack, sp, cur)) continue;
    } else {
      leaf(cur);
    }
    do {
      if (sp == 0) return;
      cur = stack[--sp];
    } while (!(cur.t <= hit.t * SlabGuards::kTieGuard));
  }
}

// Closest hit for one ray in the whole tree, nearer than hit.t (updated: t, u, v, tri; hits at
// hit.t tie to the lower triangle index).
template <class Count>
HWY_INLINE void ClosestInTree(const WideBvh& bvh, const Ray& ray, Hit& hit, Count count) {
  if (bvh.nodes().empty()) return;
  const RayShear ray_shear(ray);
  const PackRay shear(ray_shear);
  const Triangle* tris = bvh.scene().triangles.data();
  const TrianglePack* packs = bvh.packs().data();
  ClosestWalk(bvh.nodes().data(), ray, hit, count, [&](const StackEntry& e) TRACER_INLINE_LAMBDA {
    count.pack(1, e.count);
    ClosestInPack(packs[e.child], shear, tris, ray.tnear, hit);
  });
}

// The any-hit walk of one ray below `start` (a node, or a leaf when start.count > 0): children
// in no order of distance (any hit ends it), the last slot (the smallest subtree, see
// wide_bvh_build.cpp) entered first and the others popped from the last down. `leaf(e)` returns
// whether leaf entry e holds a hit.
template <class Count, class Leaf>
HWY_INLINE bool AnyHitWalk(const WideNode* nodes, const NodeRay& node_ray, float tnear, float tfar, StackEntry start,
                           Count count, const Leaf& leaf) {
  StackEntry stack[kWideWidth * (Bvh::kMaxDepth + 2)];
  int sp = 0;
  HWY_ALIGN float t[kWideWidth];
  StackEntry cur = start;
  for (;;) {
    if (cur.count == 0) {
      count.node(1);
      const WideNode& n = nodes[cur.child];
      uint32_t bits = TestChildren(n, node_ray, tnear, tfar, t);
      if (bits) {
        const int c = 31 - __builtin_clz(bits);
        for (bits &= ~(1u << c); bits; bits &= bits - 1) {
          const int o = __builtin_ctz(bits);
          stack[sp++] = {n.child[o], n.count[o], 0.0f};
        }
        cur = {n.child[c], n.count[c], 0.0f};
        continue;
      }
    } else if (leaf(cur)) {
      return true;
    }
    if (sp == 0) return false;
    cur = stack[--sp];
  }
}

// Any hit for one ray below `start` (a node, or a leaf pack when start.count > 0).
template <class Count>
HWY_INLINE bool OccludedBelow(const WideBvh& bvh, const WideRay& wr, const RayShear& shear, float tnear, float tfar,
                              StackEntry start, Count count) {
  const Triangle* tris = bvh.scene().triangles.data();
  const TrianglePack* packs = bvh.packs().data();
  HWY_ALIGN float tt[kWideWidth], uu[kWideWidth], vv[kWideWidth];
  const PackRay pack_ray(shear);
  return AnyHitWalk(bvh.nodes().data(), NodeRay(wr), tnear, tfar, start, count,
                    [&](const StackEntry& e) TRACER_INLINE_LAMBDA {
                      count.pack(1, e.count);
                      return IntersectPack(packs[e.child], pack_ray, tris, tnear, tfar, tt, uu, vv) != 0;
                    });
}

// Any hit for one ray, from the root.
template <class Count>
HWY_INLINE bool OccludedFromRoot(const WideBvh& bvh, const Ray& ray, Count count) {
  count.rays(1);
  if (bvh.nodes().empty()) return false;
  return OccludedBelow(bvh, WideRay(ray), RayShear(ray), ray.tnear, ray.tfar, StackEntry{0, 0, ray.tnear}, count);
}

}  // namespace HWY_NAMESPACE
}  // namespace tracer
HWY_AFTER_NAMESPACE();

#endif  // TRACER_ACCEL_WIDE_BVH_KERNELS_INL_H_
