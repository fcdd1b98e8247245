// What a material is at one hit, written once for every integrator: its textures read at the hit
// (material_point) and the BSDF that makes of it (material_bsdf). MTL: illum 3/5 a mirror of
// reflectance Ks, illum 4/6/7/9 a dielectric of index Ni filtered by Tf, otherwise Lambert from Kd
// plus (illum 2 and up, "highlight on") a GGX lobe of reflectance Ks whose width comes from Ns.
// glTF: the metallic-roughness BRDF of its base colour, metalness and roughness at the hit.
#pragma once

#include <algorithm>

#include "scene/scene.hpp"
#include "shade/bsdf.hpp"
#include "shade/texture_lookup.hpp"

namespace tracer {

// A material's parameters at one surface point, factors times textures.
struct MaterialPoint {
  Vec3 color{0.0f};  // Kd or the base colour (map_Kd, baseColorTexture)
  float metallic = 0.0f, roughness = 1.0f;
  Vec3 specular{0.0f};     // MTL: Ks (times map_Ks)
  float shininess = 0.0f;  // MTL: Ns (times map_Ns)
  // What the surface reflects of uniform light, within [0, 1]: the denoiser's albedo feature and
  // the diffuse shade of whitted's lamp light. MTL: Kd + Ks; metallic-roughness: the diffuse under
  // the specular layer plus that layer's reflectance at normal incidence.
  Vec3 albedo{0.0f};
};

// `cos_incidence`: |cos| of the ray with the surface, for the texture footprint of `cone`.
inline MaterialPoint material_point(const Scene& scene, const Hit& hit, const Material& mat, const RayCone& cone = {},
                                    float cos_incidence = 1.0f) {
  MaterialPoint p;
  p.color = diffuse_color(scene, hit, mat, cone, cos_incidence);
  if (!mat.metallic_roughness) {
    p.specular = slot_color(scene, hit, mat.specular_texture, Vec3{1.0f}, cone, cos_incidence) * mat.ks;
    p.shininess = mat.ns;
    if (mat.shininess_texture.present()) {
      const Vec3 t = slot_data(scene, hit, mat.shininess_texture, Vec3{1.0f});
      p.shininess *= (t.x + t.y + t.z) * (1.0f / 3.0f);
    }
    p.albedo = min(p.color + p.specular, Vec3{1.0f});
    return p;
  }
  const Vec3 mr = slot_data(scene, hit, mat.metallic_roughness_texture, Vec3{1.0f});
  p.metallic = std::clamp(mat.metallic * mr.z, 0.0f, 1.0f);
  p.roughness = std::clamp(mat.roughness * mr.y, 0.0f, 1.0f);
  const Vec3 f0 = min(mat.specular_f0, Vec3{1.0f});
  p.albedo = min(p.color * (p.metallic + (1.0f - p.metallic) * (1.0f - max_component(f0))) + f0 * (1.0f - p.metallic),
                 Vec3{1.0f});
  return p;
}

// shading_n: the shading normal on the side the ray arrived from; front: the ray hit the side
// the winding faces.
inline Bsdf material_bsdf(const Material& mat, const MaterialPoint& p, Vec3 shading_n, bool front) {
  const Frame frame(shading_n);
  switch (mat.surface()) {
    case SurfaceKind::Mirror:
      return Bsdf::mirror(frame, p.specular);
    case SurfaceKind::Dielectric:
      return Bsdf::dielectric(frame, front ? mat.ni : 1.0f / mat.ni, mat.tf);
    case SurfaceKind::MetallicRoughness:  // GGX's alpha is roughness squared (glTF)
      return Bsdf::metallic_roughness(frame, p.color, p.metallic, Ggx{p.roughness * p.roughness}, mat.specular_f0,
                                      mat.specular_f90);
    case SurfaceKind::Diffuse:
      break;
  }
  return Bsdf::smooth(frame, p.color, mat.illum >= 2 ? p.specular : Vec3{0.0f}, Ggx::from_phong_exponent(p.shininess));
}

}  // namespace tracer
