// The 8-wide BVH's packet kernels (up to 16 coherent rays, one SIMD lane each, going down a tree
// together), shared by the flat tree's packets (wide_bvh_packets.cpp) and the two-level tree's
// (the instance tree walked by the world packet, each mesh tree by the packet moved into its
// space). Every lane computes the scalar code's arithmetic (RayBoxTest, the watertight test of
// triangle_test.hpp, closer()), so each ray gets the hit it gets alone, bit for bit. Include it
// after foreach_target.h; the guard toggles per target as Highway's -inl.h convention requires.
#if defined(TRACER_ACCEL_WIDE_BVH_PACKET_KERNELS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef TRACER_ACCEL_WIDE_BVH_PACKET_KERNELS_INL_H_
#undef TRACER_ACCEL_WIDE_BVH_PACKET_KERNELS_INL_H_
#else
#define TRACER_ACCEL_WIDE_BVH_PACKET_KERNELS_INL_H_
#endif

#include <hwy/highway.h>

#include <bit>
#include <cmath>

#include "accel/kernels/simd_lanes-inl.h"
#include "accel/wide_bvh/wide_bvh.hpp"

HWY_BEFORE_NAMESPACE();
namespace tracer {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Per-lane constants and running results of one packet, as SoA arrays.
struct PacketState {
  HWY_ALIGN float ox[kPacketSize], oy[kPacketSize], oz[kPacketSize];
  HWY_ALIGN float ix[kPacketSize], iy[kPacketSize], iz[kPacketSize];    // reciprocal direction
  HWY_ALIGN float fx[kPacketSize], fy[kPacketSize], fz[kPacketSize];    // ... times SlabGuards::kFarGuard
  HWY_ALIGN int32_t nx[kPacketSize], ny[kPacketSize], nz[kPacketSize];  // -1 where that reciprocal is negative
  HWY_ALIGN float sx[kPacketSize], sy[kPacketSize], sz[kPacketSize];    // shear constants (RayShear)
  HWY_ALIGN float tnear[kPacketSize];
  HWY_ALIGN float t[kPacketSize], u[kPacketSize], v[kPacketSize];  // closest hit so far (t = tfar if none)
  HWY_ALIGN int32_t tri[kPacketSize];  // its scene index with the sign bit flipped: signed order = unsigned order
  const float* okx;                    // the origin component along the shared shear axes
  const float* oky;
  const float* okz;
  int kx, ky, kz;
  const RayPacket* rays;
};

constexpr int32_t kFlip = INT32_MIN;

// Tests child `c` of `n` against the lanes in `mask`: returns the lanes that enter it before
// their closest hit, and the entry distance of the first of them (the visiting order: in a
// coherent packet one ray's order is the packet's, and it costs no reduction across lanes).
HWY_INLINE uint32_t TestChildPacket(const WideNode& n, int c, const PacketState& st, uint32_t mask, float& entry) {
  const hn::ScalableTag<float> d;
  using L = SimdLanes<decltype(d)>;
  const size_t N = hn::Lanes(d);
  const auto lo_x = hn::Set(d, n.lo_x[c]), lo_y = hn::Set(d, n.lo_y[c]), lo_z = hn::Set(d, n.lo_z[c]);
  const auto hi_x = hn::Set(d, n.hi_x[c]), hi_y = hn::Set(d, n.hi_y[c]), hi_z = hn::Set(d, n.hi_z[c]);
  HWY_ALIGN float t0s[kPacketSize];
  uint32_t hits = 0;
  for (size_t i = 0; i < size_t(kPacketSize); i += N) {
    const uint32_t chunk = ChunkBits(mask, i, N);
    if (chunk == 0) continue;
    const auto ox = hn::Load(d, st.ox + i), oy = hn::Load(d, st.oy + i), oz = hn::Load(d, st.oz + i);
    Lanes3<L::V> near, far;  // each lane's planes relative to its own origin
    NearFarPlanes(d, st.nx, st.ny, st.nz, i, {lo_x - ox, lo_y - oy, lo_z - oz}, {hi_x - ox, hi_y - oy, hi_z - oz}, near,
                  far);
    const Lanes3<L::V> inv{hn::Load(d, st.ix + i), hn::Load(d, st.iy + i), hn::Load(d, st.iz + i)};
    const Lanes3<L::V> inv_far{hn::Load(d, st.fx + i), hn::Load(d, st.fy + i), hn::Load(d, st.fz + i)};
    L::V t0;
    const auto enters = slab_test<L>(near, far, inv, inv_far, hn::Load(d, st.tnear + i), hn::Load(d, st.t + i), t0);
    const auto hit = hn::And(enters, LaneMask(d, chunk));
    if (hn::AllFalse(d, hit)) continue;
    hits |= Bits(d, hit) << i;
    hn::Store(t0, d, t0s + i);
  }
  entry = hits ? t0s[__builtin_ctz(hits)] : kInfinity;
  return hits;
}

// Triangle `k` of `p`, its vertices along the packet's shear axes splatted once; sheared_for()
// moves it to the origins of lanes i .. i + N and shears it by their directions.
template <class V>
struct PackTriangleLanes {
  V ax, ay, az, bx, by, bz, cx, cy, cz;
  template <class D>
  HWY_INLINE PackTriangleLanes(D d, const TrianglePack& p, int k, const PacketState& st)
      : ax(hn::Set(d, p.v[0][st.kx][k])),
        ay(hn::Set(d, p.v[0][st.ky][k])),
        az(hn::Set(d, p.v[0][st.kz][k])),
        bx(hn::Set(d, p.v[1][st.kx][k])),
        by(hn::Set(d, p.v[1][st.ky][k])),
        bz(hn::Set(d, p.v[1][st.kz][k])),
        cx(hn::Set(d, p.v[2][st.kx][k])),
        cy(hn::Set(d, p.v[2][st.ky][k])),
        cz(hn::Set(d, p.v[2][st.kz][k])) {}
  template <class D>
  HWY_INLINE ShearedTriangle<V> sheared_for(D d, const PacketState& st, size_t i) const {
    using L = SimdLanes<D>;
    const V okx = hn::Load(d, st.okx + i), oky = hn::Load(d, st.oky + i), okz = hn::Load(d, st.okz + i);
    return shear_triangle<L>({ax - okx, ay - oky, az - okz}, {bx - okx, by - oky, bz - okz},
                             {cx - okx, cy - oky, cz - okz}, hn::Load(d, st.sx + i), hn::Load(d, st.sy + i));
  }
};

// Triangle `k` of `pack` against the lanes in `mask`, updating each lane's closest hit exactly
// as intersect_range() does for one ray.
HWY_INLINE void IntersectTrianglePacket(const TrianglePack& p, int k, const Triangle* tris, PacketState& st,
                                        uint32_t mask) {
  const hn::ScalableTag<float> d;
  using L = SimdLanes<decltype(d)>;
  const hn::RebindToSigned<decltype(d)> di;
  const size_t N = hn::Lanes(d);
  const uint32_t tri = p.id[k];
  const int32_t id = int32_t(tri ^ uint32_t(kFlip));
  const PackTriangleLanes<L::V> t(d, p, k, st);
  const auto vid = hn::Set(di, id);
  for (size_t i = 0; i < size_t(kPacketSize); i += N) {
    const uint32_t chunk = ChunkBits(mask, i, N);
    if (chunk == 0) continue;
    const ShearedTriangle<L::V> s = t.sheared_for(d, st, i);
    const auto best_t = hn::Load(d, st.t + i);
    const auto best_id = hn::Load(di, st.tri + i);
    const TriangleLanes<L> found =
        triangle_hit<L>(s, passes_outside<L>(s), hn::Load(d, st.sz + i), hn::Load(d, st.tnear + i), best_t);
    // closer(): nearer t wins; equal t goes to the lower scene index.
    auto hit = hn::And(found.hit, hn::Or(hn::Lt(found.t, best_t),
                                         hn::And(hn::Eq(found.t, best_t), hn::RebindMask(d, hn::Lt(vid, best_id)))));
    hit = hn::And(hit, LaneMask(d, chunk));
    // Lanes exactly on an edge in float are decided by the scalar test in double, as they would
    // be for that ray alone; their vector result is dropped.
    const auto on_edge = on_an_edge<L>(s);
    hit = hn::AndNot(on_edge, hit);
    const auto keep = hn::Not(hit);
    hn::Store(hn::IfThenElse(keep, best_t, found.t), d, st.t + i);
    hn::Store(hn::IfThenElse(keep, hn::Load(d, st.u + i), found.u), d, st.u + i);
    hn::Store(hn::IfThenElse(keep, hn::Load(d, st.v + i), found.v), d, st.v + i);
    hn::Store(hn::IfThenElse(hn::RebindMask(di, keep), best_id, vid), di, st.tri + i);
    for (uint32_t bits = Bits(d, on_edge) & chunk; bits; bits &= bits - 1) {
      const size_t lane = i + size_t(__builtin_ctz(bits));
      const RayShear shear(st.rays->ray(int(lane)));
      const uint32_t best_tri = uint32_t(st.tri[lane]) ^ uint32_t(kFlip);
      Hit h;
      h.t = st.t[lane];
      h.tri = best_tri;
      TriangleHit th;
      if (intersect_triangle(shear, tris[tri], st.tnear[lane], h.t, th) && closer(th.t, tri, h)) {
        st.t[lane] = th.t;
        st.u[lane] = th.u;
        st.v[lane] = th.v;
        st.tri[lane] = id;
      }
    }
  }
}

struct PacketEntry {
  uint32_t child, count;  // count > 0: a leaf pack
  uint32_t lanes;         // the rays that entered this child
  float t;                // their smallest entry distance
};

// Fills `st` from the lanes `active` of `rays`, each lane's closest hit so far empty at its tfar;
// returns whether those rays share the shear axes of the triangle test (the packet's triangle
// test needs them shared; the box test does not).
HWY_INLINE bool InitPacketState(const RayPacket& rays, uint32_t active, PacketState& st) {
  st.rays = &rays;
  st.kx = st.ky = st.kz = -1;
  bool shared_axes = true;
  for (uint32_t bits = active; bits; bits &= bits - 1) {
    const int lane = __builtin_ctz(bits);
    const Ray r = rays.ray(lane);
    const RayShear shear(r);
    if (st.kx < 0) {
      st.kx = shear.kx;
      st.ky = shear.ky;
      st.kz = shear.kz;
    }
    shared_axes &= shear.kx == st.kx && shear.ky == st.ky && shear.kz == st.kz;
    st.ox[lane] = r.org.x;
    st.oy[lane] = r.org.y;
    st.oz[lane] = r.org.z;
    const RayBoxTest box(r);
    st.ix[lane] = box.inv[0];
    st.iy[lane] = box.inv[1];
    st.iz[lane] = box.inv[2];
    st.fx[lane] = box.inv_far[0];
    st.fy[lane] = box.inv_far[1];
    st.fz[lane] = box.inv_far[2];
    st.nx[lane] = std::signbit(box.inv[0]) ? -1 : 0;
    st.ny[lane] = std::signbit(box.inv[1]) ? -1 : 0;
    st.nz[lane] = std::signbit(box.inv[2]) ? -1 : 0;
    st.sx[lane] = shear.sx;
    st.sy[lane] = shear.sy;
    st.sz[lane] = shear.sz;
    st.tnear[lane] = r.tnear;
    st.t[lane] = r.tfar;
  }
  // Lanes without a ray get the first ray's values (harmless in the SIMD arithmetic; the masks
  // keep them out of every result), copied rather than computed again: the two-level tree fills a
  // state per instance a packet enters, often for a few of its lanes.
  const int first = __builtin_ctz(active);
  for (uint32_t bits = ~active & ((1u << kPacketSize) - 1u); bits; bits &= bits - 1) {
    const int lane = __builtin_ctz(bits);
    for (float* a :
         {st.ox, st.oy, st.oz, st.ix, st.iy, st.iz, st.fx, st.fy, st.fz, st.sx, st.sy, st.sz, st.tnear, st.t})
      a[lane] = a[first];
    st.nx[lane] = st.nx[first];
    st.ny[lane] = st.ny[first];
    st.nz[lane] = st.nz[first];
  }
  for (int lane = 0; lane < kPacketSize; ++lane) {
    st.u[lane] = st.v[lane] = 0.0f;
    st.tri[lane] = int32_t(kInvalidIndex ^ uint32_t(kFlip));
  }
  const float* org[3] = {st.ox, st.oy, st.oz};
  if (shared_axes) {
    st.okx = org[st.kx];
    st.oky = org[st.ky];
    st.okz = org[st.kz];
  }
  return shared_axes;
}

// The closest-hit walk of the lanes `active` of `st` down an 8-wide tree of `nodes` from the
// root, each child visited by the lanes that enter it before their closest hit, nearest first (by
// its first lane's entry). `leaf(e)` answers a leaf entry (e.child, e.count, e.lanes), updating
// the lanes' closest hits in st: a pack of triangles in the flat tree, an instance at the top of
// the two-level tree.
template <class Count, class Leaf>
HWY_INLINE void PacketWalk(const WideNode* nodes, const PacketState& st, uint32_t active, Count count,
                           const Leaf& leaf) {
  PacketEntry stack[kWideWidth * (Bvh::kMaxDepth + 2)];
  int sp = 0;
  PacketEntry cur{0, 0, active, 0.0f};
  for (;;) {
    if (cur.count == 0) {
      count.node(uint32_t(std::popcount(cur.lanes)));
      const WideNode& n = nodes[cur.child];
      PacketEntry hit[kWideWidth];
      int k = 0;
      for (int c = 0; c < kWideWidth; ++c) {
        if (!(n.lo_x[c] <= n.hi_x[c])) continue;  // empty slot
        float entry;
        const uint32_t lanes = TestChildPacket(n, c, st, cur.lanes, entry);
        if (lanes == 0) continue;
        // Insertion sort, farthest first: the nearest ends up last and is visited next.
        PacketEntry e{n.child[c], n.count[c], lanes, entry};
        int m = k++;
        while (m > 0 && hit[m - 1].t < e.t) {
          hit[m] = hit[m - 1];
          --m;
        }
        hit[m] = e;
      }
      if (k > 0) {
        for (int c = 0; c < k - 1; ++c) stack[sp++] = hit[c];
        cur = hit[k - 1];
        continue;
      }
    } else {
      leaf(cur);
    }
    if (sp == 0) break;
    cur = stack[--sp];
  }
}

// The closest hits of the lanes `active` of `st` (its rays sharing their shear axes) in the whole
// tree, nearer than each lane's st.t (updated with u, v and tri; ties to the lower index).
template <class Count>
HWY_INLINE void ClosestInTreePacket(const WideBvh& bvh, PacketState& st, uint32_t active, Count count) {
  if (bvh.nodes().empty()) return;
  const TrianglePack* packs = bvh.packs().data();
  const Triangle* tris = bvh.scene().triangles.data();
  PacketWalk(bvh.nodes().data(), st, active, count, [&](const PacketEntry& e) TRACER_INLINE_LAMBDA {
    count.pack(uint32_t(std::popcount(e.lanes)), e.count);
    const TrianglePack& p = packs[e.child];
    for (uint32_t k = 0; k < e.count; ++k) IntersectTrianglePacket(p, int(k), tris, st, e.lanes);
  });
}

}  // namespace HWY_NAMESPACE
}  // namespace tracer
HWY_AFTER_NAMESPACE();

#endif  // TRACER_ACCEL_WIDE_BVH_PACKET_KERNELS_INL_H_
