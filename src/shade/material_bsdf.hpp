// Which BSDF an MTL material is at a surface point: illum 3/5 a mirror of reflectance Ks, illum
// 4/6/7/9 a dielectric of index Ni filtered by Tf, otherwise Lambert from Kd plus (illum 2 and
// up, "highlight on") a GGX lobe of reflectance Ks whose width comes from Ns.
#pragma once

#include "scene/scene.hpp"
#include "shade/bsdf.hpp"

namespace tracer {

// kd: the diffuse colour at the point (Kd, or its texture's texel); shading_n: the shading
// normal on the side the ray arrived from; front: the ray hit the side the winding faces.
inline Bsdf material_bsdf(const Material& mat, Vec3 kd, Vec3 shading_n, bool front) {
  const Frame frame(shading_n);
  switch (mat.surface()) {
    case SurfaceKind::Mirror:
      return Bsdf::mirror(frame, mat.ks);
    case SurfaceKind::Dielectric:
      return Bsdf::dielectric(frame, front ? mat.ni : 1.0f / mat.ni, mat.tf);
    case SurfaceKind::Diffuse:
      break;
  }
  return Bsdf::smooth(frame, kd, mat.illum >= 2 ? mat.ks : Vec3{0.0f}, Ggx::from_phong_exponent(mat.ns));
}

}  // namespace tracer
