// The light from beyond the scene as the integrators see it: the settings' environment radiance
// (--env r,g,b), times the scene's environment map where it has one (--env-map).
#pragma once

#include <numbers>

#include "math/sampling.hpp"
#include "render/settings.hpp"

namespace tracer {

struct EnvironmentLight {
  Vec3 scale{0.0f};
  const EnvironmentMap* map = nullptr;  // null: uniform radiance `scale`

  static EnvironmentLight of(const RenderContext& ctx) {
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

}  // namespace tracer
