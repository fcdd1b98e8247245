#include "scene/emitters.hpp"

#include <algorithm>
#include <cmath>

#include "math/sampling.hpp"
#include "math/spherical_triangle.hpp"
#include "scene/emission.hpp"
#include "scene/scene.hpp"

namespace tracer {

Emitters::Emitters(const Scene& scene, bool solid_angle) : solid_angle_(solid_angle) {
  std::vector<double> power;
  // Keys ascend: instances in order, each its mesh's triangles in order.
  const auto add = [&](TriangleRange range, uint32_t inst) {
    for (uint32_t i = range.first; i < range.first + range.count; ++i) {
      const Material& m = scene.materials[scene.tri_material[i]];
      if (!m.emissive() || scene.triangles[i].degenerate()) continue;
      const float area = 0.5f * length(scene.world_triangle(i, inst).normal());
      const double p = double(luminance(mean_emission(scene, i))) * double(area);  // 0 over black texels
      if (!(area > 0.0f) || !(p > 0.0) || !std::isfinite(p)) continue;
      keys_.push_back(key(i, inst));
      area_.push_back(area);
      power.push_back(p);
    }
  };
  if (!scene.instanced()) {
    add(TriangleRange::all(scene), kInvalidIndex);
  } else {
    for (uint32_t i = 0; i < scene.instances.size(); ++i) {
      const Mesh& m = scene.meshes[scene.instances[i].mesh];
      if (m.emissive) add(m.triangles, i);
    }
  }
  // Double sums so a million small emitters still get exact-enough probabilities.
  double total = 0.0;
  for (double p : power) total += p;
  double running = 0.0;
  for (double p : power) {
    running += p;
    pmf_.push_back(float(p / total));
    cdf_.push_back(float(running / total));
  }
  if (!cdf_.empty()) cdf_.back() = 1.0f;
}

bool Emitters::by_solid_angle(const Triangle& t, Vec3 from, double& omega) const {
  if (!solid_angle_) return false;
  omega = triangle_solid_angle(from, t.v0, t.v1, t.v2);
  return omega >= kMinSolidAngle && omega <= kMaxSolidAngle;
}

bool Emitters::sample(const Scene& scene, Vec3 from, float u_select, float u1, float u2, EmitterSample& out) const {
  if (keys_.empty()) return false;
  const size_t i =
      std::min(size_t(std::upper_bound(cdf_.begin(), cdf_.end(), u_select) - cdf_.begin()), keys_.size() - 1);
  const auto tri = uint32_t(keys_[i]);
  const auto inst = uint32_t((keys_[i] >> 32) - 1);
  const Triangle t = scene.world_triangle(tri, inst);
  double omega = 0.0;
  if (by_solid_angle(t, from, omega)) {
    const Vec3 n = scene.face_normal(t, inst);
    if (!(dot(n, from - t.v0) > 0.0f)) return false;  // behind the emitting face
    Vec3 w;
    if (!sample_spherical_triangle(from, t.v0, t.v1, t.v2, u1, u2, w)) return false;
    // Where the direction meets the triangle's plane.
    const float along = dot(n, t.v0 - from) / dot(n, w);
    if (!(along > 0.0f) || !std::isfinite(along)) return false;
    out.wi = w;
    out.distance = along;
    out.point = from + w * along;
    out.pdf = float(double(pmf_[i]) / omega);
    // The point's barycentric coordinates, for its texel: the triangle's areas opposite each corner.
    const Vec3 e1 = t.v1 - t.v0, e2 = t.v2 - t.v0, d = out.point - t.v0;
    const float d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2), dp1 = dot(d, e1), dp2 = dot(d, e2);
    const float det = d11 * d22 - d12 * d12;
    const float b1 = det != 0.0f ? std::clamp((d22 * dp1 - d12 * dp2) / det, 0.0f, 1.0f) : 0.0f;
    const float b2 = det != 0.0f ? std::clamp((d11 * dp2 - d12 * dp1) / det, 0.0f, 1.0f - b1) : 0.0f;
    out.radiance = emitted_radiance(scene, tri, b1, b2);
    return std::isfinite(out.pdf);
  }
  float b1, b2;
  uniform_triangle(u1, u2, b1, b2);
  out.point = t.v0 * (1.0f - b1 - b2) + t.v1 * b1 + t.v2 * b2;
  const Vec3 to = out.point - from;
  const float d2 = dot(to, to);
  if (!(d2 > 0.0f)) return false;
  out.distance = std::sqrt(d2);
  out.wi = to / out.distance;
  const float cos_light = -dot(normalize(scene.face_normal(t, inst)), out.wi);  // the front face must face `from`
  if (!(cos_light > 0.0f)) return false;
  out.pdf = pmf_[i] * d2 / (area_[i] * cos_light);
  out.radiance = emitted_radiance(scene, tri, b1, b2);
  return std::isfinite(out.pdf);
}

float Emitters::pdf(const Scene& scene, uint32_t tri, uint32_t inst, Vec3 from, Vec3 to) const {
  const auto it = std::lower_bound(keys_.begin(), keys_.end(), key(tri, inst));
  if (it == keys_.end() || *it != key(tri, inst)) return 0.0f;
  const size_t i = size_t(it - keys_.begin());
  const Triangle t = scene.world_triangle(tri, inst);
  double omega = 0.0;
  if (by_solid_angle(t, from, omega)) {
    return dot(scene.face_normal(t, inst), from - t.v0) > 0.0f ? float(double(pmf_[i]) / omega) : 0.0f;
  }
  const Vec3 d = to - from;
  const float d2 = dot(d, d);
  if (!(d2 > 0.0f)) return 0.0f;
  const float cos_light = -dot(normalize(scene.face_normal(t, inst)), d / std::sqrt(d2));
  return cos_light > 0.0f ? pmf_[i] * d2 / (area_[i] * cos_light) : 0.0f;
}

}  // namespace tracer
