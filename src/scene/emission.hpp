// What an emissive surface emits: its material's emission (MTL Ke, glTF emissiveFactor x
// strength) times its emission texture's texel where it has one (glTF emissiveTexture). Written
// once for the integrators that see an emitter and for the emitters that sample it.
#pragma once

#include <cstdint>

#include "math/vec.hpp"
#include "scene/scene.hpp"

namespace tracer {

// The emission of material `m` times its texture's texel (bilinear, linear light) at barycentric
// (b1, b2) of scene triangle `tri`.
Vec3 textured_emission(const Scene& scene, const Material& m, uint32_t tri, float b1, float b2);

// The radiance scene triangle `tri` emits at barycentric (b1, b2) (Hit's u and v): its emission
// (0 for a material that does not emit), times the texel where it has an emission texture. Every
// hit of ao and whitted asks: the untextured case is a load, as reading Ke was.
inline Vec3 emitted_radiance(const Scene& scene, uint32_t tri, float b1, float b2) {
  const Material& m = scene.materials[scene.tri_material[tri]];
  if (!m.emission_texture.present()) return m.ke;
  return textured_emission(scene, m, tri, b1, b2);
}

// The mean radiance over triangle `tri` (its power per unit area): the emission itself without a
// texture; with one, the texture averaged over the triangle's footprint at load (stratified
// points, read from the mip level their spacing spans), so a triangle over black texels has none.
Vec3 mean_emission(const Scene& scene, uint32_t tri);

}  // namespace tracer
