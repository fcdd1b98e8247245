#include "scene/emission.hpp"

#include <algorithm>
#include <cmath>

#include "math/sampling.hpp"
#include "scene/slot_coordinates.hpp"

namespace tracer {

Vec3 textured_emission(const Scene& scene, const Material& m, uint32_t tri, float b1, float b2) {
  if (!m.emissive()) return Vec3{0.0f};
  Vec2 c[3];
  if (!slot_corners(scene, tri, m.emission_texture, c)) return m.ke;
  const Vec2 uv = interpolate_uv(c, b1, b2);
  return m.ke * scene.textures[m.emission_texture.texture].bilinear(uv.x, uv.y, m.emission_texture.sampler);
}

Vec3 mean_emission(const Scene& scene, uint32_t tri) {
  const Material& m = scene.materials[scene.tri_material[tri]];
  if (!m.emissive()) return Vec3{0.0f};
  Vec2 c[3];
  if (!slot_corners(scene, tri, m.emission_texture, c)) return m.ke;
  const Texture& t = scene.textures[m.emission_texture.texture];
  // The footprint in texels; four points per texel it covers, at least 8 x 8 (a 16-point mean of
  // a gradient over 8 texels was 4 % off) and at most 32 x 32, each read at the level where
  // texels are as far apart as the points.
  const double texels =
      0.5 *
      std::fabs(double(c[1].x - c[0].x) * double(c[2].y - c[0].y) - double(c[2].x - c[0].x) * double(c[1].y - c[0].y)) *
      double(t.width()) * double(t.height());
  const int k = std::clamp(int(std::ceil(2.0 * std::sqrt(std::isfinite(texels) ? texels : 0.0))), 8, 32);
  const double points_per_texel = double(k) * k / std::max(texels, 1e-30);
  const float lod = points_per_texel < 1.0 ? -0.5f * float(std::log2(points_per_texel)) : 0.0f;
  Vec3 sum{0.0f};
  for (int i = 0; i < k; ++i) {
    for (int j = 0; j < k; ++j) {
      float b1, b2;
      uniform_triangle((float(i) + 0.5f) / float(k), (float(j) + 0.5f) / float(k), b1, b2);
      const Vec2 uv = interpolate_uv(c, b1, b2);
      sum += t.filtered(uv.x, uv.y, lod, m.emission_texture.sampler);
    }
  }
  return m.ke * sum * (1.0f / float(k * k));
}

}  // namespace tracer
