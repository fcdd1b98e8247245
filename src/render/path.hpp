// Unbiased path tracing. At each non-specular vertex: next-event estimation toward one emissive
// triangle (chosen by power, a point by area) and toward every point light, then a BSDF sample
// continues the path; an emitter the path hits is weighted against the light sample that could
// have found it by the power heuristic (Veach's MIS). Russian roulette from the fourth bounce.
// Every random number is a function of (pixel, sample, bounce), so the image does not depend on
// threads, tiles, passes or the accelerator.
#pragma once

#include <algorithm>
#include <cstdint>

#include "math/rng.hpp"
#include "parallel/tiles.hpp"
#include "render/accel_concepts.hpp"
#include "render/surface_point.hpp"
#include "shade/material_bsdf.hpp"

namespace tracer {

// Random dimensions: 0 and 1 place the sample in the pixel; each bounce then takes kPathDims:
// three for the emitter sample, three for the BSDF sample, one for Russian roulette.
inline constexpr uint32_t kPathPixelDims = 2, kPathDims = 7;
inline constexpr int kRouletteDepth = 3;  // bounces kept unconditionally

template <class Accel>
Vec3 path_radiance(const Accel& accel, const RenderContext& ctx, Ray ray, const SampleRng& rng, RayCounts& counts) {
  const Scene& scene = *ctx.scene;
  const RenderSettings& s = ctx.settings;
  const bool nee = s.light_sampling == LightSampling::Mis;
  Vec3 radiance{0.0f}, beta{1.0f};
  bool specular = true;  // the last bounce was a delta lobe (or the camera): no light sample competed
  float bsdf_pdf = 0.0f;
  for (int depth = 0;; ++depth) {
    Hit hit;
    if (!accel.intersect(ray, hit)) {
      radiance += beta * s.environment;
      break;
    }
    SurfacePoint sp = surface_point(ctx, ray, hit);
    sp.shading_n = interpolated_normal(scene, hit, sp.n);
    const Material& mat = *sp.mat;
    if (mat.emissive() && sp.front) {  // emitters shine from their front face (see Emitters)
      float w = 1.0f;
      if (nee && !specular) w = power_heuristic(bsdf_pdf, scene.emitters.pdf(scene, hit.tri, ray.org, sp.position));
      radiance += beta * mat.ke * w;
    }
    if (depth >= s.max_depth) break;
    const uint32_t dim = kPathPixelDims + uint32_t(depth) * kPathDims;
    const Bsdf bsdf = material_bsdf(mat, diffuse_color(scene, hit, mat), sp.shading_n, sp.front);
    const Vec3 wo = -ray.dir;
    if (!bsdf.delta()) {
      // One emitter sample: Ke * f * cos / pdf, weighted against BSDF sampling.
      EmitterSample es;
      if (nee && scene.emitters.sample(scene, sp.origin, rng.draw(dim), rng.draw(dim + 1), rng.draw(dim + 2), es) &&
          dot(es.wi, sp.n) > 0.0f) {
        const Vec3 f = bsdf.eval(wo, es.wi);
        if (max_component(f) > 0.0f) {
          Ray shadow;
          shadow.org = sp.origin;
          shadow.dir = es.wi;
          shadow.tfar = es.distance * (1.0f - 1e-4f);  // stop short of the emitter's own surface
          ++counts.shadow;
          if (!occluded_leaving(accel, shadow, sp.tri)) {
            const float w = power_heuristic(es.pdf, bsdf.pdf(wo, es.wi));
            radiance += beta * f * es.radiance * (w / es.pdf);
          }
        }
      }
      // Point lights (--light, a view's light): delta lights, found only this way.
      for (const Light& light : scene.lights) {
        if (!light.is_point()) continue;
        const Vec3 to = light.position - sp.origin;
        const float d2 = dot(to, to);
        if (!(d2 > 0.0f)) continue;
        const float d = std::sqrt(d2);
        const Vec3 wi = to / d;
        if (dot(wi, sp.n) <= 0.0f) continue;
        const Vec3 f = bsdf.eval(wo, wi);
        if (!(max_component(f) > 0.0f)) continue;
        Ray shadow;
        shadow.org = sp.origin;
        shadow.dir = wi;
        shadow.tfar = d;
        ++counts.shadow;
        if (!occluded_leaving(accel, shadow, sp.tri)) radiance += beta * f * light.power / d2;
      }
    }
    BsdfSample bs;
    if (!bsdf.sample(wo, rng.draw(dim + 3), rng.draw(dim + 4), rng.draw(dim + 5), bs)) break;
    // The shading normal may send a reflection through the geometric surface (or a refraction
    // back out): such a sample has no consistent meaning, so the path ends.
    if ((dot(bs.wi, sp.n) < 0.0f) != bs.transmitted) break;
    beta = beta * bs.weight;
    specular = bs.delta;
    bsdf_pdf = bs.pdf;
    if (depth >= kRouletteDepth) {
      const float keep = std::min(0.95f, max_component(beta));
      if (!(rng.draw(dim + 6) < keep)) break;
      beta = beta / keep;
    }
    ray = Ray{};
    ray.org = offset_origin(sp.position, bs.transmitted ? -sp.n : sp.n);
    ray.dir = bs.wi;
    ++counts.secondary;
  }
  return radiance;
}

// Adds this pass's samples to every pixel of `tile`: their sum, taken in sample order from zero
// (see Framebuffer). A sample that comes out non-finite (a float overflow on a degenerate path)
// adds black rather than poisoning the pixel.
template <class Accel>
void path_tile(const Accel& accel, const RenderContext& ctx, const Tile& tile, RayCounts& counts) {
  const RenderSettings& s = ctx.settings;
  for (int y = tile.y0; y < tile.y1; ++y) {
    for (int x = tile.x0; x < tile.x1; ++x) {
      const uint32_t pixel = uint32_t(y) * uint32_t(s.width) + uint32_t(x);
      Vec3 sum{0.0f};
      for (uint32_t k = ctx.samples.first, end = ctx.samples.first + ctx.samples.count; k < end; ++k) {
        const SampleRng rng(pixel, k, s.seed);
        const Ray ray = ctx.camera.ray_through(float(x) + rng.draw(0), float(y) + rng.draw(1));
        ++counts.primary;
        const Vec3 l = path_radiance(accel, ctx, ray, rng, counts);
        if (is_finite(l)) sum += l;
      }
      ctx.framebuffer->add(x, y, sum, ctx.samples.count);
    }
  }
}

}  // namespace tracer
