// The 8-wide BVH's AO-bundle kernels (up to 16 rays leaving one point, searched top-down
// together while many of them enter the same nodes), shared by the flat tree's bundles
// (wide_bvh_bundles.cpp) and the two-level tree's (each instance's mesh tree). Include it after
// foreach_target.h; the guard toggles per target as Highway's -inl.h convention requires.
#if defined(TRACER_ACCEL_WIDE_BVH_BUNDLE_KERNELS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef TRACER_ACCEL_WIDE_BVH_BUNDLE_KERNELS_INL_H_
#undef TRACER_ACCEL_WIDE_BVH_BUNDLE_KERNELS_INL_H_
#else
#define TRACER_ACCEL_WIDE_BVH_BUNDLE_KERNELS_INL_H_
#endif

#include <hwy/highway.h>

#include <bit>

#include "accel/kernels/ray_bundle-inl.h"
#include "accel/wide_bvh/wide_bvh.hpp"
#include "accel/wide_bvh/wide_bvh_kernels-inl.h"

HWY_BEFORE_NAMESPACE();
namespace tracer {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

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
    const uint32_t hit = OccludedByTriangle(v0, v1, v2, tris[pack.id[k]], st, mask);
    found |= hit;
    mask &= ~hit;
  }
  return found;
}

// A bundle's walk down an 8-wide tree of `nodes` from the root: each entry carries the lanes
// that entered it, children are pushed in slot order (so the last slot, the smallest subtree, is
// searched first, as in single-ray any-hit), and lanes found occluded leave every entry.
// `visit(e, lanes, found)` answers entry e for `lanes` (setting `found`) and returns true, or
// returns false to have the walk open it as a node. Returns the occluded lanes of `active`.
struct BundleEntry {
  uint32_t child, count, lanes;
};
template <class Count, class Visit>
HWY_INLINE uint32_t BundleWalk(const WideNode* nodes, const BundleState& st, uint32_t active, Count count,
                               const Visit& visit) {
  uint32_t occluded = 0;
  BundleEntry stack[kWideWidth * (Bvh::kMaxDepth + 2)];
  int sp = 0;
  stack[sp++] = {0, 0, active};
  while (sp > 0) {
    const BundleEntry e = stack[--sp];
    const uint32_t lanes = e.lanes & active;
    if (lanes == 0) continue;
    uint32_t found = 0;
    if (!visit(e, lanes, found)) {
      count.node(uint32_t(std::popcount(lanes)));
      const WideNode& n = nodes[e.child];
      for (uint32_t c = 0; c < uint32_t(kWideWidth); ++c) {
        if (n.child[c] == 0 && n.count[c] == 0) break;  // empty slots come last
        const float clo[3] = {n.lo_x[c], n.lo_y[c], n.lo_z[c]}, chi[3] = {n.hi_x[c], n.hi_y[c], n.hi_z[c]};
        const uint32_t entering = TestBundleBox(clo, chi, st, lanes);
        if (entering) stack[sp++] = {n.child[c], n.count[c], entering};
      }
    }
    occluded |= found;
    active &= ~found;
    if (active == 0) break;
  }
  return occluded;
}

// The lanes of `st` (a bundle) among `active` whose rays are occluded in `bvh`'s whole tree.
template <class Count>
HWY_INLINE uint32_t OccludedBundleInTree(const WideBvh& bvh, const BundleState& st, uint32_t active, Count count) {
  if (bvh.nodes().empty() || active == 0) return 0;
  // Rays that miss the tree's box are answered at once.
  const float lo[3] = {bvh.bounds().lo.x, bvh.bounds().lo.y, bvh.bounds().lo.z};
  const float hi[3] = {bvh.bounds().hi.x, bvh.bounds().hi.y, bvh.bounds().hi.z};
  active = TestBundleBox(lo, hi, st, active);
  if (active == 0) return 0;
  const Triangle* tris = bvh.scene().triangles.data();
  const TrianglePack* packs = bvh.packs().data();
  return BundleWalk(bvh.nodes().data(), st, active, count,
                    [&](const BundleEntry& e, uint32_t lanes, uint32_t& found) TRACER_INLINE_LAMBDA {
                      if (std::popcount(lanes) < kBundleMinLanes) {
                        for (uint32_t bits = lanes; bits; bits &= bits - 1) {
                          const int k = __builtin_ctz(bits);
                          if (OccludedBelow(bvh, LaneRay(st, k), st.shear(k), st.tnear, st.tfar,
                                            StackEntry{e.child, e.count, 0.0f}, count))
                            found |= 1u << k;
                        }
                        return true;
                      }
                      if (e.count == 0) return false;
                      count.pack(uint32_t(std::popcount(lanes)), e.count);
                      found = OccludedInPackBundle(packs[e.child], e.count, tris, st, lanes);
                      return true;
                    });
}

}  // namespace HWY_NAMESPACE
}  // namespace tracer
HWY_AFTER_NAMESPACE();

#endif  // TRACER_ACCEL_WIDE_BVH_BUNDLE_KERNELS_INL_H_
