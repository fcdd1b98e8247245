// Unbiased path tracing. At each non-specular vertex: next-event estimation toward one light --
// the environment (its map by luminance, a uniform sky cosine-weighted) or one emissive triangle
// (chosen by power, a point by area) -- and toward every point light, then a BSDF sample
// continues the path; a light the path hits (an emitter, or the environment when a ray escapes)
// is weighted against the light sample that could have found it by the power heuristic (Veach's
// MIS). Russian roulette from the fourth bounce. The samples are stratified (Sobol-Burley, see
// math/sobol.hpp), a function of (pixel, sample, bounce), so the image does not depend on
// threads, tiles, passes or the accelerator.
#pragma once

#include <algorithm>
#include <cstdint>

#include "math/rng.hpp"
#include "math/sobol.hpp"
#include "render/direct_light.hpp"
#include "render/pixel_samples.hpp"
#include "scene/emission.hpp"
#include "shade/material_bsdf.hpp"

namespace tracer {

// Sample dimensions, in sets (PixelSampler::get): set 0 places the sample in the pixel (x, y);
// bounce b takes set 1 + 3b (two for the point on the light, then the light's choice), set 2 + 3b
// (two for the direction, then the BSDF's lobe; glass takes only its lobe) and set 3 + 3b (Russian
// roulette). The 2D samples take a set's first two dimensions, the pair that forms (0,m,2)-nets;
// a choice that has one outcome (one light, one lobe) draws no dimension, as each costs a hash.
// The light's numbers are drawn before the bounce's ray is traced (see path_radiance), so also
// for a ray that escapes or meets glass or a mirror, where they go unused.
constexpr uint32_t light_set(int depth) { return 1 + 3 * uint32_t(depth); }
constexpr uint32_t bsdf_set(int depth) { return 2 + 3 * uint32_t(depth); }
constexpr uint32_t roulette_set(int depth) { return 3 + 3 * uint32_t(depth); }
inline constexpr int kRouletteDepth = 3;  // bounces kept unconditionally
// A 2D sample with the third dimension (a choice with one outcome) at 0.
inline std::array<float, 3> with_third(std::array<float, 2> u) { return {u[0], u[1], 0.0f}; }

// The dimensions of `set` a BSDF's sample uses, as {lobe, direction, direction}: a mirror none,
// glass one (its lobe), a smooth surface two for the direction and a third for the lobe when it
// has two (u_lobe 0 picks the one lobe there is).
inline std::array<float, 3> bsdf_numbers(const Bsdf& bsdf, const PathSampler& sampler, uint32_t set) {
  switch (bsdf.kind()) {
    case Bsdf::Kind::Mirror:
      return {0.0f, 0.0f, 0.0f};
    case Bsdf::Kind::Dielectric:
      return {sampler.get<1>(set)[0], 0.0f, 0.0f};
    case Bsdf::Kind::Smooth:
    case Bsdf::Kind::MetallicRoughness:
      break;
  }
  if (!bsdf.two_lobes()) {
    const std::array<float, 2> u = sampler.get<2>(set);
    return {0.0f, u[0], u[1]};
  }
  const std::array<float, 3> u = sampler.get<3>(set);
  return {u[2], u[0], u[1]};
}

// Next-event estimation at a non-specular vertex `si` seen from `wo`, as pbrt-v4's SampleLd: with
// multiple importance sampling on (`mis`), one sample of the environment or an emitter by the
// light numbers `u`, weighted against the BSDF sampling the same direction; then every point lamp,
// which only this finds. Each unblocked sample adds beta * f * L / pdf (times its weight) to
// `radiance`, in that order.
template <class Accel>
void add_sampled_light(const Accel& accel, const LightSampler& lights, const SurfaceInteraction& si, const Bsdf& bsdf,
                       Vec3 wo, std::array<float, 3> u, bool mis, Vec3 beta, Vec3& radiance, RayCounts& counts) {
  LightSample ls;
  if (mis && lights.sample(si, u, ls) && dot(ls.wi, si.n) > 0.0f) {
    const Vec3 f = bsdf.eval(wo, ls.wi);
    if (max_component(f * ls.L) > 0.0f) {
      const float w = power_heuristic(ls.pdf, bsdf.pdf(wo, ls.wi));
      radiance += direct_light(accel, si, ls, beta * f, w, counts);
    }
  }
  for (const Light& lamp : lights.lamps()) {
    if (!lamp.is_delta() || !sample_lamp(lamp, si, ls)) continue;
    const Vec3 f = bsdf.eval(wo, ls.wi);
    if (!(max_component(f) > 0.0f)) continue;
    radiance += direct_light(accel, si, ls, beta * f, 1.0f, counts);
  }
}

// The radiance along `ray`. The denoiser's features of the sample (film/feature_film.hpp) go to
// `guide` as Cycles' denoising features are taken: at the first vertex that is not a mirror or
// glass, with the albedo times what the specular bounces before it let through, so a reflection
// is guided by what it reflects; where the path ends before such a vertex, the last vertex's.
template <class Accel>
Vec3 path_radiance(const Accel& accel, const PassContext& ctx, Ray ray, const PathSampler& sampler, RayCounts& counts,
                   FirstHit* first = nullptr, GuideFeatures* guide = nullptr) {
  const Scene& scene = *ctx.scene;
  const RenderSettings& s = ctx.settings;
  const LightSampler lights(ctx);
  const bool nee = s.light_sampling == LightSampling::Mis;
  Vec3 radiance{0.0f}, beta{1.0f};
  // No light sample could have found what this ray finds: the last bounce was a delta lobe (or
  // this is the camera ray), or it went through the surface, where light samples never go.
  bool unsampled = true;
  float bsdf_pdf = 0.0f;
  Vec3 prev_n{0.0f};  // the geometric normal at the vertex the ray left, on its side
  RayCone cone{0.0f, ctx.camera.pixel_spread()};
  float travelled = 0.0f;
  bool guided = guide == nullptr;  // the guide's vertex found (or none asked for)
  for (int depth = 0;; ++depth) {
    // Each sample is drawn before the ray it waits for is traced, so that its hash chain runs in
    // the shadow of that traversal rather than after it (more samples per second: docs/bench/LOG.md): the light's
    // numbers before this bounce's ray, the BSDF's (which depend on the surface hit) before the shadow ray.
    const std::array<float, 3> u_light =
        lights.chooses() ? sampler.get<3>(light_set(depth)) : with_third(sampler.get<2>(light_set(depth)));
    Hit hit;
    if (!accel.intersect(ray, hit)) {
      if (lights.lights_environment()) {
        float w = 1.0f;
        if (nee && !unsampled) w = power_heuristic(bsdf_pdf, lights.pdf_environment(prev_n, ray.dir));
        radiance += beta * lights.environment().radiance(ray.dir) * w;
      }
      break;
    }
    SurfaceInteraction si = surface_interaction(ctx, ray, hit);
    si.shading_n = interpolated_normal(scene, hit, si.n);
    const Material& mat = *si.mat;
    si.shading_n = bumped_normal(scene, hit, mat, si.shading_n, -ray.dir);
    if (mat.emissive() && si.front) {  // emitters shine from their front face (see Emitters)
      float w = 1.0f;
      if (nee && !unsampled) {
        w = power_heuristic(bsdf_pdf, lights.pdf_emitter(hit.tri, hit.inst, ray.org, si.position));
      }
      radiance += beta * emitted_radiance(scene, hit.tri, hit.u, hit.v) * w;
    }
    if (depth >= s.max_depth) break;
    const MaterialPoint point = material_point(scene, hit, mat, cone, std::fabs(dot(ray.dir, si.n)));
    const Bsdf bsdf = material_bsdf(mat, point, si.shading_n, si.front);
    const Vec3 wo = -ray.dir;
    const Vec3 albedo = bsdf.delta() ? Vec3{1.0f} : point.albedo;
    if (!guided) {
      travelled += hit.t;
      guide->albedo = beta * albedo;
      guide->normal = si.shading_n;
      guide->distance = travelled;
      guided = !bsdf.delta();
    }
    if (depth == 0 && first) {
      first->albedo = albedo;
      first->normal = si.shading_n;
    }
    const std::array<float, 3> u_bsdf = bsdf_numbers(bsdf, sampler, bsdf_set(depth));
    if (!bsdf.delta()) {
      add_sampled_light(accel, lights, si, bsdf, wo, u_light, nee, beta, radiance, counts);
    }
    BsdfSample bs;
    if (!bsdf.sample(wo, u_bsdf[0], u_bsdf[1], u_bsdf[2], bs)) break;
    // The shading normal may send a reflection through the geometric surface (or a refraction
    // back out): such a sample has no consistent meaning, so the path ends.
    if ((dot(bs.wi, si.n) < 0.0f) != bs.transmitted) break;
    beta = beta * bs.weight;
    cone = bs.delta ? RayCone{cone.width_at(hit.t), cone.spread} : RayCone{};
    unsampled = bs.delta || bs.transmitted;
    bsdf_pdf = bs.pdf;
    prev_n = si.n;
    if (depth >= kRouletteDepth) {
      const float keep = std::min(0.95f, max_component(beta));
      if (!(sampler.get<1>(roulette_set(depth))[0] < keep)) break;
      beta = beta / keep;
    }
    ray = Ray{};
    ray.org = offset_origin(si.position, bs.transmitted ? -si.n : si.n);
    ray.dir = bs.wi;
    ++counts.secondary;
  }
  return radiance;
}

// Path tracing as the pixel-sample loop (render/pixel_samples.hpp) takes it.
struct PathIntegrator {
  using Streams = PathStreams;
  template <class Accel>
  Vec3 radiance(const Accel& accel, const PassContext& ctx, const PixelSample& ps, const PathSampler& sampler,
                RayCounts& counts, FirstHit* first, GuideFeatures* guide) const {
    return path_radiance(accel, ctx, ps.ray, sampler, counts, first, guide);
  }
};

}  // namespace tracer
