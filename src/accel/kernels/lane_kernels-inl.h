// The bodies of lane_kernels.hpp's kernels, written once over a lane type L. Not a header of its
// own: it is included inside a namespace twice, by lane_kernels.hpp (namespace tracer, for
// scalar code) and by simd_lanes-inl.h (namespace tracer::HWY_NAMESPACE, once per SIMD target,
// so each copy is compiled with that target's instructions as Highway requires). No include
// guard, no includes: its includers provide kInfinity and SlabGuards.

template <class V>
struct Lanes3 {
  V x, y, z;
};

// The slab test. `near` and `far` are the planes each slab is entered and left by (chosen by the
// direction's signs) minus the ray origin; `inv` the reciprocal direction, `inv_far` the same
// times kFarGuard. Returns the lanes whose ray enters the box within [tnear, tfar]; t0 receives
// the entry distance. A zero direction component gives an infinite reciprocal, an origin on that
// slab's plane then 0*inf = NaN, which max_or_second/min_or_second drop: such a slab never culls.
template <class L>
typename L::M slab_test(const Lanes3<typename L::V>& near, const Lanes3<typename L::V>& far,
                        const Lanes3<typename L::V>& inv, const Lanes3<typename L::V>& inv_far, typename L::V tnear,
                        typename L::V tfar, typename L::V& t0) {
  using V = typename L::V;
  V t1 = tfar * L::splat(SlabGuards::kTieGuard);
  t0 = L::max_or_second(near.x * inv.x, tnear);
  t0 = L::max_or_second(near.y * inv.y, t0);
  t0 = L::max_or_second(near.z * inv.z, t0);
  t1 = L::min_or_second(far.x * inv_far.x, t1);
  t1 = L::min_or_second(far.y * inv_far.y, t1);
  t1 = L::min_or_second(far.z * inv_far.z, t1);
  return t0 <= t1;
}

// The watertight test's 2D edge functions (Woop, Benthin, Wald, JCGT 2013). a, b, c are the
// vertices minus the ray origin, in the shear's axis order (x and y across the ray, z along it);
// sx, sy the shear. u, v, w are the edge functions of the sheared triangle seen down +z.
template <class V>
struct ShearedTriangle {
  V ax, ay, bx, by, cx, cy;  // sheared x, y
  V az, bz, cz;              // z, not yet scaled
  V u, v, w;
};

template <class L>
ShearedTriangle<typename L::V> shear_triangle(const Lanes3<typename L::V>& a, const Lanes3<typename L::V>& b,
                                              const Lanes3<typename L::V>& c, typename L::V sx, typename L::V sy) {
  ShearedTriangle<typename L::V> s;
  s.az = a.z;
  s.bz = b.z;
  s.cz = c.z;
  s.ax = a.x - sx * a.z;
  s.ay = a.y - sy * a.z;
  s.bx = b.x - sx * b.z;
  s.by = b.y - sy * b.z;
  s.cx = c.x - sx * c.z;
  s.cy = c.y - sy * c.z;
  s.u = s.cx * s.by - s.cy * s.bx;
  s.v = s.ax * s.cy - s.ay * s.cx;
  s.w = s.bx * s.ay - s.by * s.ax;
  return s;
}

// Some edge function exactly zero: the float answer is ambiguous on that edge, and callers decide
// such lanes in double (scalar: recompute u, v, w; SIMD: the scalar test for that lane).
template <class L>
typename L::M on_an_edge(const ShearedTriangle<typename L::V>& s) {
  const auto zero = L::splat(0.0f);
  return L::or_(L::or_(s.u == zero, s.v == zero), s.w == zero);
}

// Edge functions of both signs: the ray passes outside the triangle.
template <class L>
typename L::M passes_outside(const ShearedTriangle<typename L::V>& s) {
  const auto zero = L::splat(0.0f);
  const auto neg = L::or_(L::or_(s.u < zero, s.v < zero), s.w < zero);
  const auto pos = L::or_(L::or_(s.u > zero, s.v > zero), s.w > zero);
  return L::and_(neg, pos);
}

template <class L>
struct TriangleLanes {
  typename L::M hit;
  typename L::V t, u, v;  // distance and barycentrics of v1 and v2; meaningful where hit
};

// The hit of the sheared triangle: inside (not `outside`, which is passes_outside(s), computed
// once by the caller that also decides early with it), not degenerate or seen exactly edge-on
// (det = 0), and t within [tnear, tfar] (also rejecting NaN and overflow). sz is the shear's
// 1 / dir[kz]. Two-sided.
template <class L>
TriangleLanes<L> triangle_hit(const ShearedTriangle<typename L::V>& s, typename L::M outside, typename L::V sz,
                              typename L::V tnear, typename L::V tfar) {
  const auto det = s.u + s.v + s.w;
  const auto rcp = L::splat(1.0f) / det;
  const auto t = (s.u * (sz * s.az) + s.v * (sz * s.bz) + s.w * (sz * s.cz)) * rcp;
  TriangleLanes<L> out;
  out.hit = L::and_not(outside, det != L::splat(0.0f));
  out.hit = L::and_(out.hit, L::and_(L::and_(t >= tnear, t <= tfar), t < L::splat(kInfinity)));
  out.t = t;
  out.u = s.v * rcp;
  out.v = s.w * rcp;
  return out;
}
