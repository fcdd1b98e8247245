// Whitted ray tracing: direct light from the lamps (as the ao workload takes them), perfect
// mirrors and dielectrics followed recursively.
#pragma once

#include "render/direct_light.hpp"
#include "render/pixel_samples.hpp"
#include "scene/emission.hpp"
#include "shade/material_bsdf.hpp"
#include "shade/optics.hpp"

namespace tracer {

// Whitted ray tracing along `ray`, `depth` specular bounces from the camera: what the surface it
// hits emits, plus its direct light and ambient term where diffuse, its mirror image where a
// mirror, and where a dielectric the Fresnel-weighted reflected and (filtered by Tf) refracted
// images, with total internal reflection; nothing past max_depth bounces; the environment (--env,
// --env-map) where nothing is hit. Diffuse surfaces take their light from the lights only.
template <class Accel>
Vec3 whitted_radiance(const Accel& accel, const PassContext& ctx, const Ray& ray, int depth, RayCounts& counts,
                      RayCone cone = {}) {
  if (depth == 0) cone = RayCone{0.0f, ctx.camera.pixel_spread()};
  Hit hit;
  if (!accel.intersect(ray, hit)) return EnvironmentLight::of(ctx).radiance(ray.dir);
  SurfaceInteraction si = surface_interaction(ctx, ray, hit);  // si.n faces the ray's side
  const Vec3 emitted = emitted_radiance(*ctx.scene, hit.tri, hit.u, hit.v);
  si.shading_n = interpolated_normal(*ctx.scene, hit, si.n);
  const Material& mat = *si.mat;
  si.shading_n = bumped_normal(*ctx.scene, hit, mat, si.shading_n, -ray.dir);
  const bool deeper = depth < ctx.settings.max_depth;
  const RayCone next{cone.width_at(hit.t), cone.spread};  // mirrors and glass carry the footprint on
  switch (mat.surface()) {
    case SurfaceKind::Mirror: {
      if (!deeper) return emitted;
      Ray reflected;
      reflected.org = si.origin;
      reflected.dir = reflect(ray.dir, si.shading_n);
      ++counts.secondary;
      return emitted + mat.ks * whitted_radiance(accel, ctx, reflected, depth + 1, counts, next);
    }
    case SurfaceKind::Dielectric: {
      if (!deeper) return emitted;
      const float eta_i = si.front ? 1.0f : mat.ni, eta_t = si.front ? mat.ni : 1.0f;  // front: entering
      const float f = fresnel_dielectric(-dot(ray.dir, si.shading_n), eta_i, eta_t);
      Ray reflected;
      reflected.org = si.origin;
      reflected.dir = reflect(ray.dir, si.shading_n);
      ++counts.secondary;
      Vec3 color = emitted + whitted_radiance(accel, ctx, reflected, depth + 1, counts, next) * f;
      Vec3 transmitted;
      if (f < 1.0f && refract(ray.dir, si.shading_n, eta_i / eta_t, transmitted)) {
        Ray refracted;
        refracted.org = offset_origin(si.position, -si.n);  // off the surface, on the far side
        refracted.dir = transmitted;
        ++counts.secondary;
        color += mat.tf * whitted_radiance(accel, ctx, refracted, depth + 1, counts, next) * (1.0f - f);
      }
      return color;
    }
    case SurfaceKind::Diffuse:
    case SurfaceKind::MetallicRoughness:
      break;
  }
  // Whitted has no glossy lobe: MTL's Kd is diffuse, a metallic-roughness surface diffuse of its
  // albedo (the metal's colour; the dielectric's base colour under its specular layer).
  const MaterialPoint point = material_point(*ctx.scene, hit, mat, cone, std::fabs(dot(ray.dir, si.n)));
  const Vec3 kd = mat.metallic_roughness ? point.albedo : point.color;
  si.albedo_over_pi = kd * std::numbers::inv_pi_v<float>;
  return add_lamp_light(accel, ctx, si, emitted, counts) + kd * ctx.settings.ambient;
}

// Whitted ray tracing as the pixel-sample loop (render/pixel_samples.hpp) takes it.
struct WhittedIntegrator {
  using Streams = JitterStreams;
  template <class Accel>
  Vec3 radiance(const Accel& accel, const PassContext& ctx, const PixelSample& ps, const SampleRng&, RayCounts& counts,
                FirstHit*, GuideFeatures*) const {
    return whitted_radiance(accel, ctx, ps.ray, 0, counts);
  }
};

}  // namespace tracer
