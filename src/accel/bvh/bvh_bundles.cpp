// Occlusion bundles on the binary BVH: the AO rays of one shading point leave one point in up to
// 16 directions. Started at their origin triangle's leaf (as Bvh::occluded_from starts one ray),
// they all walk up the same path and test the same sibling boxes, so the walk is made once, one
// SIMD lane per ray (one AVX-512 register, two AVX2 or four SSE4 ones); below a sibling, the rays
// that enter it go down together with a lane mask, and each ray leaves the bundle when it is
// found occluded.
//
// Each lane computes the scalar RayBoxTest's arithmetic (the shared origin makes plane - origin
// one scalar per plane), and triangles are tested by the scalar watertight test per lane, so
// every ray gets the answer it gets alone.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "accel/bvh/bvh_bundles.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <bit>

#include "accel/bvh/bvh.hpp"
#include "accel/kernels/ray_bundle-inl.h"

HWY_BEFORE_NAMESPACE();
namespace tracer {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// The lanes of `mask` whose rays enter node `n`'s box.
HWY_INLINE uint32_t TestBox(const BvhNode& n, const BundleState& st, uint32_t mask) {
  const float lo[3] = {n.lo.x, n.lo.y, n.lo.z}, hi[3] = {n.hi.x, n.hi.y, n.hi.z};
  return TestBundleBox(lo, hi, st, mask);
}

// Fewer rays than this entering a subtree together go down it one by one (the scalar
// traversal): a lane-parallel test costs the same for one ray as for sixteen.
constexpr int kBundleMinLanes = 4;

// The lanes of `mask` whose rays hit a triangle of leaf `n`: triangle by triangle against all
// the lanes at once when there are at least as many rays as triangles, else ray by ray.
HWY_INLINE uint32_t OccludedInLeaf(const BvhNode& n, const Triangle* tris, const BundleState& st, uint32_t mask) {
  uint32_t found = 0;
  if (std::popcount(mask) >= int(n.count)) {
    for (uint32_t i = n.index, end = n.index + n.count; i < end && mask; ++i) {
      const uint32_t hit = OccludedByTriangle(tris[i].v0, tris[i].v1, tris[i].v2, tris[i], st, mask);
      found |= hit;
      mask &= ~hit;
    }
    return found;
  }
  for (uint32_t bits = mask; bits; bits &= bits - 1) {
    const int lane = __builtin_ctz(bits);
    const RayShear shear = st.shear(lane);
    TriangleHit th;
    for (uint32_t i = n.index, end = n.index + n.count; i < end; ++i) {
      if (intersect_triangle(shear, tris[i], st.tnear, st.tfar, th)) {
        found |= 1u << lane;
        break;
      }
    }
  }
  return found;
}

// The lanes of `mask`, all entering node `root`'s box, whose rays hit a triangle below it.
HWY_INLINE uint32_t OccludedBelow(const Bvh& bvh, const RayBundle& rays, uint32_t root, const BundleState& st,
                                  uint32_t mask) {
  const BvhNode* nodes = bvh.nodes().data();
  const Triangle* tris = bvh.triangles().data();
  struct Entry {
    uint32_t node, mask;
  };
  Entry stack[Bvh::kMaxDepth + 2];
  int sp = 0;
  uint32_t found = 0;
  Entry cur{root, mask};
  for (;;) {
    const BvhNode& n = nodes[cur.node];
    if (n.leaf()) {
      found |= OccludedInLeaf(n, tris, st, cur.mask);
      if (found == mask) return found;
    } else if (std::popcount(cur.mask) < kBundleMinLanes) {
      for (uint32_t bits = cur.mask; bits; bits &= bits - 1) {
        const int k = __builtin_ctz(bits);
        const Ray ray = rays.ray(k);
        if (bvh.occluded_subtree(cur.node, ray, st.shear(k), RayBoxTest(ray))) found |= 1u << k;
      }
      if (found == mask) return found;
    } else {
      const BvhNode& a = nodes[n.index];
      const BvhNode& b = nodes[n.index + 1];
      // Request the grandchildren's lines now, so the loads of both paths overlap.
      prefetch_child(a, nodes, tris);
      prefetch_child(b, nodes, tris);
      const uint32_t ma = TestBox(a, st, cur.mask);
      const uint32_t mb = TestBox(b, st, cur.mask);
      if (ma | mb) {
        // No order is needed for occlusion: the left child first, the right one stacked.
        if (ma && mb) stack[sp++] = {n.index + 1, mb};
        cur = ma ? Entry{n.index, ma} : Entry{n.index + 1, mb};
        continue;
      }
    }
    // Pop, dropping the lanes found occluded since the entry was stacked.
    for (;;) {
      if (sp == 0) return found;
      cur = stack[--sp];
      cur.mask &= ~found;
      if (cur.mask) break;
    }
  }
}

uint32_t OccludedBundleFrom(const Bvh& bvh, const RayBundle& rays, uint32_t origin) {
  const auto& nodes = bvh.nodes();
  if (nodes.empty() || rays.active == 0) return 0;
  const BundleState st(rays);
  // Rays that miss the scene's box are answered at once, as for one ray.
  uint32_t active = TestBox(nodes[0], st, rays.active);
  if (active == 0) return 0;
  const auto& leaf_of = bvh.leaf_of();
  if (origin >= leaf_of.size() || leaf_of[origin] == kInvalidIndex) return OccludedBelow(bvh, rays, 0, st, active);
  // The leaf, then each level's sibling subtree on the way up: together they cover the tree.
  uint32_t node = leaf_of[origin];
  uint32_t occluded = OccludedBelow(bvh, rays, node, st, active);
  active &= ~occluded;
  const auto& parents = bvh.pair_parents();
  while (node != 0 && active) {
    const uint32_t sibling = node ^ 1u;
    node = parents[node >> 1];
    const uint32_t entering = TestBox(nodes[sibling], st, active);
    if (entering == 0) continue;
    const uint32_t found = OccludedBelow(bvh, rays, sibling, st, entering);
    occluded |= found;
    active &= ~found;
  }
  return occluded;
}

}  // namespace HWY_NAMESPACE
}  // namespace tracer
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace tracer {

HWY_EXPORT(OccludedBundleFrom);

uint32_t Bvh::occluded_bundle_from(const RayBundle& rays, uint32_t origin) const {
  return SIMD_DISPATCH(simd_, OccludedBundleFrom)(*this, rays, origin);
}

}  // namespace tracer
#endif  // HWY_ONCE
