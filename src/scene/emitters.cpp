#include "scene/emitters.hpp"

#include <algorithm>
#include <cmath>

#include "math/sampling.hpp"
#include "math/spherical_triangle.hpp"
#include "scene/scene.hpp"

namespace tracer {

Emitters::Emitters(const Scene& scene, bool solid_angle) : solid_angle_(solid_angle) {
  std::vector<double> power;
  for (uint32_t i = 0; i < scene.triangles.size(); ++i) {
    const Material& m = scene.materials[scene.tri_material[i]];
    if (!m.emissive() || scene.triangles[i].degenerate()) continue;
    const float area = 0.5f * length(scene.triangles[i].normal());
    const double p = double(luminance(m.ke)) * double(area);
    if (!(area > 0.0f) || !(p > 0.0) || !std::isfinite(p)) continue;
    tris_.push_back(i);
    area_.push_back(area);
    power.push_back(p);
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

bool Emitters::by_solid_angle(const Scene& scene, uint32_t tri, Vec3 from, double& omega) const {
  if (!solid_angle_) return false;
  const Triangle& t = scene.triangles[tri];
  omega = triangle_solid_angle(from, t.v0, t.v1, t.v2);
  return omega >= kMinSolidAngle && omega <= kMaxSolidAngle;
}

bool Emitters::sample(const Scene& scene, Vec3 from, float u_select, float u1, float u2, EmitterSample& out) const {
  if (tris_.empty()) return false;
  const size_t i =
      std::min(size_t(std::upper_bound(cdf_.begin(), cdf_.end(), u_select) - cdf_.begin()), tris_.size() - 1);
  const uint32_t tri = tris_[i];
  const Triangle& t = scene.triangles[tri];
  double omega = 0.0;
  if (by_solid_angle(scene, tri, from, omega)) {
    const Vec3 n = t.normal();
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
    out.radiance = scene.materials[scene.tri_material[tri]].ke;
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
  const float cos_light = -dot(normalize(t.normal()), out.wi);  // the front face must face `from`
  if (!(cos_light > 0.0f)) return false;
  out.pdf = pmf_[i] * d2 / (area_[i] * cos_light);
  out.radiance = scene.materials[scene.tri_material[tri]].ke;
  return std::isfinite(out.pdf);
}

float Emitters::pdf(const Scene& scene, uint32_t tri, Vec3 from, Vec3 to) const {
  const auto it = std::lower_bound(tris_.begin(), tris_.end(), tri);
  if (it == tris_.end() || *it != tri) return 0.0f;
  const size_t i = size_t(it - tris_.begin());
  double omega = 0.0;
  if (by_solid_angle(scene, tri, from, omega)) {
    return dot(scene.triangles[tri].normal(), from - scene.triangles[tri].v0) > 0.0f ? float(double(pmf_[i]) / omega)
                                                                                     : 0.0f;
  }
  const Vec3 d = to - from;
  const float d2 = dot(d, d);
  if (!(d2 > 0.0f)) return 0.0f;
  const float cos_light = -dot(normalize(scene.triangles[tri].normal()), d / std::sqrt(d2));
  return cos_light > 0.0f ? pmf_[i] * d2 / (area_[i] * cos_light) : 0.0f;
}

}  // namespace tracer
