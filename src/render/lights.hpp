// Every light as the integrators see it, in one place: a light sample (LightSample) from a shading
// point toward the scene's lamps (Light: point lights and the study's area-light centroids), its
// emissive triangles (Emitters) or the environment (EnvironmentLight); and the LightSampler that
// path tracing draws them from. What a sample adds once its shadow ray is traced is
// direct_light.hpp's.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <span>

#include "math/sampling.hpp"
#include "render/interaction.hpp"

namespace tracer {

// Light arriving at a shading point from one direction: radiance (or a lamp's power) L along the
// unit direction wi from a light `distance` away, times `falloff` (the geometric term of a lamp:
// 1/d^2 for a point; 1 for samples whose L is already radiance), drawn with solid-angle density
// `pdf` (1 for a lamp, which is not drawn but taken).
struct LightSample {
  Vec3 L{0.0f};
  Vec3 wi{0.0f};
  float falloff = 1.0f;
  float pdf = 0.0f;
  float distance = kInfinity;  // the shadow ray's tfar: short of the light's own surface
};

// The lamp `light` seen from `si`: toward its position (a point or spot light), against its
// direction (a directional light), or toward the centroid of its area (the study's one shadow ray
// per area light); false when it cannot light `si` (it is the surface's own emitter, lies behind
// the surface, or `si` is outside a spot's cone).
inline bool sample_lamp(const Light& light, const SurfaceInteraction& si, LightSample& out) {
  if (light.geomID == si.geomID && light.inst == si.inst) return false;  // an emitter does not light itself
  if (light.kind == LightKind::Directional) {
    out.wi = -light.normal;
    if (dot(si.n, out.wi) <= 0.0f) return false;
    out.L = light.power;
    out.falloff = 1.0f;  // irradiance at normal incidence, at every distance
    out.pdf = 1.0f;
    out.distance = kInfinity;
    return true;
  }
  const Vec3 to_light = light.position - si.origin;
  const float d2 = dot(to_light, to_light);
  if (!(d2 > 0.0f)) return false;
  const float d = std::sqrt(d2);
  const Vec3 wi = to_light / d;
  if (dot(si.n, wi) <= 0.0f) return false;  // below the surface itself, whatever the shading normal
  // Irradiance from a light of area A at distance d: power * cos_l / (d^2 + A/pi), exact on the
  // axis of a disk of that area and free of the 1/d^2 blow-up near the lamp; 1/d^2 for points.
  const float cos_light = light.kind == LightKind::Area   ? std::fabs(dot(light.normal, wi))
                          : light.kind == LightKind::Spot ? light.spot_falloff(-dot(light.normal, wi))
                                                          : 1.0f;
  if (light.kind == LightKind::Spot && !(cos_light > 0.0f)) return false;  // outside its cone
  out.L = light.power;
  out.wi = wi;
  out.falloff = cos_light / (d2 + light.area * std::numbers::inv_pi_v<float>);
  out.pdf = 1.0f;
  out.distance = d * (1.0f - 1e-4f);  // stop short of the light's own surface
  return true;
}

// The light from beyond the scene: the settings' environment radiance (--env r,g,b), times the
// scene's environment map where it has one (--env-map).
struct EnvironmentLight {
  Vec3 scale{0.0f};
  const EnvironmentMap* map = nullptr;  // null: uniform radiance `scale`

  static EnvironmentLight of(const PassContext& ctx) {
    const EnvironmentMap& m = ctx.scene->environment_map;
    return {ctx.settings.environment, m.empty() ? nullptr : &m};
  }
  bool black() const { return !(max_component(scale) > 0.0f); }
  Vec3 radiance(Vec3 dir) const { return map ? scale * map->radiance(dir) : scale; }
  // A direction toward the environment from a surface of geometric normal `n` and its density
  // per solid angle: a map by its luminance; a uniform sky cosine-weighted about n (no sample
  // wasted below the surface, and the density a diffuse surface weights it by).
  bool sample(Vec3 n, float u1, float u2, Vec3& wi, float& pdf) const {
    if (map) return map->sample(u1, u2, wi, pdf);
    const Vec3 local = cosine_hemisphere(u1, u2);
    wi = Frame(n).to_world(local);
    pdf = local.z * std::numbers::inv_pi_v<float>;
    return pdf > 0.0f;
  }
  float pdf(Vec3 n, Vec3 wi) const {
    if (map) return map->pdf(wi);
    return std::max(0.0f, dot(n, wi)) * std::numbers::inv_pi_v<float>;
  }
};

// The lights path tracing samples: one draw picks the environment (probability 1/2 when there are
// emissive triangles too) or an emissive triangle (by power, a point on it by area); the point
// lights, which no ray can hit, are each taken at every vertex (delta_lamps()).
class LightSampler {
 public:
  explicit LightSampler(const PassContext& ctx)
      : scene_(ctx.scene),
        env_(EnvironmentLight::of(ctx)),
        p_env_(env_.black()                  ? 0.0f
               : ctx.scene->emitters.empty() ? 1.0f
                                             : 0.5f) {}

  const EnvironmentLight& environment() const { return env_; }
  bool lights_environment() const { return p_env_ > 0.0f; }
  // Whether sample() chooses among lights (and so reads its third number).
  bool chooses() const { return (p_env_ > 0.0f && p_env_ < 1.0f) || scene_->emitters.size() > 1; }

  // A sample of the environment or an emitter from `si`, by three uniform numbers (u[2] chooses
  // the light); false where it has no density.
  bool sample(const SurfaceInteraction& si, std::array<float, 3> u, LightSample& out) const {
    if (u[2] < p_env_) {
      if (!env_.sample(si.n, u[0], u[1], out.wi, out.pdf)) return false;
      out.pdf *= p_env_;
      out.L = env_.radiance(out.wi);
      out.distance = kInfinity;
    } else {
      EmitterSample es;
      const float u_select = (u[2] - p_env_) / (1.0f - p_env_);
      if (!scene_->emitters.sample(*scene_, si.origin, std::min(u_select, 0x1.fffffep-1f), u[0], u[1], es)) {
        return false;
      }
      out.wi = es.wi;
      out.pdf = es.pdf * (1.0f - p_env_);
      out.L = es.radiance;
      out.distance = es.distance * (1.0f - 1e-4f);  // stop short of the emitter's own surface
    }
    out.falloff = 1.0f;
    return out.pdf > 0.0f;
  }
  // The density with which sample() finds the environment along `wi` from a surface of normal `n`.
  float pdf_environment(Vec3 n, Vec3 wi) const { return p_env_ * env_.pdf(n, wi); }
  // The density with which sample() finds the point `to` of scene triangle `tri` (placed by
  // instance `inst`) from `from`.
  float pdf_emitter(uint32_t tri, uint32_t inst, Vec3 from, Vec3 to) const {
    return (1.0f - p_env_) * scene_->emitters.pdf(*scene_, tri, inst, from, to);
  }
  // The scene's lamps: path tracing takes the point, spot and directional lights among them at
  // every vertex (an area lamp's triangles are sample()'s emitters).
  std::span<const Light> lamps() const { return scene_->lights; }

 private:
  const Scene* scene_;
  EnvironmentLight env_;
  float p_env_;  // the probability that sample() picks the environment
};

}  // namespace tracer
