// A hit being shaded (SurfaceInteraction): where it is, which side was hit, the normals shading
// uses, and where the rays it sends start.
#pragma once

#include <cmath>
#include <numbers>

#include "math/ray.hpp"
#include "render/pass_context.hpp"

namespace tracer {

// Moves a surface point off its surface along the geometric normal (on the side the new ray
// leaves from), by a margin that grows with the coordinates' magnitude like float rounding does.
inline Vec3 offset_origin(Vec3 p, Vec3 n) {
  const float eps = 1e-4f * (1.0f + max_component(abs(p)));
  return p + n * eps;
}

// A hit being shaded: the normal on the side the ray came from and the origin of the rays it sends.
struct SurfaceInteraction {
  Vec3 position, n, origin, albedo_over_pi;  // origin: position moved off the surface along n
  Vec3 shading_n;  // the normal shading uses: n, or the interpolated vertex normal on n's side
  bool front;      // the ray hit the side the triangle's winding faces
  const Material* mat;
  uint32_t tri, geomID, inst;
};

inline SurfaceInteraction surface_interaction(const PassContext& ctx, const Ray& ray, const Hit& hit) {
  const Scene& scene = *ctx.scene;
  const Triangle tri = scene.world_triangle(hit.tri, hit.inst);
  SurfaceInteraction si;
  si.mat = &scene.materials[scene.tri_material[hit.tri]];
  si.n = normalize(scene.face_normal(tri, hit.inst));
  si.front = dot(si.n, ray.dir) <= 0.0f;
  if (!si.front) si.n = -si.n;  // shade the side the ray sees
  // Barycentric position: more precise than org + t*dir far from the camera.
  const Vec3 p = tri.v0 * (1.0f - hit.u - hit.v) + tri.v1 * hit.u + tri.v2 * hit.v;
  si.position = p;
  si.shading_n = si.n;
  si.origin = offset_origin(p, si.n);
  si.albedo_over_pi = si.mat->kd * std::numbers::inv_pi_v<float>;
  si.tri = hit.tri;
  si.geomID = hit.geomID;
  si.inst = hit.inst;
  return si;
}

// The vertex normals of the hit triangle interpolated at the hit, turned to the side of the
// geometric normal `n` (which faces the ray); `n` itself where the scene has none.
inline Vec3 interpolated_normal(const Scene& scene, const Hit& hit, Vec3 n) {
  if (scene.corner_normals.empty()) return n;
  const Vec3* c = &scene.corner_normals[3 * size_t(hit.tri)];
  Vec3 s = c[0] * (1.0f - hit.u - hit.v) + c[1] * hit.u + c[2] * hit.v;
  if (hit.inst != kInvalidIndex) s = scene.instances[hit.inst].normal(s);
  const float len = length(s);
  if (!(len > 0.0f) || !std::isfinite(len)) return n;
  const Vec3 unit = s / len;
  return dot(unit, n) < 0.0f ? -unit : unit;
}

}  // namespace tracer
