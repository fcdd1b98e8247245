// Whitted ray tracing: direct light from the lights (as the ao workload samples them), perfect
// mirrors and dielectrics followed recursively.
#pragma once

#include "render/ao.hpp"
#include "render/environment_light.hpp"
#include "shade/optics.hpp"

namespace tracer {

// Whitted ray tracing along `ray`, `depth` specular bounces from the camera: what the surface it
// hits emits, plus its direct light and ambient term where diffuse, its mirror image where a
// mirror, and where a dielectric the Fresnel-weighted reflected and (filtered by Tf) refracted
// images, with total internal reflection; nothing past max_depth bounces; the environment (--env,
// --env-map) where nothing is hit. Diffuse surfaces take their light from the lights only.
template <class Accel>
Vec3 whitted_radiance(const Accel& accel, const RenderContext& ctx, const Ray& ray, int depth, RayCounts& counts,
                      RayCone cone = {}) {
  if (depth == 0) cone = RayCone{0.0f, ctx.camera.pixel_spread()};
  Hit hit;
  if (!accel.intersect(ray, hit)) return EnvironmentLight::of(ctx).radiance(ray.dir);
  SurfacePoint sp = surface_point(ctx, ray, hit);  // sp.n faces the ray's side
  sp.shading_n = interpolated_normal(*ctx.scene, hit, sp.n);
  const Material& mat = *sp.mat;
  sp.shading_n = bumped_normal(*ctx.scene, hit, mat, sp.shading_n, -ray.dir);
  const bool deeper = depth < ctx.settings.max_depth;
  const RayCone next{cone.width_at(hit.t), cone.spread};  // mirrors and glass carry the footprint on
  switch (mat.surface()) {
    case SurfaceKind::Mirror: {
      if (!deeper) return sp.color;
      Ray reflected;
      reflected.org = sp.origin;
      reflected.dir = reflect(ray.dir, sp.shading_n);
      ++counts.secondary;
      return sp.color + mat.ks * whitted_radiance(accel, ctx, reflected, depth + 1, counts, next);
    }
    case SurfaceKind::Dielectric: {
      if (!deeper) return sp.color;
      const float eta_i = sp.front ? 1.0f : mat.ni, eta_t = sp.front ? mat.ni : 1.0f;  // front: entering
      const float f = fresnel_dielectric(-dot(ray.dir, sp.shading_n), eta_i, eta_t);
      Ray reflected;
      reflected.org = sp.origin;
      reflected.dir = reflect(ray.dir, sp.shading_n);
      ++counts.secondary;
      Vec3 color = sp.color + whitted_radiance(accel, ctx, reflected, depth + 1, counts, next) * f;
      Vec3 transmitted;
      if (f < 1.0f && refract(ray.dir, sp.shading_n, eta_i / eta_t, transmitted)) {
        Ray refracted;
        refracted.org = offset_origin(sp.position, -sp.n);  // off the surface, on the far side
        refracted.dir = transmitted;
        ++counts.secondary;
        color += mat.tf * whitted_radiance(accel, ctx, refracted, depth + 1, counts, next) * (1.0f - f);
      }
      return color;
    }
    case SurfaceKind::Diffuse:
      break;
  }
  const Vec3 kd = diffuse_color(*ctx.scene, hit, mat, cone, std::fabs(dot(ray.dir, sp.n)));
  sp.albedo_over_pi = kd * std::numbers::inv_pi_v<float>;
  add_direct_light(accel, ctx, sp, counts);
  return sp.color + kd * ctx.settings.ambient;
}

}  // namespace tracer
