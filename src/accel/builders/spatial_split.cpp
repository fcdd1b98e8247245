// Binning, sweeping and dividing for spatial splits (see spatial_split.hpp).
#include "accel/builders/spatial_split.hpp"

#include <algorithm>
#include <cmath>

namespace tracer {
namespace {

// 2^-20: about eight units in the last place of a float, far above the cut points' rounding.
constexpr float kWiden = 1.0f / 1048576.0f;

SseBox sse_box(const Aabb& b) {
  return {_mm_setr_ps(b.lo.x, b.lo.y, b.lo.z, 0.0f), _mm_setr_ps(b.hi.x, b.hi.y, b.hi.z, 0.0f)};
}
SseBox sse_box(const PrimRef& r) {  // without the id in lo's lane 3
  return {_mm_and_ps(r.lo, _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0))), r.hi};
}

struct Corners {
  __m128 v[3];
  float a[3][4];  // the same, to read one coordinate
  explicit Corners(const Triangle& t) {
    const Vec3* p[3] = {&t.v0, &t.v1, &t.v2};
    for (int i = 0; i < 3; ++i) {
      v[i] = _mm_setr_ps(p[i]->x, p[i]->y, p[i]->z, 0.0f);
      _mm_storeu_ps(a[i], v[i]);
    }
  }
};

// Widens a cut part by kWiden of the box's magnitude (not along the cut axis) and keeps it in the box.
SseBox clamp_to(SseBox part, const SseBox& box, __m128 off_axis) {
  if (part.empty()) return SseBox{};
  const __m128 abs = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
  const __m128 m = _mm_and_ps(
      _mm_mul_ps(_mm_max_ps(_mm_and_ps(box.lo, abs), _mm_and_ps(box.hi, abs)), _mm_set1_ps(kWiden)), off_axis);
  part.lo = _mm_max_ps(_mm_sub_ps(part.lo, m), box.lo);
  part.hi = _mm_min_ps(_mm_add_ps(part.hi, m), box.hi);
  return part.empty() ? SseBox{} : part;
}

__m128 off_axis_mask(int axis) {
  alignas(16) int32_t m[4] = {-1, -1, -1, 0};
  m[axis] = 0;
  return _mm_castsi128_ps(_mm_load_si128(reinterpret_cast<const __m128i*>(m)));
}

void clip(const Corners& c, const SseBox& box, int axis, float pos, __m128 off_axis, SseBox& left, SseBox& right) {
  SseBox l, r;
  const __m128 plane = _mm_set1_ps(pos);
  for (int i = 0; i < 3; ++i) {
    const int j = i == 2 ? 0 : i + 1;
    const float pa = c.a[i][axis], qa = c.a[j][axis];
    if (pa <= pos) l.extend(c.v[i]);
    if (pa >= pos) r.extend(c.v[i]);
    if ((pa < pos && qa > pos) || (pa > pos && qa < pos)) {
      __m128 x = _mm_add_ps(c.v[i], _mm_mul_ps(_mm_sub_ps(c.v[j], c.v[i]), _mm_set1_ps((pos - pa) / (qa - pa))));
      x = _mm_or_ps(_mm_and_ps(off_axis, x), _mm_andnot_ps(off_axis, plane));  // exactly on the plane
      l.extend(x);
      r.extend(x);
    }
  }
  left = clamp_to(l, box, off_axis);
  right = clamp_to(r, box, off_axis);
}

}  // namespace

void clip_triangle(const Triangle& tri, const Aabb& box, int axis, float pos, Aabb& left, Aabb& right) {
  SseBox l, r;
  clip(Corners(tri), sse_box(box), axis, pos, off_axis_mask(axis), l, r);
  left = l.empty() ? Aabb{} : l.aabb();
  right = r.empty() ? Aabb{} : r.aabb();
}

int SpatialSplit::slab(float x) const {
  const float f = (x - lo) / width;
  if (!(f > 0.0f)) return 0;  // also NaN: never converted
  return f >= float(bins - 1) ? bins - 1 : static_cast<int>(f);
}

SpatialSplit find_spatial_split(const Triangle* tris, const PrimRef* refs, uint32_t begin, uint32_t end,
                                const Aabb& box, int bins) {
  bins = std::clamp(bins, 2, kMaxSpatialBins);
  SpatialSplit best;
  for (int a = 0; a < 3; ++a) {
    const float extent = box.hi[a] - box.lo[a];
    if (!(extent > 0.0f)) continue;
    SpatialSplit s;
    s.axis = a;
    s.bins = bins;
    s.lo = box.lo[a];
    s.width = extent / float(bins);
    if (!(s.width > 0.0f)) continue;  // an extent of a few denormals
    const __m128 off_axis = off_axis_mask(a);
    SseBox slab_box[kMaxSpatialBins];
    uint32_t enter[kMaxSpatialBins] = {}, exit[kMaxSpatialBins] = {};
    for (uint32_t i = begin; i < end; ++i) {
      const SseBox rb = sse_box(refs[i]);
      const int b0 = s.slab(refs[i].lo[a]), b1 = s.slab(refs[i].hi[a]);
      ++enter[b0];
      ++exit[b1];
      if (b0 == b1) {
        slab_box[b0].extend(rb);
        continue;
      }
      // Cut the reference at each slab edge it crosses, left to right.
      const Corners corners(tris[refs[i].id()]);
      SseBox rest = rb;
      for (int b = b0; b < b1 && !rest.empty(); ++b) {
        SseBox part, next;
        clip(corners, rest, a, s.lo + s.width * float(b + 1), off_axis, part, next);
        slab_box[b].extend(part);  // an empty part changes nothing
        rest = next;
      }
      slab_box[b1].extend(rest);
    }
    // Sweep: references entering slabs left of the plane go left, those leaving right of it go right.
    float right_area[kMaxSpatialBins];
    uint32_t right_count[kMaxSpatialBins];
    SseBox acc;
    uint32_t n = 0;
    for (int b = bins - 1; b > 0; --b) {
      acc.extend(slab_box[b]);
      n += exit[b];
      right_area[b] = acc.aabb().half_area();
      right_count[b] = n;
    }
    acc = SseBox{};
    n = 0;
    for (int b = 1; b < bins; ++b) {
      acc.extend(slab_box[b - 1]);
      n += enter[b - 1];
      if (n == 0 || right_count[b] == 0) continue;
      const float raw = acc.aabb().half_area() * float(n) + right_area[b] * float(right_count[b]);
      if (raw < best.raw) {
        s.bin = b;
        s.raw = raw;
        s.left_count = n;
        s.right_count = right_count[b];
        best = s;
        SseBox l, r;
        for (int k = 0; k < bins; ++k) (k < b ? l : r).extend(slab_box[k]);
        best.left_box = l.aabb();
        best.right_box = r.aabb();
      }
    }
  }
  return best;
}

void divide_spatially(const Triangle* tris, const PrimRef* refs, uint32_t begin, uint32_t end,
                      const SpatialSplit& split, std::vector<PrimRef>& left, std::vector<PrimRef>& right) {
  left.clear();
  right.clear();
  const int a = split.axis;
  const float pos = split.plane();
  const float left_area = split.left_box.half_area(), right_area = split.right_box.half_area();
  const auto nl = float(split.left_count), nr = float(split.right_count);
  for (uint32_t i = begin; i < end; ++i) {
    const PrimRef& r = refs[i];
    const Aabb rb = r.box();
    const int b0 = split.slab(rb.lo[a]), b1 = split.slab(rb.hi[a]);
    if (b1 < split.bin) {
      left.push_back(r);
      continue;
    }
    if (b0 >= split.bin) {
      right.push_back(r);
      continue;
    }
    // Crossing: cut, or kept whole on the side where that costs less.
    Aabb l = split.left_box, rr = split.right_box;
    l.extend(rb);
    rr.extend(rb);
    const float cut = left_area * nl + right_area * nr;
    const float whole_left = l.half_area() * nl + right_area * (nr - 1.0f);
    const float whole_right = left_area * (nl - 1.0f) + rr.half_area() * nr;
    if (whole_left < cut && whole_left <= whole_right) {
      left.push_back(r);
      continue;
    }
    if (whole_right < cut) {
      right.push_back(r);
      continue;
    }
    Aabb lb, rb2;
    clip_triangle(tris[r.id()], rb, a, pos, lb, rb2);
    if (lb.empty()) {
      right.push_back(r);
    } else if (rb2.empty()) {
      left.push_back(r);
    } else {
      left.push_back(PrimRef::make(lb, r.id()));
      right.push_back(PrimRef::make(rb2, r.id()));
    }
  }
}

}  // namespace tracer
