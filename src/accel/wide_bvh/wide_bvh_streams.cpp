// The 8-wide BVH's ray streams: a tile's occlusion rays, sorted so that neighbours point the same
// way from nearby points (render/stream_order.hpp), traced as packets of up to 16 consecutive
// rays of one shear class. Each lane has its own origin and direction (the packet kernels' box
// and triangle tests, wide_bvh_packet_kernels-inl.h), so any rays may share a packet; sorting is
// what makes them enter the same nodes. Compiled once per SIMD target.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "accel/wide_bvh/wide_bvh_streams.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <algorithm>
#include <bit>

#include "accel/wide_bvh/wide_bvh.hpp"
#include "accel/wide_bvh/wide_bvh_kernels-inl.h"
#include "accel/wide_bvh/wide_bvh_packet_kernels-inl.h"

HWY_BEFORE_NAMESPACE();
namespace tracer {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Fewer rays than this entering a subtree together go down it one by one (as a bundle's do).
constexpr int kStreamMinLanes = 4;

// The lanes of `mask` whose rays hit triangle k of `p` within [tnear, tfar]: the packet's
// triangle test (rays sharing the shear axes), lanes exactly on an edge decided by the scalar
// test in double, as a ray alone decides them.
HWY_INLINE uint32_t OccludedByTrianglePacket(const TrianglePack& p, int k, const Triangle* tris, const PacketState& st,
                                             uint32_t mask) {
  const hn::ScalableTag<float> d;
  using L = SimdLanes<decltype(d)>;
  const size_t N = hn::Lanes(d);
  const PackTriangleLanes<L::V> t(d, p, k, st);
  uint32_t found = 0;
  for (size_t i = 0; i < size_t(kPacketSize); i += N) {
    const uint32_t chunk = ChunkBits(mask, i, N);
    if (chunk == 0) continue;
    const ShearedTriangle<L::V> s = t.sheared_for(d, st, i);
    const auto on_edge = on_an_edge<L>(s);
    const auto outside = passes_outside<L>(s);
    const auto live = LaneMask(d, chunk);
    if (hn::AllFalse(d, hn::And(live, hn::Or(on_edge, hn::Not(outside))))) continue;
    const TriangleLanes<L> h =
        triangle_hit<L>(s, outside, hn::Load(d, st.sz + i), hn::Load(d, st.tnear + i), hn::Load(d, st.t + i));
    found |= Bits(d, hn::And(live, hn::AndNot(on_edge, h.hit))) << i;
    for (uint32_t bits = Bits(d, on_edge) & chunk; bits; bits &= bits - 1) {
      const int lane = int(i) + __builtin_ctz(bits);
      const Ray r = st.rays->ray(lane);
      TriangleHit th;
      if (intersect_triangle(RayShear(r), tris[p.id[k]], r.tnear, r.tfar, th)) found |= 1u << lane;
    }
  }
  return found;
}

// The lanes of `active` of `st` (rays sharing their shear axes, each up to its tfar in st.t)
// that are occluded in `bvh`: a walk down the tree with the lanes that enter each child, children
// pushed in slot order (the last, the smallest subtree, searched first, as a single ray's any-hit
// does), occluded lanes leaving every entry. `last_pack` is set to the last pack visited once a
// lane of its entry is occluded, by it or earlier (for the occluder cache; keeping only packs that
// occluded a lane themselves cost more instructions a ray: docs/bench/LOG.md, session 31).
template <class Count>
HWY_INLINE uint32_t OccludedPacketInTree(const WideBvh& bvh, const PacketState& st, uint32_t active, Count count,
                                         uint32_t& last_pack) {
  struct Entry {
    uint32_t child, count, lanes;
  };
  const WideNode* nodes = bvh.nodes().data();
  const TrianglePack* packs = bvh.packs().data();
  const Triangle* tris = bvh.scene().triangles.data();
  Entry stack[kWideWidth * (Bvh::kMaxDepth + 2)];
  int sp = 0;
  stack[sp++] = {0, 0, active};
  uint32_t occluded = 0;
  while (sp > 0) {
    const Entry e = stack[--sp];
    uint32_t lanes = e.lanes & ~occluded;
    if (lanes == 0) continue;
    if (std::popcount(lanes) < kStreamMinLanes) {
      for (uint32_t bits = lanes; bits; bits &= bits - 1) {
        const int k = __builtin_ctz(bits);
        const Ray r = st.rays->ray(k);
        if (OccludedBelow(bvh, WideRay(r), RayShear(r), r.tnear, r.tfar, StackEntry{e.child, e.count, 0.0f}, count))
          occluded |= 1u << k;
      }
    } else if (e.count == 0) {
      count.node(uint32_t(std::popcount(lanes)));
      const WideNode& n = nodes[e.child];
      for (int c = 0; c < kWideWidth; ++c) {
        if (!(n.lo_x[c] <= n.hi_x[c])) continue;  // empty slot
        float entry;
        const uint32_t entering = TestChildPacket(n, c, st, lanes, entry);
        if (entering) stack[sp++] = {n.child[c], n.count[c], entering};
      }
    } else {
      count.pack(uint32_t(std::popcount(lanes)), e.count);
      const TrianglePack& p = packs[e.child];
      for (uint32_t k = 0; k < e.count && lanes; ++k) {
        const uint32_t hit = OccludedByTrianglePacket(p, int(k), tris, st, lanes);
        occluded |= hit;
        lanes &= ~hit;
      }
      if (occluded & e.lanes) last_pack = e.child;
    }
    if (occluded == active) break;
  }
  return occluded;
}

// The occluder cache: per shear class, the last two packs in which a group found an occluder are
// tested first by the next group of the class (sorted, its rays point the same way from nearby
// points, so they often hit the same wall); a class whose cache ended none of a group's rays
// skips it for the next kCacheRest groups. It ends most of Sponza's AO rays before any node is
// visited (4.89 nodes a ray to 1.49) and costs the Bunny's, which mostly escape, a pack a group
// at most (docs/bench/LOG.md, session 30).
constexpr int kCacheSlots = 2;
constexpr int kCacheRest = 4;
struct OccluderCache {
  uint32_t pack[6][kCacheSlots];
  int rest[6] = {};
  OccluderCache() {
    for (auto& c : pack)
      for (uint32_t& p : c) p = kInvalidIndex;
  }
  void found(uint32_t cls, uint32_t p) {
    if (p == kInvalidIndex || p == pack[cls][0]) return;
    for (int k = kCacheSlots - 1; k > 0; --k) pack[cls][k] = pack[cls][k - 1];
    pack[cls][0] = p;
  }
};

// The lanes of `open` of `st` occluded by a triangle of the cached packs of class `cls`.
template <class Count>
HWY_INLINE uint32_t OccludedByCache(const WideBvh& bvh, const PacketState& st, uint32_t open, uint32_t cls,
                                    OccluderCache& cache, Count count) {
  if (cache.rest[cls] > 0) {
    --cache.rest[cls];
    return 0;
  }
  const Triangle* tris = bvh.scene().triangles.data();
  uint32_t hit = 0;
  for (int c = 0; c < kCacheSlots && open != hit; ++c) {
    const uint32_t at = cache.pack[cls][c];
    if (at == kInvalidIndex) break;
    const TrianglePack& p = bvh.packs()[at];
    uint32_t n = 0;  // padding (kInvalidIndex) comes last
    while (n < uint32_t(kWideWidth) && p.id[n] != kInvalidIndex) ++n;
    count.pack(uint32_t(std::popcount(open & ~hit)), n);
    for (uint32_t k = 0; k < n && open != hit; ++k) hit |= OccludedByTrianglePacket(p, int(k), tris, st, open & ~hit);
  }
  if (hit == 0 && cache.pack[cls][0] != kInvalidIndex) cache.rest[cls] = kCacheRest;
  return hit;
}

template <class Count>
void OccludedStreamT(const WideBvh& bvh, const RayStream& rays, StreamMask& out, Count count) {
  count.rays(rays.size);
  if (bvh.nodes().empty()) return;
  RayPacket packet;
  uint32_t index[kPacketSize];
  PacketState st;
  OccluderCache cache;
  // Groups of up to 16 consecutive rays of one class, which share the triangle test's shear axes.
  uint32_t begin = 0;
  for (uint32_t cls = 0; cls < 6; ++cls) {
    for (uint32_t at = begin, end = rays.class_end[cls]; at < end; at += kPacketSize) {
      const uint32_t n = std::min<uint32_t>(kPacketSize, end - at);
      packet.active = 0;
      for (uint32_t k = 0; k < n; ++k) {
        index[k] = rays.order[at + k];
        packet.set(int(k), rays.ray(index[k]));
      }
      uint32_t hit = 0;
      if (InitPacketState(packet, packet.active, st)) {  // always, by the class
        hit = OccludedByCache(bvh, st, packet.active, cls, cache, count);
        uint32_t last = kInvalidIndex;
        if (hit != packet.active) hit |= OccludedPacketInTree(bvh, st, packet.active & ~hit, count, last);
        cache.found(cls, last);
      } else {
        for (uint32_t bits = packet.active; bits; bits &= bits - 1) {
          const int k = __builtin_ctz(bits);
          const Ray r = packet.ray(k);
          if (OccludedBelow(bvh, WideRay(r), RayShear(r), r.tnear, r.tfar, StackEntry{0, 0, 0.0f}, count))
            hit |= 1u << k;
        }
      }
      for (uint32_t bits = hit; bits; bits &= bits - 1) out.set(index[__builtin_ctz(bits)]);
    }
    begin = rays.class_end[cls];
  }
}

void OccludedStream(const WideBvh& bvh, const RayStream& rays, StreamMask* out) {
  OccludedStreamT(bvh, rays, *out, NoCount{});
}
void OccludedStreamCounted(const WideBvh& bvh, const RayStream& rays, StreamMask* out, TraversalCounts* counts) {
  OccludedStreamT(bvh, rays, *out, CountInto{counts});
}

}  // namespace HWY_NAMESPACE
}  // namespace tracer
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace tracer {

HWY_EXPORT(OccludedStream);
HWY_EXPORT(OccludedStreamCounted);

void WideBvh::occluded_stream(const RayStream& rays, StreamMask& occluded) const {
  SIMD_DISPATCH(simd_, OccludedStream)(*this, rays, &occluded);
}
void WideBvh::occluded_stream(const RayStream& rays, StreamMask& occluded, TraversalCounts& counts) const {
  SIMD_DISPATCH(simd_, OccludedStreamCounted)(*this, rays, &occluded, &counts);
}

}  // namespace tracer
#endif  // HWY_ONCE
