// libFuzzer target for the whole path a render walks: load an OBJ (the input), build every
// accelerator over it, and trace a few rays derived from the input through each. Every
// accelerator must give brute force's closest hit (triangle, t, u, v) and occlusion answer bit
// for bit, as the README claims; a mismatch, a crash or a non-InputError exception is a finding.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>

#include "accel/accelerator.hpp"
#include "base/errors.hpp"
#include "scene/obj_loader.hpp"

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

bool same(bool ha, const Hit& a, bool hb, const Hit& b) {
  return ha == hb && (!ha || (a.tri == b.tri && a.t == b.t && a.u == b.u && a.v == b.v && a.geomID == b.geomID &&
                              a.primID == b.primID));
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
  AccelOptions sah{.kind = AccelKind::Bvh}, median{.kind = AccelKind::Bvh}, wide, simd;
  median.bvh.split = BvhSplit::Median;
  wide.kind = AccelKind::Bvh8;
  simd.kind = AccelKind::BruteSimd;
  const Accelerator accels[] = {build_accelerator(scene, sah), build_accelerator(scene, median),
                                build_accelerator(scene, wide), build_accelerator(scene, simd)};
  // Rays from the input's bytes, cycling over them; always a few, even from a short input.
  uint8_t window[24];
  for (size_t k = 0; k < 16; ++k) {
    for (size_t i = 0; i < sizeof window; ++i) window[i] = data[(k * 7 + i * 13) % size];
    Ray ray = ray_from(window, scene);
    Hit expected;
    const bool hit = reference.intersect(ray, expected);
    for (const Accelerator& accel : accels) {
      Hit got;
      const bool h = accel.visit([&](const auto& a) { return a.intersect(ray, got); });
      if (!same(hit, expected, h, got)) std::abort();
    }
    ray.tfar = hit ? expected.t * 0.999f : kInfinity;
    const bool occluded = reference.occluded(ray);
    for (const Accelerator& accel : accels) {
      if (accel.visit([&](const auto& a) { return a.occluded(ray); }) != occluded) std::abort();
    }
  }
  return 0;
}
