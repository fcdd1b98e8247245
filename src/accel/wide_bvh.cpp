// WideBvh: collapse from the binary tree (once), and the traversal kernels, compiled once per
// SIMD target by Highway's foreach_target (this file includes itself for each target).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "accel/wide_bvh.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "accel/ray_bundle-inl.h"
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
    t0 = hn::IfThenElse(a > t0, a, t0);  // NaN compares false: no cull
    t0 = hn::IfThenElse(b > t0, b, t0);
    t0 = hn::IfThenElse(c > t0, c, t0);
    const auto e = hn::Mul(hn::Sub(hn::Load(d, far_x + i), ox), fx);
    const auto f = hn::Mul(hn::Sub(hn::Load(d, far_y + i), oy), fy);
    const auto g = hn::Mul(hn::Sub(hn::Load(d, far_z + i), oz), fz);
    t1 = hn::IfThenElse(e < t1, e, t1);
    t1 = hn::IfThenElse(f < t1, f, t1);
    t1 = hn::IfThenElse(g < t1, g, t1);
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
      const uint32_t slot = p.slot[i + size_t(k)];
      TriangleHit th;
      h &= ~(1u << k);
      if (slot != kInvalidIndex && intersect_triangle(s, tris[slot], tnear, tfar, th)) {
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
HWY_INLINE void ClosestInPack(const TrianglePack& p, const RayShear& shear, const Triangle* tris, const uint32_t* ids,
                              float tnear, Hit& hit) {
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
    const uint32_t id = ids[p.slot[k]];
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
  StackEntry hits[kWideWidth];
  int k = 0;
  bits |= (1u << i) | (1u << j);
  while (bits) {
    const int c = __builtin_ctz(bits);
    bits &= bits - 1;
    StackEntry e{n.child[c], n.count[c], t[c]};
    int m = k++;
    while (m > 0 && hits[m - 1].t < e.t) {  // descending: farthest first
      hits[m] = hits[m - 1];
      --m;
    }
    hits[m] = e;
  }
  for (int c = 0; c < k - 1; ++c) stack[sp++] = hits[c];
  next = hits[k - 1];
  return true;
}

bool IntersectWide(const WideBvh& bvh, const Ray& ray, Hit& hit) {
  hit = Hit{};
  hit.t = ray.tfar;
  const auto& nodes = bvh.nodes();
  if (nodes.empty()) return false;
  const WideRay wr(ray);
  const RayShear shear(ray);
  const Triangle* tris = bvh.triangles().data();
  const uint32_t* ids = bvh.triangle_ids().data();
  const TrianglePack* packs = bvh.packs().data();
  StackEntry stack[kWideWidth * (Bvh::kMaxDepth + 2)];
  int sp = 0;
  HWY_ALIGN float t[kWideWidth];
  StackEntry cur{0, 0, ray.tnear};
  for (;;) {
    if (cur.count == 0) {
      const WideNode& n = nodes[cur.child];
      if (Descend(n, TestChildren(n, wr, ray.tnear, hit.t, t), t, stack, sp, cur)) continue;
    } else {
      ClosestInPack(packs[cur.child], shear, tris, ids, ray.tnear, hit);
    }
    // Pop, skipping entries now beyond the closest hit (<=: ties still count).
    do {
      if (sp == 0) return finish_hit(bvh.scene(), hit);
      cur = stack[--sp];
    } while (!(cur.t <= hit.t * RayBoxTest::kTieGuard));
  }
}

// Any hit for one ray below `start` (a node, or a leaf pack when start.count > 0).
HWY_INLINE bool OccludedBelow(const WideBvh& bvh, const WideRay& wr, const RayShear& shear, float tnear, float tfar,
                              StackEntry start) {
  const WideNode* nodes = bvh.nodes().data();
  const Triangle* tris = bvh.triangles().data();
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

bool OccludedWide(const WideBvh& bvh, const Ray& ray) {
  if (bvh.nodes().empty()) return false;
  return OccludedBelow(bvh, WideRay(ray), RayShear(ray), ray.tnear, ray.tfar, StackEntry{0, 0, ray.tnear});
}

// Lane k of a bundle as a WideRay (the same values WideRay(rays.ray(k)) computes).
HWY_INLINE WideRay LaneRay(const BundleState& st, int k) {
  WideRay r;
  r.ox = st.org[0];
  r.oy = st.org[1];
  r.oz = st.org[2];
  r.ix = st.ix[k];
  r.iy = st.iy[k];
  r.iz = st.iz[k];
  r.fx = st.fx[k];
  r.fy = st.fy[k];
  r.fz = st.fz[k];
  r.nx = st.nx[k] != 0;
  r.ny = st.ny[k] != 0;
  r.nz = st.nz[k] != 0;
  return r;
}

// Fewer rays than this entering a subtree together go down it one by one: a lane-parallel test
// costs the same for one ray as for sixteen, a ray alone tests all eight children in one pass.
constexpr int kBundleMinLanes = 8;

// The lanes of `mask` whose rays hit a triangle of `pack`.
HWY_INLINE uint32_t OccludedInPackBundle(const TrianglePack& pack, uint32_t count, const Triangle* tris,
                                         const BundleState& st, uint32_t mask) {
  uint32_t found = 0;
  for (uint32_t k = 0; k < count && mask; ++k) {
    const Vec3 v0{pack.v[0][0][k], pack.v[0][1][k], pack.v[0][2][k]};
    const Vec3 v1{pack.v[1][0][k], pack.v[1][1][k], pack.v[1][2][k]};
    const Vec3 v2{pack.v[2][0][k], pack.v[2][1][k], pack.v[2][2][k]};
    const uint32_t hit = OccludedByTriangle(v0, v1, v2, tris[pack.slot[k]], st, mask);
    found |= hit;
    mask &= ~hit;
  }
  return found;
}

uint32_t OccludedBundleWide(const WideBvh& bvh, const RayBundle& rays, uint32_t origin) {
  const auto& nodes = bvh.nodes();
  if (nodes.empty() || rays.active == 0) return 0;
  const auto& leaves = bvh.leaf_places();
  if (origin >= leaves.size() || leaves[origin] == kInvalidIndex) {
    uint32_t occluded = 0;  // no leaf to start from: each ray from the root
    for (uint32_t bits = rays.active; bits; bits &= bits - 1) {
      const int k = __builtin_ctz(bits);
      if (OccludedWide(bvh, rays.ray(k))) occluded |= 1u << k;
    }
    return occluded;
  }
  const BundleState st(rays);
  // Rays that miss the tree's box are answered at once, as from the root.
  const float lo[3] = {bvh.bounds().lo.x, bvh.bounds().lo.y, bvh.bounds().lo.z};
  const float hi[3] = {bvh.bounds().hi.x, bvh.bounds().hi.y, bvh.bounds().hi.z};
  uint32_t active = TestBundleBox(lo, hi, st, rays.active);
  if (active == 0) return 0;
  const Triangle* tris = bvh.triangles().data();
  const TrianglePack* packs = bvh.packs().data();
  uint32_t occluded = 0;

  // Subtrees to search, each with the lanes that enter it: many lanes go on together, one SIMD
  // lane per ray; a few go on one ray at a time.
  struct Entry {
    uint32_t child, count, lanes;
  };
  Entry stack[kWideWidth * (Bvh::kMaxDepth + 2)];
  int sp = 0;
  const auto push_children = [&](const WideNode& n, uint32_t skip, uint32_t lanes) {
    for (uint32_t c = 0; c < uint32_t(kWideWidth); ++c) {
      if (c == skip || (n.child[c] == 0 && n.count[c] == 0)) continue;  // the way we came, or an empty slot
      const float clo[3] = {n.lo_x[c], n.lo_y[c], n.lo_z[c]}, chi[3] = {n.hi_x[c], n.hi_y[c], n.hi_z[c]};
      const uint32_t entering = TestBundleBox(clo, chi, st, lanes);
      if (entering) stack[sp++] = {n.child[c], n.count[c], entering};
    }
  };
  const auto search = [&] {
    while (sp > 0) {
      const Entry e = stack[--sp];
      const uint32_t lanes = e.lanes & active;
      if (lanes == 0) continue;
      uint32_t found = 0;
      if (std::popcount(lanes) < kBundleMinLanes) {
        for (uint32_t bits = lanes; bits; bits &= bits - 1) {
          const int k = __builtin_ctz(bits);
          if (OccludedBelow(bvh, LaneRay(st, k), st.shear(k), st.tnear, st.tfar, StackEntry{e.child, e.count, 0.0f}))
            found |= 1u << k;
        }
      } else if (e.count > 0) {
        found = OccludedInPackBundle(packs[e.child], e.count, tris, st, lanes);
      } else {
        push_children(nodes[e.child], kWideWidth, lanes);
      }
      occluded |= found;
      active &= ~found;
      if (active == 0) return;
    }
  };
  // The origin's leaf, then each ancestor's other children on the way up: every node off that
  // path lies below exactly one of them, so together they cover the tree.
  uint32_t where = leaves[origin];
  uint32_t node = where / kWideWidth, slot = where % kWideWidth;
  stack[sp++] = {nodes[node].child[slot], nodes[node].count[slot], active};
  search();
  while (active != 0) {
    push_children(nodes[node], slot, active);
    search();
    where = bvh.node_places()[node];
    if (where == kInvalidIndex) break;
    node = where / kWideWidth;
    slot = where % kWideWidth;
  }
  return occluded;
}

// Brute force over packs: closest hit, ties to the lower scene index as everywhere.
bool IntersectBrute(const SimdBruteForce& bf, const Ray& ray, Hit& hit) {
  hit = Hit{};
  hit.t = ray.tfar;
  const RayShear shear(ray);
  const Triangle* tris = bf.triangles().data();
  const uint32_t* ids = bf.triangle_ids().data();
  for (const TrianglePack& p : bf.packs()) ClosestInPack(p, shear, tris, ids, ray.tnear, hit);
  return finish_hit(bf.scene(), hit);
}

bool OccludedBrute(const SimdBruteForce& bf, const Ray& ray) {
  const RayShear shear(ray);
  const Triangle* tris = bf.triangles().data();
  HWY_ALIGN float tt[kWideWidth], uu[kWideWidth], vv[kWideWidth];
  for (const TrianglePack& p : bf.packs()) {
    if (IntersectPack(p, shear, tris, ray.tnear, ray.tfar, tt, uu, vv)) return true;
  }
  return false;
}

int64_t CurrentTarget() { return HWY_TARGET; }

}  // namespace HWY_NAMESPACE
}  // namespace tracer
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace tracer {

HWY_EXPORT(IntersectWide);
HWY_EXPORT(OccludedWide);
HWY_EXPORT(OccludedBundleWide);
HWY_EXPORT(CurrentTarget);
HWY_EXPORT(IntersectBrute);
HWY_EXPORT(OccludedBrute);

bool SimdBruteForce::intersect(const Ray& ray, Hit& hit) const {
  return HWY_DYNAMIC_DISPATCH(IntersectBrute)(*this, ray, hit);
}
bool SimdBruteForce::occluded(const Ray& ray) const { return HWY_DYNAMIC_DISPATCH(OccludedBrute)(*this, ray); }

SimdBruteForce::SimdBruteForce(const Scene& scene) : scene_(&scene) {
  for (uint32_t i = 0; i < scene.size(); ++i) {
    if (scene.triangles[i].degenerate()) continue;
    tris_.push_back(scene.triangles[i]);
    ids_.push_back(i);
  }
  for (uint32_t first = 0; first < tris_.size(); first += kWideWidth) {
    packs_.push_back(make_triangle_pack(tris_, first, std::min<uint32_t>(kWideWidth, uint32_t(tris_.size()) - first)));
  }
}

TrianglePack make_triangle_pack(std::span<const Triangle> triangles, uint32_t first, uint32_t count) {
  TrianglePack p;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int lane = 0; lane < kWideWidth; ++lane) {
    const bool used = uint32_t(lane) < count;
    const Triangle& t = triangles[used ? first + uint32_t(lane) : first];
    const Vec3 vs[3] = {t.v0, t.v1, t.v2};
    for (int vtx = 0; vtx < 3; ++vtx) {
      for (int axis = 0; axis < 3; ++axis) p.v[vtx][axis][lane] = used ? vs[vtx][axis] : nan;
    }
    p.slot[lane] = used ? first + uint32_t(lane) : kInvalidIndex;
  }
  return p;
}

// One table-indexed call per ray (Highway's dynamic dispatch), never per node: the kernels above
// inline the whole traversal.
bool WideBvh::intersect(const Ray& ray, Hit& hit) const { return HWY_DYNAMIC_DISPATCH(IntersectWide)(*this, ray, hit); }
bool WideBvh::occluded(const Ray& ray) const { return HWY_DYNAMIC_DISPATCH(OccludedWide)(*this, ray); }
uint32_t WideBvh::occluded_bundle_from(const RayBundle& rays, uint32_t origin) const {
  return HWY_DYNAMIC_DISPATCH(OccludedBundleWide)(*this, rays, origin);
}

std::string WideBvh::simd_target() { return hwy::TargetName(HWY_DYNAMIC_DISPATCH(CurrentTarget)()); }

void WideBvh::force_simd_target(SimdTarget target) {
  switch (target) {
    case SimdTarget::Auto:
    case SimdTarget::Avx512:
      hwy::DisableTargets(0);
      break;
    case SimdTarget::Avx2:
      hwy::DisableTargets(HWY_AVX3 | HWY_AVX3_DL);
      break;
    case SimdTarget::Sse4:
      hwy::DisableTargets(HWY_AVX2 | HWY_AVX3 | HWY_AVX3_DL);
      break;
  }
}

bool WideBvh::force_simd_target(const std::string& name) {
  for (const EnumName<SimdTarget>& e : kSimdTargetNames) {
    if (e.name == name) {
      force_simd_target(e.value);
      return true;
    }
  }
  return false;
}

namespace {

// Collapses the binary subtree under `root` into wide nodes, appending to `out`; returns the
// index of the wide node made for `root`.
class Collapser {
 public:
  Collapser(const Bvh& bin, std::vector<WideNode>& out, std::vector<TrianglePack>& packs)
      : bin_(bin), out_(out), packs_(packs), first_(bin.nodes().size()), count_(bin.nodes().size()) {
    // Each binary subtree's triangles are one contiguous run (the builder lays leaves out in
    // depth-first order); record it, children before parents (children have larger indices).
    const auto& nodes = bin.nodes();
    for (size_t i = nodes.size(); i-- > 0;) {
      if (i == 1) continue;  // padding
      const BvhNode& n = nodes[i];
      first_[i] = n.leaf() ? n.index : first_[n.index];
      count_[i] = n.leaf() ? n.count : count_[n.index] + count_[n.index + 1];
    }
  }

  uint32_t collapse(uint32_t root) {
    // Open the largest inner node until eight children (or only leaves) remain: keeps the
    // children's total surface area, and so the expected cost, as low as greedy can.
    std::vector<uint32_t> kids{root};
    if (!packable(root)) kids = {bin_.nodes()[root].index, bin_.nodes()[root].index + 1};
    while (kids.size() < size_t(kWideWidth)) {
      int best = -1;
      float best_area = -1.0f;
      for (size_t i = 0; i < kids.size(); ++i) {
        const BvhNode& n = bin_.nodes()[kids[i]];
        const float area = Aabb{n.lo, n.hi}.half_area();
        if (!packable(kids[i]) && area > best_area) {
          best = int(i);
          best_area = area;
        }
      }
      if (best < 0) break;
      const BvhNode& n = bin_.nodes()[kids[size_t(best)]];
      kids[size_t(best)] = n.index;
      kids.insert(kids.begin() + best + 1, n.index + 1);
    }
    const auto self = static_cast<uint32_t>(out_.size());
    out_.emplace_back();
    {
      WideNode& w = out_[self];
      for (int i = 0; i < kWideWidth; ++i) {
        w.lo_x[i] = w.lo_y[i] = w.lo_z[i] = kInfinity;
        w.hi_x[i] = w.hi_y[i] = w.hi_z[i] = -kInfinity;
        w.child[i] = 0;
        w.count[i] = 0;
      }
    }
    for (size_t i = 0; i < kids.size(); ++i) {
      const BvhNode& n = bin_.nodes()[kids[i]];
      uint32_t child = 0, count = 0;
      if (packable(kids[i])) {
        count = count_[kids[i]];
        child = make_pack(first_[kids[i]], count);
      } else {
        child = collapse(kids[i]);  // may reallocate out_: index, not reference
      }
      WideNode& w = out_[self];
      w.lo_x[i] = n.lo.x;
      w.lo_y[i] = n.lo.y;
      w.lo_z[i] = n.lo.z;
      w.hi_x[i] = n.hi.x;
      w.hi_y[i] = n.hi.y;
      w.hi_z[i] = n.hi.z;
      w.child[i] = child;
      w.count[i] = count;
    }
    return self;
  }

 private:
  // A subtree of at most one pack's worth of triangles becomes one leaf: testing eight lanes
  // costs about what one more level of boxes would, and saves that level's loads.
  bool packable(uint32_t node) const { return count_[node] <= uint32_t(kWideWidth); }

  uint32_t make_pack(uint32_t first, uint32_t count) {
    packs_.push_back(make_triangle_pack(bin_.triangles(), first, count));
    return static_cast<uint32_t>(packs_.size() - 1);
  }

  const Bvh& bin_;
  std::vector<WideNode>& out_;
  std::vector<TrianglePack>& packs_;
  std::vector<uint32_t> first_, count_;  // per binary node: its subtree's triangle run
};

}  // namespace

WideBvh::WideBvh(const Scene& scene, const BvhBuildOptions& options_in) : scene_(&scene) {
  BvhBuildOptions options = options_in;
  options.max_leaf = std::min(options.max_leaf, kWideWidth);
  const Bvh binary(scene, options);
  tris_ = binary.triangles();
  ids_ = binary.triangle_ids();
  if (binary.nodes().empty()) return;
  nodes_.reserve(binary.nodes().size() / 4 + 1);
  Collapser(binary, nodes_, packs_).collapse(0);
  bounds_ = Aabb{binary.nodes()[0].lo, binary.nodes()[0].hi};
  // Where every node and every triangle's leaf hangs, for searches that start at a leaf.
  node_place_.assign(nodes_.size(), kInvalidIndex);
  leaf_place_.assign(scene.size(), kInvalidIndex);
  for (uint32_t w = 0; w < nodes_.size(); ++w) {
    const WideNode& n = nodes_[w];
    for (uint32_t c = 0; c < uint32_t(kWideWidth); ++c) {
      if (n.count[c] > 0) {
        const TrianglePack& pack = packs_[n.child[c]];
        for (uint32_t lane = 0; lane < n.count[c]; ++lane) leaf_place_[ids_[pack.slot[lane]]] = place(w, c);
      } else if (n.child[c] != 0) {  // child 0 is the root: an empty slot
        node_place_[n.child[c]] = place(w, c);
      }
    }
  }
}

std::string WideBvh::validate() const {
  if (nodes_.empty()) return tris_.empty() ? "" : "triangles but no nodes";
  std::vector<uint32_t> seen(scene_->size(), 0);
  std::vector<uint32_t> visits(nodes_.size(), 0);
  std::vector<uint32_t> stack{0};
  // Every triangle below a child must lie in that child's box; check leaf by leaf.
  struct Pending {
    uint32_t node;
    Aabb box;
  };
  std::vector<Pending> work{{0, bounds_}};  // the root's children lie in the tree's bounds
  while (!work.empty()) {
    const Pending p = work.back();
    work.pop_back();
    if (p.node >= nodes_.size()) return "node index out of range";
    if (++visits[p.node] > 1) return "node " + std::to_string(p.node) + " reached twice";
    const WideNode& n = nodes_[p.node];
    for (int i = 0; i < kWideWidth; ++i) {
      const Aabb box{{n.lo_x[i], n.lo_y[i], n.lo_z[i]}, {n.hi_x[i], n.hi_y[i], n.hi_z[i]}};
      if (box.empty()) {
        if (n.count[i] != 0 || n.child[i] != 0) return "empty slot with contents";
        continue;
      }
      if (!p.box.contains(box)) return "child box outside its parent's box";
      if (n.count[i] > 0) {
        if (n.child[i] >= packs_.size() || n.count[i] > uint32_t(kWideWidth)) return "leaf pack out of range";
        const TrianglePack& pk = packs_[n.child[i]];
        for (uint32_t lane = 0; lane < uint32_t(kWideWidth); ++lane) {
          if (lane >= n.count[i]) {
            if (pk.slot[lane] != kInvalidIndex || !std::isnan(pk.v[0][0][lane])) return "padding lane not empty";
            continue;
          }
          const uint32_t k = pk.slot[lane];
          if (k >= tris_.size()) return "pack slot out of range";
          const Triangle& t = tris_[k];
          if (pk.v[0][0][lane] != t.v0.x || pk.v[2][2][lane] != t.v2.z) return "pack lane differs from its triangle";
          if (!box.contains(t.bounds())) return "leaf box does not contain triangle " + std::to_string(ids_[k]);
          if (leaf_place_.size() != seen.size() || leaf_place_[ids_[k]] != place(p.node, uint32_t(i))) {
            return "leaf place of triangle " + std::to_string(ids_[k]) + " is wrong";
          }
          ++seen[ids_[k]];
        }
      } else {
        if (n.child[i] >= node_place_.size() || node_place_[n.child[i]] != place(p.node, uint32_t(i))) {
          return "node " + std::to_string(n.child[i]) + " does not record its parent";
        }
        work.push_back({n.child[i], box});
      }
    }
  }
  for (size_t i = 0; i < seen.size(); ++i) {
    const uint32_t expected = scene_->triangles[i].degenerate() ? 0 : 1;
    if (seen[i] != expected)
      return "triangle " + std::to_string(i) + " appears in " + std::to_string(seen[i]) + " leaves";
  }
  for (size_t i = 0; i < visits.size(); ++i) {
    if (visits[i] != 1) return "node " + std::to_string(i) + " unreachable";
  }
  if (node_place_.empty() || node_place_[0] != kInvalidIndex) return "the root has a parent";
  for (size_t i = 0; i < seen.size(); ++i) {
    if (seen[i] == 0 && leaf_place_[i] != kInvalidIndex)
      return "degenerate triangle " + std::to_string(i) + " has a leaf place";
  }
  return "";
}

}  // namespace tracer
#endif  // HWY_ONCE
