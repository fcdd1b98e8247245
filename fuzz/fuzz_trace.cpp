// libFuzzer target for the whole path a render walks: load an OBJ (the input), build every
// accelerator over it (the 8-wide BVH at both build qualities, each validated), and trace a few rays derived from the
// input through each. Every accelerator must give brute force's occlusion answer and closest hit bit for bit, or a real
// hit that rounding made a near tie (see same()), as the README says; a mismatch, a crash or a
// non-InputError exception is a finding.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <string>
#include <variant>

#include "accel/accelerator.hpp"
#include "accel/kernels/triangle_test.hpp"
#include "base/errors.hpp"
#include "importers/obj_loader.hpp"

namespace {

using namespace tracer;

// A deterministic ray from 24 bytes of the input (or a hash of the scene when it runs out): an
// origin and a point to aim at, each inside the scene's bounds grown by half.
Ray ray_from(const uint8_t* bytes, const Scene& scene) {
  float f[6];
  for (int i = 0; i < 6; ++i) {
    uint32_t u;
    std::memcpy(&u, bytes + 4 * i, 4);
    f[i] = float(u >> 8) / float(1u << 24) * 2.0f - 0.5f;  // [-0.5, 1.5)
  }
  const Vec3 lo = scene.bounds.lo, ext = scene.bounds.extent();
  const Vec3 org{lo.x + f[0] * ext.x, lo.y + f[1] * ext.y, lo.z + f[2] * ext.z};
  const Vec3 to{lo.x + f[3] * ext.x, lo.y + f[4] * ext.y, lo.z + f[5] * ext.z};
  Ray r;
  r.org = org;
  r.dir = to - org;
  if (length(r.dir) == 0.0f) r.dir = Vec3{0.0f, 0.0f, 1.0f};
  r.dir = normalize(r.dir);
  return r;
}

// Says what differed before the fuzzer records the input, so a finding is readable at once.
[[noreturn]] void mismatch(const char* what, size_t accel, const Ray& ray, bool ha, const Hit& a, bool hb,
                           const Hit& b) {
  std::fprintf(stderr,
               "fuzz_trace: %s mismatch, accelerator %zu, ray org (%a %a %a) dir (%a %a %a) tfar %a\n"
               "  brute force: %d tri %u t %a u %a v %a\n  accelerator: %d tri %u t %a u %a v %a\n",
               what, accel, ray.org.x, ray.org.y, ray.org.z, ray.dir.x, ray.dir.y, ray.dir.z, ray.tfar, ha, a.tri, a.t,
               a.u, a.v, hb, b.tri, b.t, b.u, b.v);
  std::abort();
}

// The accelerator agrees with brute force when both miss, or both hit at the same t on the same
// triangle (ties in t go to the lower index). A BVH culls a box whose entry lies beyond the
// closest t found so far (by more than its tie guard); a triangle's own t carries the rounding
// of its vertices' distances, so near an edge and close to the origin it can come out below its
// box's entry, and such a box may be culled. So the accelerator may also report another
// triangle, if it is a real hit (the triangle test gives it exactly the reported t, u, v) at most
// `kNearTie` of the vertices' distance scale beyond brute force's t: the rounding, not a
// traversal that skipped geometry.
constexpr float kNearTie = 0x1p-12f;

bool same(const Scene& scene, const Ray& ray, bool ha, const Hit& a, bool hb, const Hit& b) {
  if (ha != hb) return false;
  if (!ha) return true;
  if (a.tri == b.tri) {
    return a.t == b.t && a.u == b.u && a.v == b.v && a.geomID == b.geomID && a.primID == b.primID;
  }
  if (b.tri >= scene.triangles.size() || b.geomID != scene.tri_geom[b.tri] || b.primID != scene.tri_prim[b.tri]) {
    return false;
  }
  TriangleHit th;
  if (!intersect_triangle(RayShear(ray), scene.triangles[b.tri], ray.tnear, ray.tfar, th) || th.t != b.t ||
      th.u != b.u || th.v != b.v) {
    return false;
  }
  if (b.t == a.t) return true;  // a tie
  const Aabb& box = scene.bounds;
  const float scale = a.t + length(max(abs(box.lo - ray.org), abs(box.hi - ray.org)));
  return b.t > a.t && b.t - a.t <= kNearTie * scale;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > 8192) return 0;  // small scenes: brute force is the reference
  const std::string obj(reinterpret_cast<const char*>(data), size);
  Scene scene;
  try {
    scene = load_obj_from_string(obj, "", "fuzz.obj", [](const std::string&) {});
  } catch (const InputError&) {
    return 0;
  }
  if (!std::isfinite(length(scene.bounds.extent()))) return 0;
  const BruteForce reference(scene);
  AccelOptions sah{.kind = AccelKind::Bvh}, median{.kind = AccelKind::Bvh}, wide, wide_high, simd;
  median.bvh.split = BvhSplit::Median;
  wide.kind = wide_high.kind = AccelKind::Bvh8;
  wide_high.quality = BuildQuality::High;  // spatial splits: references cut to their triangle's part
  simd.kind = AccelKind::BruteSimd;
  const Accelerator accels[] = {build_accelerator(scene, sah), build_accelerator(scene, median),
                                build_accelerator(scene, wide), build_accelerator(scene, wide_high),
                                build_accelerator(scene, simd)};
  for (const Accelerator& a : accels) {
    if (const auto* w = std::get_if<WideBvh>(a.impl.get())) {
      if (const std::string bad = w->validate(); !bad.empty()) {
        std::fprintf(stderr, "fuzz_trace: %s tree invalid: %s\n", a.name.c_str(), bad.c_str());
        std::abort();
      }
    }
  }
  // Rays from the input's bytes, cycling over them; always a few, even from a short input.
  uint8_t window[24];
  for (size_t k = 0; k < 16; ++k) {
    for (size_t i = 0; i < sizeof window; ++i) window[i] = data[(k * 7 + i * 13) % size];
    Ray ray = ray_from(window, scene);
    Hit expected;
    const bool hit = reference.intersect(ray, expected);
    for (size_t i = 0; i < std::size(accels); ++i) {
      Hit got;
      const bool h = accels[i].visit([&](const auto& a) { return a.intersect(ray, got); });
      if (!same(scene, ray, hit, expected, h, got)) mismatch("closest hit", i, ray, hit, expected, h, got);
    }
    ray.tfar = hit ? expected.t * 0.999f : kInfinity;
    const bool occluded = reference.occluded(ray);
    for (size_t i = 0; i < std::size(accels); ++i) {
      const bool o = accels[i].visit([&](const auto& a) { return a.occluded(ray); });
      if (o != occluded) mismatch("occlusion", i, ray, occluded, expected, o, expected);
    }
  }
  return 0;
}
